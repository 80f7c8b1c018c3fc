"""The package where production code meets it: process pools, interrupts,
every picture form numpy and PIL hold, Python's own exception and warning
types, the Drawing and its metadata, and the stubs under ``mypy --strict``.
"""

from __future__ import annotations

import errno
import multiprocessing as mp
import os
import subprocess
import sys
import textwrap
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import pixelpie

ROOT = Path(__file__).resolve().parents[2]
ASSETS = ROOT / "assets"


# --- process pools ------------------------------------------------------------


def _work(seed: int) -> bytes:
    """Every call that works on the library's threads."""
    pts, _ = pixelpie.sample(300, 300, radius=3.0, seed=seed)
    d = pixelpie.stipple(ASSETS / "default.png", points=1500, seed=seed, paper="a6", pen_mm=0.3)
    plan = pixelpie.plan(ASSETS / "default.png", points=1500)
    count = pixelpie.analyze(pts, 300, 300)["count"]
    paths = sum(len(p) for layer in d.paths() for p in layer.paths)
    said = f"{plan['line']} {count} {paths}".encode()
    return pts.tobytes() + d.dots.tobytes() + d.svg() + d.png() + said


@pytest.mark.parametrize("method", ["fork", "forkserver", "spawn"])
def test_a_process_pool_after_a_call_in_the_parent_gives_the_serial_results(method):
    if method not in mp.get_all_start_methods():
        pytest.fail(f"the start method {method} is missing on this platform")
    serial = [_work(s) for s in range(4)]  # the parent's threads exist now
    start = time.monotonic()
    with mp.get_context(method).Pool(2) as pool:
        pooled = pool.map_async(_work, range(4)).get(timeout=60)
    took = time.monotonic() - start
    assert pooled == serial
    if method == "fork":
        assert took < 10, f"a fork pool took {took:.1f} s"


def test_a_raw_fork_child_samples_and_stipples():
    pixelpie.sample(200, 200, radius=3.0)
    pid = os.fork()
    if pid == 0:  # the child: exit 0 only when both calls return
        try:
            _work(1)
            os._exit(0)
        except BaseException:
            os._exit(1)
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            assert os.waitstatus_to_exitcode(status) == 0
            return
        time.sleep(0.05)
    os.kill(pid, 9)
    pytest.fail("the forked child hung")


# --- interrupts ----------------------------------------------------------------

_INTERRUPTED = textwrap.dedent(
    """
    import os, signal, sys, threading, time
    import pixelpie
    out, delay, options = sys.argv[1], float(sys.argv[2]), eval(sys.argv[3])
    sent = []
    def interrupt():
        time.sleep(delay)
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)
    threading.Thread(target=interrupt, daemon=True).start()
    try:
        pixelpie.stipple(sys.argv[4], out, **options)
    except KeyboardInterrupt:
        print("late", time.monotonic() - sent[0])
        print("exists", os.path.exists(out))
        print("strays", [f for f in os.listdir(os.path.dirname(out)) if f.startswith(".pixelpie")])
    else:
        print("finished")
    """
)


def _interrupted(tmp_path, delay, options):
    """What a fresh process says when SIGINT comes ``delay`` s into
    ``stipple(astronaut, out, **options)``: how late the KeyboardInterrupt
    came, and whether the output or a temporary file exists."""
    out = tmp_path / "drawing.svg"
    run = subprocess.run(
        [sys.executable, "-c", _INTERRUPTED, str(out), str(delay), repr(options),
         str(ASSETS / "astronaut.jpg")],
        capture_output=True, text=True, timeout=120,
    )
    assert run.returncode == 0, run.stderr
    assert "finished" not in run.stdout, f"the run ended before the interrupt at {delay} s"
    assert "PanicException" not in run.stderr and "panicked" not in run.stderr
    return dict(line.split(" ", 1) for line in run.stdout.splitlines())


def _assert_prompt(said):
    assert float(said["late"]) < 0.5, said
    assert said["exists"] == "False" and said["strays"] == "[]", said


def test_ctrl_c_raises_keyboard_interrupt_within_half_a_second_and_leaves_no_file(tmp_path):
    # 0.3 s into the first stipple of a fresh process: its sampling.
    _assert_prompt(_interrupted(tmp_path, 0.3, dict(points=1_000_000)))


@pytest.mark.parametrize(
    "stage,options",
    [
        ("order", dict(points=1_000_000, order="tsp")),
        ("relax", dict(points=200_000)),
        ("size", dict(points=200_000)),
    ],
)
def test_ctrl_c_stops_the_tour_the_relaxation_and_the_correction_too(tmp_path, stage, options):
    # Where the stage lies in time, from an uninterrupted run (the fresh
    # process adds its imports, about as long as this process's warm call
    # saves), and the interrupt in its middle.
    d = pixelpie.stipple(ASSETS / "astronaut.jpg", **options)
    names = list(d.stages)
    assert d.stages[stage] > 0.1, d.stages
    before = sum(d.stages[n] for n in names[: names.index(stage)])
    _assert_prompt(_interrupted(tmp_path, before + d.stages[stage] / 2, options))


# --- one input rule for every picture ------------------------------------------


def _grey() -> np.ndarray:
    """A small grey picture with every value 0..255 in it."""
    y, x = np.mgrid[0:96, 0:128]
    return ((x * 2 + y) % 256).astype(np.uint8)


def _forms(grey: np.ndarray, tmp_path: Path):
    """The same picture in every form the rule takes, each with the file it
    must draw as: the grey PNG, or the same grey as an RGB PNG (whose
    luminance may round apart from the grey's in the last bit)."""
    grey_png, rgb_png = tmp_path / "grey.png", tmp_path / "rgb.png"
    rgb = np.repeat(grey[:, :, None], 3, axis=2)
    Image.fromarray(grey, "L").save(grey_png)
    Image.fromarray(rgb, "RGB").save(rgb_png)
    opaque = np.full_like(grey, 255)
    rgba = np.concatenate([rgb, opaque[:, :, None]], axis=2)
    palette = Image.fromarray(rgb, "RGB").convert("P", palette=Image.Palette.ADAPTIVE, colors=256)
    assert palette.mode == "P"
    return {
        "str path": (str(grey_png), grey_png),
        "Path": (grey_png, grey_png),
        "bytes path": (os.fsencode(grey_png), grey_png),
        "uint8": (grey, grey_png),
        "uint16": (grey.astype(np.uint16) * 257, grey_png),
        "float 0..1": (grey.astype(np.float64) / 255.0, grey_png),
        "float32 0..1": (grey.astype(np.float32) / 255.0, grey_png),
        "bool": (grey > 127, None),
        "uint8 (H, W, 1)": (grey[:, :, None], grey_png),
        "uint8 LA": (np.stack([grey, opaque], axis=2), grey_png),
        "uint8 RGB": (rgb, rgb_png),
        "uint8 RGBA": (rgba, rgb_png),
        "PIL 1": (Image.fromarray(grey > 127), None),
        "PIL L": (Image.fromarray(grey, "L"), grey_png),
        "PIL LA": (Image.fromarray(np.stack([grey, opaque], axis=2), "LA"), grey_png),
        "PIL RGB": (Image.fromarray(rgb, "RGB"), rgb_png),
        "PIL RGBA": (Image.fromarray(rgba, "RGBA"), rgb_png),
        "PIL P": (palette, rgb_png),
        "PIL CMYK": (Image.fromarray(rgb, "RGB").convert("CMYK"), rgb_png),
        "PIL YCbCr": (Image.fromarray(rgb, "RGB").convert("YCbCr"), None),
        "PIL I;16": (Image.fromarray(grey.astype(np.uint16) * 257), grey_png),
        "PIL I (8-bit values)": (Image.fromarray(grey, "L").convert("I"), grey_png),
        "PIL I (16-bit values)": (Image.fromarray(grey.astype(np.int32) * 257, "I"), grey_png),
        "PIL F (0..255)": (Image.fromarray(grey, "L").convert("F"), grey_png),
        "PIL F (0..1)": (Image.fromarray(grey.astype(np.float32) / 255.0, "F"), grey_png),
    }


def test_every_picture_form_gives_the_same_drawing(tmp_path):
    grey = _grey()
    forms = _forms(grey, tmp_path)
    drawn = {}
    for name, (form, file) in forms.items():
        dots = pixelpie.stipple(form, points=800, seed=3).dots
        assert len(dots) > 500, name
        if file is None:  # a form of its own (bilevel, YCbCr's rounding): drawn
            continue
        if file not in drawn:
            drawn[file] = pixelpie.stipple(file, points=800, seed=3).dots
        assert np.array_equal(dots, drawn[file]), f"{name} draws another picture"
    # The bilevel forms draw the same two-tone picture.
    assert np.array_equal(
        pixelpie.stipple(forms["bool"][0], points=800, seed=3).dots,
        pixelpie.stipple(forms["PIL 1"][0], points=800, seed=3).dots,
    )
    # In colour too: the same pens' dots from a path, an array and PIL.
    rgb_png = forms["uint8 RGB"][1]
    colour = pixelpie.stipple(rgb_png, points=800, seed=3, pens="cmyk").dots
    for name in ["uint8 RGB", "PIL CMYK", "PIL P", "uint8 RGBA"]:
        dots = pixelpie.stipple(forms[name][0], points=800, seed=3, pens="cmyk").dots
        assert np.array_equal(dots, colour), f"{name} draws another colour picture"


@pytest.mark.parametrize(
    "form,error,words",
    [
        (lambda g: g.astype(np.float64), ValueError, "outside [0, 1], from 0 to 255"),
        (lambda g: g.astype(np.float32) / 255.0 - 0.5, ValueError, "outside [0, 1]"),
        (lambda g: np.where(g > 9, np.nan, 0.5), ValueError, "NaN"),
        (lambda g: g.astype(np.int64), TypeError, "int64"),
        (lambda g: g.astype(np.complex64), TypeError, "complex64"),
        (lambda g: g.astype(object), TypeError, "object"),
        (lambda g: Image.fromarray(g.astype(np.int32) * 70000, "I"), ValueError, "mode 'I'"),
        (lambda g: Image.fromarray(g, "L").convert("F").point(lambda v: v * 300),
         ValueError, "mode 'F'"),
        (lambda g: Image.new("LAB", (8, 8)), ValueError, "mode 'LAB'"),
        (lambda g: 3.5, TypeError, "float"),
        (lambda g: {"pixels": g}, TypeError, "dict"),
    ],
)
def test_what_the_rule_does_not_take_is_refused_by_name(form, error, words):
    with pytest.raises(error) as e:
        pixelpie.stipple(form(_grey()), points=500)
    assert words in str(e.value), str(e.value)
    assert str(e.value).startswith("image"), str(e.value)


def test_sample_takes_its_importance_by_the_same_rule(tmp_path):
    grey = _grey()
    path = tmp_path / "grey.png"
    Image.fromarray(grey, "L").save(path)
    by_path, _ = pixelpie.sample(importance=path, points=900, seed=1)
    # A PIL image and a 3-D array are pictures, decoded as the file is.
    for form in [Image.fromarray(grey, "L"), np.repeat(grey[:, :, None], 3, axis=2)]:
        pts, _ = pixelpie.sample(importance=form, points=900, seed=1)
        assert np.array_equal(pts, by_path)
    # A 2-D array's values are taken as they are, whatever its type.
    as_float, _ = pixelpie.sample(importance=grey / 255.0, points=900, seed=1)
    for form in [grey, grey.astype(np.uint16) * 257, (grey / 255.0).astype(np.float32)]:
        pts, _ = pixelpie.sample(importance=form, points=900, seed=1)
        assert np.array_equal(pts, as_float)
    with pytest.raises(ValueError, match="outside"):
        pixelpie.sample(importance=grey.astype(np.float32), points=900)


# --- Python's exception and warning types -------------------------------------


def test_missing_files_raise_file_not_found_with_errno_and_name(tmp_path):
    missing = tmp_path / "missing.png"
    calls = [
        lambda: pixelpie.stipple(missing),
        lambda: pixelpie.stipple(str(missing)),
        lambda: pixelpie.plan(missing),
        lambda: pixelpie.stipple(ASSETS / "default.png", job=tmp_path / "missing.toml"),
        lambda: pixelpie.stipple(ASSETS / "default.png", pens=tmp_path / "missing.toml"),
        lambda: pixelpie.sample(importance=missing, points=100),
        lambda: pixelpie.sample(100, 100, radius_map=tmp_path / "missing.exr"),
    ]
    for call in calls:
        with pytest.raises(FileNotFoundError) as e:
            call()
        assert e.value.errno == errno.ENOENT
        assert e.value.filename and "missing" in str(e.value.filename)


def test_an_unwritable_output_raises_its_os_error(tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        pixelpie.stipple(ASSETS / "default.png", tmp_path / "no" / "such" / "out.svg", points=300)
    assert e.value.errno == errno.ENOENT and "out.svg" in str(e.value.filename)
    assert not (tmp_path / "no").exists()
    if os.geteuid() != 0:  # root writes anywhere
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        with pytest.raises(PermissionError) as e:
            pixelpie.stipple(ASSETS / "default.png", locked / "out.svg", points=300)
        assert e.value.errno == errno.EACCES


@pytest.mark.parametrize(
    "options,error,words",
    [
        (dict(pens=3), TypeError, "pens must be"),
        (dict(points="100"), TypeError, "points must be a whole number"),
        (dict(relax="tsp"), TypeError, 'relax must be a whole number, at least 0, not the text "tsp"'),
        (dict(width=0), ValueError, "width=0 must be at least 1 px"),
        (dict(order="random"), ValueError, "order"),
    ],
)
def test_bad_options_raise_their_python_type_naming_the_option(options, error, words):
    with pytest.raises(error) as e:
        pixelpie.stipple(ASSETS / "default.png", **options)
    assert words in str(e.value), str(e.value)
    assert "untagged" not in str(e.value) and "variant" not in str(e.value)


def test_a_count_short_of_its_target_warns_with_the_clis_words():
    # 8000 points cannot fit a 60x40 domain at radii of at least 1 px.
    tiny = np.tile(np.linspace(0, 1, 60, dtype=np.float32), (40, 1))
    with pytest.warns(pixelpie.PixelpieWarning, match=r"asked for 8000 points, got \d+") as w:
        pts, stats = pixelpie.sample(importance=tiny, points=8000)
    assert stats["target"] == 8000 and stats["points"] == len(pts) < 8000
    assert len(w) == 1
    with pytest.warns(pixelpie.PixelpieWarning, match="asked for 10000000 points"):
        d = pixelpie.stipple(ASSETS / "default.png", points=10_000_000, width=100, height=100)
    assert d.asked == 10_000_000 and d.reached < d.asked
    assert any("asked for" in w for w in d.warnings)
    # And a count reached warns of nothing.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        d = pixelpie.stipple(ASSETS / "default.png", points=2000)
    assert d.asked == 2000 and abs(d.reached - 2000) < 100 and d.warnings == []


# --- the Drawing -------------------------------------------------------------------


def test_the_drawing_carries_what_comes_next(tmp_path):
    out = tmp_path / "d.svg"
    d = pixelpie.stipple(ASSETS / "rocket.jpg", out, points=3000, paper="a5", pen_mm=0.3,
                         order="tsp")
    # analyze without guessing the domain.
    report = pixelpie.analyze(d.dots, *d.domain)
    assert report["count"] == d.reached == len(d.dots)
    assert d.domain == tuple(d.plan["domain"]) and d.plan["points"] == d.asked == 3000
    # The files' bytes are the written file's, and the PNG is a PNG.
    assert d.svg() == out.read_bytes()
    assert d.png().startswith(b"\x89PNG")
    # The array's behaviour, for code written for the array.
    a = np.asarray(d)
    assert a.shape == d.shape == (d.reached, 3) and len(d) == d.reached
    assert np.array_equal(d[:, :2], d.dots[:, :2]) and d.max() == d.dots.max()
    # Domain pixels to mm on the sheet: inside the A5 sheet's margins.
    mm = d.to_mm(d.dots)
    assert d.page == (148.0, 210.0)
    assert mm[:, 0].min() >= 10 - 1e-9 and mm[:, 0].max() <= 138 + 1e-9
    assert mm[:, 1].min() >= 10 - 1e-9 and mm[:, 1].max() <= 200 + 1e-9
    # The pen paths: one per dot, each starting at its dot's centre, in mm.
    (layer,) = d.paths()
    assert len(layer.paths) == d.reached and layer.pen_mm == 0.3 and layer.colour == "#000000"
    starts = np.array([p[0] for p in layer.paths])
    assert np.allclose(starts, mm, atol=1e-9)
    assert d.pens is None


def test_a_colour_drawing_names_its_pens_and_their_layers():
    d = pixelpie.stipple(ASSETS / "rocket.jpg", points=2000, pens="cmyk", paper="a6",
                         pen_mm=0.3)
    assert [p.name for p in d.pens] == ["cyan", "magenta", "yellow", "black"]
    assert d.dots.shape == (d.reached, 4)
    layers = d.paths()
    # The SVG's layer order: the lightest ink first.
    assert [l.name for l in layers] == ["yellow", "cyan", "magenta", "black"]
    per_pen = {p.name: int((d.dots[:, 3] == k).sum()) for k, p in enumerate(d.pens)}
    assert {l.name: len(l.paths) for l in layers} == per_pen


def test_the_plot_time_is_the_clis_and_a_profile_overrides_it(tmp_path):
    cli = Path(os.environ.get("PIXELPIE_BIN", ROOT / "target" / "release" / "pixelpie"))
    args = dict(points=1500, paper="a5", pen_mm=0.3, order="tsp")
    d = pixelpie.stipple(ASSETS / "rocket.jpg", **args)
    (ink,) = d.plot_stats()
    assert ink["dots"] == ink["lifts"] == d.reached
    # AxiDraw's planner: drawing, travel, and its servo's 0.146 s to lower
    # and 0.130 s to raise the pen a dot.
    parts = ink["pen_down_s"] + ink["pen_up_s"] + 0.276 * ink["lifts"]
    assert abs(ink["seconds"] - parts) < 1e-6 * parts
    # The CLI's table for the same job: the same minutes.
    run = subprocess.run(
        [str(cli), "stipple", str(ASSETS / "rocket.jpg"), "-o", str(tmp_path / "p.svg"),
         "--points", "1500", "--paper", "a5", "--pen-mm", "0.3", "--order", "tsp",
         "--plot-stats", "-q"],
        capture_output=True, text=True, check=True,
    )
    total = float(run.stdout.splitlines()[-1].split("\t")[-1])
    assert abs(ink["seconds"] / 60 - total) <= 0.05
    assert d.plot_stats("axidraw") == [ink]
    # AxiDraw's own option names: a slower pen, slower plots, the same dots.
    (slow,) = d.plot_stats({"speed_pendown": 10, "const_speed": False, "model": 2})
    assert slow["pen_down_s"] > ink["pen_down_s"] and slow["seconds"] > ink["seconds"]
    assert slow["pen_up_s"] == ink["pen_up_s"] and slow["pen_down_mm"] == ink["pen_down_mm"]
    # saxi's, by name and by its option names, from a dict or a profile file.
    (saxi,) = d.plot_stats("saxi")
    assert saxi["pen_down_mm"] == ink["pen_down_mm"] and saxi["seconds"] != ink["seconds"]
    (slow,) = d.plot_stats({"pen_down_max_velocity": 10, "pen_lift_duration": 0.5})
    assert slow["pen_down_s"] > saxi["pen_down_s"] and slow["seconds"] > saxi["seconds"]
    assert slow["pen_up_s"] == saxi["pen_up_s"] and slow["pen_down_mm"] == ink["pen_down_mm"]
    profile = tmp_path / "axidraw.toml"
    profile.write_text("pen_down_max_velocity = 10\npen_lift_duration = 0.5\n")
    assert d.plot_stats(profile) == [slow]
    # Bad profiles are refused naming the key.
    with pytest.raises(ValueError, match="pen_up_acceleration = -1"):
        d.plot_stats({"pen_up_acceleration": -1})
    with pytest.raises(ValueError, match="pen_speed"):
        d.plot_stats({"pen_speed": 3})
    with pytest.raises(TypeError, match="path or a dict"):
        d.plot_stats(3)  # type: ignore[arg-type]


def test_pens_chosen_from_an_inventory_are_the_clis(tmp_path):
    inventory = ASSETS / "pens-24.toml"
    d = pixelpie.stipple(ASSETS / "rocket.jpg", points=2000, pens=inventory, choose=3)
    assert d.pens is not None and len(d.pens) == 3
    run = subprocess.run(
        [str(Path(os.environ.get("PIXELPIE_BIN", ROOT / "target" / "release" / "pixelpie"))),
         "stipple", str(ASSETS / "rocket.jpg"), "-o", str(tmp_path / "c.csv"),
         "--points", "2000", "--pens", str(inventory), "--choose", "3"],
        capture_output=True, text=True, check=True,
    )
    said = next(l for l in run.stderr.splitlines() if l.startswith("chose 3 of 24 pens"))
    assert all(p.name in said for p in d.pens), said
    with pytest.raises(ValueError, match="add choose=K to pick"):
        pixelpie.stipple(ASSETS / "rocket.jpg", points=2000, pens=inventory)


def test_a_drawing_says_in_words_that_it_does_not_pickle():
    import pickle

    d = pixelpie.stipple(ASSETS / "default.png", points=300)
    with pytest.raises(TypeError, match="drawing.dots"):
        pickle.dumps(d)
    assert np.array_equal(pickle.loads(pickle.dumps(d.dots)), d.dots)


def test_paths_without_a_pen_and_page_are_refused_in_words():
    d = pixelpie.stipple(ASSETS / "default.png", points=300)
    with pytest.raises(ValueError, match="pen_mm"):
        d.paths()
    with pytest.raises(ValueError, match="paper or width_mm"):
        d.to_mm(d.dots)


# --- the stubs ---------------------------------------------------------------------

_TYPED = textwrap.dedent(
    """
    from pathlib import Path
    from typing import List, Optional, Tuple

    import numpy as np
    import numpy.typing as npt

    import pixelpie

    pts, stats = pixelpie.sample(256, 256, radius=3.0, seed=1)
    first: npt.NDArray[np.float32] = pts
    count: int = stats["points"]
    maximal: bool = stats["maximal"]
    target: Optional[int] = stats["target"]
    d = pixelpie.stipple("photo.jpg", "out.svg", points=1000, paper="a4", pen_mm=0.3)
    dots: npt.NDArray[np.float32] = d.dots
    domain: Tuple[int, int] = d.domain
    asked: Optional[int] = d.asked
    reached: int = d.reached
    line: str = d.plan["line"]
    relax: int = d.plan["relax"]
    pens: Optional[List[pixelpie.Pen]] = d.pens
    mm: npt.NDArray[np.float64] = d.to_mm(d.dots)
    svg: bytes = d.svg()
    png: bytes = d.png()
    d.save(Path("out.png"))
    for layer in d.paths():
        name: str = layer.name
        width: float = layer.pen_mm
        for path in layer.paths:
            xy: npt.NDArray[np.float64] = path
    for pen in d.plot_stats({"pen_down_max_velocity": 30}):
        minutes: float = pen["seconds"] / 60
        lifts: int = pen["lifts"]
    text: str = pixelpie.stipple("photo.jpg", svg=True)
    plan = pixelpie.plan("photo.jpg", points=5000)
    seconds: float = plan["seconds"]
    report = pixelpie.analyze(d.dots, *d.domain)
    gap: float = report["largest_gap"]["radius"]
    rho: float = report["rho"]
    options = pixelpie.stipple_options()
    defaults = pixelpie.sample_options()
    said: List[str] = d.warnings
    drawn = pixelpie.stipple("photo.jpg", style="line", line_smooth=True, width_mm=90, pen_mm=0.8)
    style: str = drawn.style
    vertices: npt.NDArray[np.float32] = drawn.line
    for stroke in drawn.strokes:
        across: float = stroke.width
        smooth: bool = stroke.smooth
        points: npt.NDArray[np.float32] = stroke.points
    line_plan = pixelpie.plan("photo.jpg", style="line", pen_mm=0.8, width_mm=90)
    needed: int = line_plan["line_plan"]["needed"]
    wide: Optional[float] = line_plan["line_plan"]["width_mm"]
    """
)


def test_mypy_strict_accepts_every_documented_call_with_no_any(tmp_path):
    script = tmp_path / "typed.py"
    script.write_text(_TYPED)
    run = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--disallow-any-expr",
         "--no-incremental", str(script)],
        capture_output=True, text=True, cwd=tmp_path,
    )
    assert run.returncode == 0, run.stdout + run.stderr


# --- the memory budget ---------------------------------------------------------


def _png_bomb(path: Path, w: int, h: int) -> None:
    """A grey PNG of one value: its rows compress to almost nothing."""
    import struct
    import zlib

    row = b"\x00" + b"\x80" * w
    z = zlib.compressobj(1)
    data = b"".join(z.compress(row) for _ in range(h)) + z.flush()

    def chunk(kind: bytes, body: bytes) -> bytes:
        crc = zlib.crc32(kind + body) & 0xFFFFFFFF
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", crc)

    header = struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", data)
                     + chunk(b"IEND", b""))


def test_a_picture_over_the_memory_budget_raises_memory_error_at_once(tmp_path):
    bomb = tmp_path / "bomb.png"
    _png_bomb(bomb, 20_000, 20_000)  # 400 Mpx: about 8 GB to draw
    out = tmp_path / "x.svg"
    for call in [
        lambda: pixelpie.stipple(bomb, out),
        lambda: pixelpie.plan(bomb),
        lambda: pixelpie.sample(importance=bomb, points=1000),
    ]:
        start = time.monotonic()
        with pytest.raises(MemoryError, match=r"20000×20000 \(400 Mpx\).*allowed"):
            call()
        assert time.monotonic() - start < 2
    assert not out.exists()
    # A call's own budget: a small picture refused under a small one, in
    # every picture form, and drawn under a larger one.
    grey = np.zeros((1500, 2000), dtype=np.uint8)
    for form in [grey, Image.fromarray(grey)]:
        with pytest.raises(MemoryError, match="2000×1500"):
            pixelpie.stipple(form, points=300, max_memory="50M")
    assert pixelpie.stipple(grey, points=300, max_memory=100 << 20).reached > 0
    # The call's budget holds for the drawing's domain too.
    small = np.zeros((24, 32), dtype=np.uint8)
    with pytest.raises(MemoryError, match="2000×1500 domain"):
        pixelpie.stipple(small, points=300, width=2000, height=1500, max_memory="50M")
    with pytest.raises(MemoryError, match="2000×1500 domain"):
        pixelpie.plan(small, points=300, width=2000, height=1500, max_memory="50M")
    assert pixelpie.stipple(small, points=300, width=2000, height=1500,
                            max_memory="100M").domain == (2000, 1500)
    with pytest.raises(MemoryError, match="point set on a 3000×3000"):
        pixelpie.sample(3000, 3000, radius=5.0, max_memory="100M")
    with pytest.raises(ValueError, match="not a size"):
        pixelpie.stipple(grey, max_memory="lots")
    with pytest.raises(TypeError, match="max_memory"):
        pixelpie.stipple(grey, max_memory=1.5)


# --- random keywords -------------------------------------------------------------


def test_random_keywords_give_a_drawing_or_a_typed_error():
    import random

    rnd = random.Random(7)
    names = sorted(pixelpie.stipple_options())
    values = [None, True, False, 0, 1, -1, 3, 2.5, -0.5, 1e9, float("nan"), "", "x", "a4",
              "#ff0000", "cmyk", "tsp", "on", [1, 2], ["#000000"], {"a": 1}, b"x"]
    picture = np.tile(np.linspace(0, 255, 32, dtype=np.uint8), (24, 1))
    drew = refused = 0
    for _ in range(400):
        options = {n: rnd.choice(values) for n in rnd.sample(names, rnd.randint(1, 3))}
        options.setdefault("points", rnd.randint(20, 300))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                d = pixelpie.stipple(picture, **options)
            assert d.reached >= 0
            drew += 1
        except (ValueError, TypeError, FileNotFoundError, MemoryError) as e:
            assert "\n" not in str(e) and str(e), (options, e)
            refused += 1
    assert drew > 5 and refused > 100, (drew, refused)
