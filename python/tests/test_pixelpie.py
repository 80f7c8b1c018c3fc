"""Tests of the pixelpie Python package.

* The points are the command line's for the same parameters, bit for bit,
  and so are the stipple drawings' bytes.
* Maximality and the minimum distance, checked independently with scipy.
* Every error case: ValueError for bad arguments, OSError for files.
* Cancellation (KeyboardInterrupt between iterations) and the released GIL.

The CLI is ``$PIXELPIE_BIN``, or ``target/release/pixelpie`` of this
checkout; a missing binary fails the tests that compare with it.
"""

from __future__ import annotations

import _thread
import math
import os
import re
import json
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

import pixelpie

ROOT = Path(__file__).resolve().parents[2]
ASSETS = ROOT / "assets"
CLI = Path(os.environ.get("PIXELPIE_BIN", ROOT / "target" / "release" / "pixelpie"))


def cli(*args: str) -> subprocess.CompletedProcess:
    assert CLI.is_file(), f"the pixelpie binary is missing at {CLI} (cargo build --release)"
    return subprocess.run([str(CLI), *args], capture_output=True, text=True, check=True)


def cli_points(tmp_path: Path, *args: str) -> np.ndarray:
    out = tmp_path / "cli.csv"
    cli("sample", *args, "--quiet", "-o", str(out))
    # The CSV holds the shortest decimals that read back exactly as f32.
    return np.loadtxt(out, delimiter=",", skiprows=1, dtype=np.float64).astype(np.float32).reshape(-1, 3)


# --- the command line's points, bit for bit ---------------------------------

CASES = [
    (dict(radius=4.0), ["--radius", "4"]),
    (dict(radius=3.3, periodic=True, seed=9), ["--radius", "3.3", "--periodic", "--seed", "9"]),
    (dict(points=3000, seed=2), ["--points", "3000", "--seed", "2"]),
    (dict(radius=2.5, exact=True, seed=4), ["--radius", "2.5", "--exact", "--seed", "4"]),
    (dict(radius=5.0, subpixel_bits=0, policy="prior"), ["--radius", "5", "--subpixel-bits", "0"]),
]


@pytest.mark.parametrize("kwargs,args", CASES)
def test_uniform_points_are_the_clis(tmp_path, kwargs, args):
    kwargs = dict(kwargs)
    policy = kwargs.pop("policy", "smaller")
    pts, stats = pixelpie.sample(300, 200, policy=policy, **kwargs)
    want = cli_points(tmp_path, "--width", "300", "--height", "200", "--policy", policy, *args)
    assert pts.dtype == np.float32 and pts.shape == want.shape
    assert np.array_equal(pts, want)
    assert stats["points"] == len(pts) and stats["maximal"]


@pytest.mark.parametrize("policy", ["prior", "current", "bigger", "smaller"])
def test_importance_points_are_the_clis(tmp_path, policy):
    image = ASSETS / "gradient.exr"
    pts, stats = pixelpie.sample(256, 160, importance=image, points=2000, policy=policy, seed=1)
    want = cli_points(
        tmp_path,
        "--width", "256", "--height", "160", "--importance", str(image),
        "--points", "2000", "--policy", policy, "--seed", "1",
    )
    assert np.array_equal(pts, want)
    assert stats["points"] == len(pts)
    # Radii vary with the map.
    assert pts[:, 2].min() < pts[:, 2].max()


def test_importance_with_a_min_radius_is_the_clis(tmp_path):
    image = ASSETS / "default.png"
    pts, _ = pixelpie.sample(400, 300, importance=str(image), min_radius=1.5, policy="bigger")
    want = cli_points(
        tmp_path,
        "--width", "400", "--height", "300", "--importance", str(image),
        "--min-radius", "1.5", "--policy", "bigger",
    )
    assert np.array_equal(pts, want)


def test_radius_map_samples_its_radii_and_points_scale_it():
    h, w = 120, 160
    rmap = np.where(np.arange(w)[None, :] < w // 2, 2.0, 5.0) * np.ones((h, 1))
    pts, stats = pixelpie.sample(w, h, radius_map=rmap, policy="smaller", seed=3)
    assert stats["maximal"]
    assert set(np.unique(pts[:, 2])) == {2.0, 5.0}
    left = pts[pts[:, 0] < w // 2 - 5]
    assert np.all(left[:, 2] == 2.0)
    scaled, _ = pixelpie.sample(w, h, radius_map=rmap, points=600, seed=3)
    assert abs(len(scaled) - 600) <= 0.03 * 600


def test_stipple_writes_the_clis_bytes(tmp_path):
    image = ASSETS / "default.png"
    for name, extra_py, extra_cli in [
        ("a.svg", {}, []),
        ("b.svg", dict(points=3000, relax=2, order="tsp", dot="fixed"),
         ["--points", "3000", "--relax", "2", "--order", "tsp", "--dot", "fixed"]),
        ("c.png", dict(points=2000, scale=0.5, white_cutoff=0.9),
         ["--points", "2000", "--scale", "0.5", "--white-cutoff", "0.9"]),
    ]:
        ours, theirs = tmp_path / ("py-" + name), tmp_path / ("cli-" + name)
        dots = pixelpie.stipple(image, ours, **extra_py)
        cli("stipple", str(image), "-o", str(theirs), "--quiet", *extra_cli)
        assert ours.read_bytes() == theirs.read_bytes(), name
        assert dots.shape[1] == 3 and len(dots) > 500
        assert np.all(dots[:, 2] > 0)


# Every option of the drawing job, once each, beside 800 dots: Python's file
# must be the command line's, byte for byte.
EVERY_OPTION = [
    ("points", 900, "a.svg"),
    ("width", 700, "a.svg"),
    ("height", 500, "a.svg"),
    ("dot", "proportional", "a.svg"),
    ("dot_factor", 0.8, "a.svg"),
    ("dot_ratio", 0.5, "a.svg"),
    ("dot_radius", 4.0, "a.svg"),
    ("relax", 2, "a.svg"),
    ("order", "tsp", "a.svg"),
    ("scale", 0.5, "a.png"),
    ("width_mm", 120.0, "a.svg"),
    ("pen_mm", 0.35, "a.svg"),
    ("ink", "#d62728", "a.png"),
    ("policy", "prior", "a.svg"),
    ("seed", 11, "a.svg"),
    ("subpixel_bits", 1, "a.svg"),
    ("periodic", True, "a.svg"),
    ("exact", True, "a.svg"),
    ("tones", "linear", "a.svg"),
    ("mapping", "linear", "a.svg"),
    ("min_radius", 3.0, "a.svg"),
    ("max_radius", 20.0, "a.svg"),
    ("gamma", 1.8, "a.svg"),
    ("black_level", 0.1, "a.svg"),
    ("white_level", 0.8, "a.svg"),
    ("invert", True, "a.svg"),
    ("white_cutoff", 0.85, "a.svg"),
    ("hdr_white", 0.7, "a.svg"),
    ("pens", "cmyk", "a.svg"),
    ("paper", "a5", "a.svg"),
    ("margin", 25.0, "a.svg"),
    ("landscape", True, "a.svg"),
    ("size_px", True, "a.svg"),
    ("choose", 3, "a.svg"),
    ("paper_colour", "kraft", "a.png"),
    ("dot_path", "circle", "a.svg"),
    ("crop", "40,20,300,200", "a.svg"),
    ("dot_mm", 1.2, "a.svg"),
    ("rotate", 90, "a.svg"),
    ("refill_mm", 300.0, "a.svg"),
    ("layer_order", "pens", "a.svg"),
    ("spacing", "radius", "a.svg"),
    ("correction", "off", "a.svg"),
    ("style", "line", "a.svg"),
    ("line_smooth", True, "a.svg"),
    ("poster", "500x300", "poster"),
]


def test_a_job_file_replays_the_clis_drawing(tmp_path):
    job, theirs, ours = tmp_path / "job.toml", tmp_path / "cli.svg", tmp_path / "py.svg"
    image = ASSETS / "rocket.jpg"
    cli("stipple", str(image), "-o", str(theirs), "--quiet", "--points", "700", "--pens", "cmyk",
        "--relax", "1", "--save-job", str(job))
    pixelpie.stipple(image, ours, job=job)
    assert ours.read_bytes() == theirs.read_bytes()
    # Options given with it override it.
    other = tmp_path / "other.svg"
    pixelpie.stipple(image, other, job=job, seed=4)
    assert other.read_bytes() != theirs.read_bytes()
    # Unknown settings are refused by name; another version warns.
    bad = tmp_path / "bad.toml"
    bad.write_text('pixelpie = "0.1.0"\nrelaxx = 2\n')
    with pytest.raises(ValueError, match="relaxx"):
        pixelpie.stipple(image, job=bad)
    old = tmp_path / "old.toml"
    old.write_text('pixelpie = "0.0.1"\npoints = 300\n')
    with pytest.warns(UserWarning, match="0.0.1"):
        pixelpie.stipple(image, job=old)


def test_a_paper_job_takes_a_width_in_mm_as_the_cli_does(tmp_path):
    # The library lays the options over the file: a width in mm drops the
    # file's paper, as --width-mm does on the command line.
    job, theirs, ours = tmp_path / "job.toml", tmp_path / "cli.svg", tmp_path / "py.svg"
    image = ASSETS / "rocket.jpg"
    cli("stipple", str(image), "-o", str(tmp_path / "a.svg"), "--quiet", "--points", "500",
        "--paper", "a5", "--save-job", str(job))
    cli("stipple", str(image), "-o", str(theirs), "--quiet", "--job", str(job),
        "--width-mm", "120")
    pixelpie.stipple(image, ours, job=job, width_mm=120.0)
    assert ours.read_bytes() == theirs.read_bytes()


@pytest.mark.parametrize("points", [10_000, 250_000])
def test_the_plan_is_the_clis(tmp_path, points):
    image = ASSETS / "rocket.jpg"
    out = tmp_path / "x.svg"
    theirs = json.loads(cli("stipple", str(image), "-o", str(out), "--points", str(points),
                            "--plan").stdout)
    ours = pixelpie.plan(image, points=points)
    assert ours == theirs
    assert not out.exists()
    assert ours["line"].startswith(f"{points:,} dots".replace(",", " "))
    if points <= 200_000:
        assert ours["corrected"] and ours["relax"] == 2 and not ours["spread"]
    else:
        assert ours["relax"] == 0


def test_a_lines_plan_is_the_clis(tmp_path):
    # The command line's JSON names the summary "line", and (this
    # version's) the line's own plan "line" too, or "line_plan": Python's
    # plan keeps the summary as "line" and the line's plan as "line_plan".
    image = ASSETS / "rocket.jpg"
    out = tmp_path / "x.svg"
    text = cli("stipple", str(image), "-o", str(out), "--style", "line", "--width-mm", "60",
               "--pen-mm", "0.8", "--plan").stdout
    pairs = json.loads(text, object_pairs_hook=list)
    summary = [v for k, v in pairs if k == "line" and isinstance(v, str)]
    line_plan = [v for k, v in pairs if k in ("line", "line_plan") and not isinstance(v, str)]
    assert len(summary) == len(line_plan) == 1, pairs
    ours = pixelpie.plan(image, style="line", width_mm=60, pen_mm=0.8)
    assert ours["line"] == summary[0] and ours["line_plan"] == dict(line_plan[0])
    rest = {k: v for k, v in json.loads(text).items() if k not in ("line", "line_plan")}
    assert {k: v for k, v in ours.items() if k not in ("line", "line_plan")} == rest
    assert ours["style"] == "line" and not out.exists()


def test_every_stipple_option_is_tested_against_the_cli():
    assert sorted(name for name, _, _ in EVERY_OPTION) == sorted(pixelpie.stipple_options())


@pytest.mark.parametrize("name,value,out", EVERY_OPTION, ids=[o[0] for o in EVERY_OPTION])
def test_every_stipple_option_gives_the_clis_file(tmp_path, name, value, out):
    image = ASSETS / {"hdr_white": "gradient.exr", "pens": "rocket.jpg"}.get(name, "default.png")
    kwargs = {name: value}
    args = ["--" + name.replace("_", "-")]
    if value is not True:
        args.append(str(value))
    # Options that need a partner, or that set the count themselves.
    if name in ("pen_mm", "dot_path", "refill_mm", "dot_mm"):
        kwargs["width_mm"] = 120.0
        args += ["--width-mm", "120"]
    if name == "layer_order":
        kwargs["pens"] = "cmyk"
        args += ["--pens", "cmyk"]
    if name == "line_smooth":
        kwargs["style"] = "line"
        args += ["--style", "line"]
    if name in ("dot_path", "refill_mm"):
        kwargs["pen_mm"] = 0.3
        args += ["--pen-mm", "0.3"]
    if name in ("margin", "landscape", "size_px", "poster"):
        kwargs["paper"] = "a4"
        args += ["--paper", "a4"]
    if name == "choose":
        kwargs["pens"] = str(ASSETS / "pens-24.toml")
        args += ["--pens", str(ASSETS / "pens-24.toml")]
    if name == "paper_colour":
        kwargs["pens"] = "#202020"
        args += ["--pens", "#202020"]
    if name not in ("points", "dot_radius", "min_radius", "pen_mm", "dot_mm"):
        kwargs["points"] = 800
        args += ["--points", "800"]
    ours, theirs = tmp_path / ("py-" + out), tmp_path / ("cli-" + out)
    pixelpie.stipple(image, ours, **kwargs)
    cli("stipple", str(image), "-o", str(theirs), "--quiet", *args)
    if ours.is_dir():  # a poster's folder: its sheets and poster.json
        names = sorted(p.name for p in ours.iterdir())
        assert names == sorted(p.name for p in theirs.iterdir()) and len(names) > 2
        assert all((ours / n).read_bytes() == (theirs / n).read_bytes() for n in names)
    else:
        assert ours.read_bytes() == theirs.read_bytes()


def test_pens_return_a_pen_column_and_write_the_clis_files(tmp_path):
    image = ASSETS / "rocket.jpg"
    dots = pixelpie.stipple(image, tmp_path / "py.csv", pens="cmyk", points=2000)
    cli("stipple", str(image), "-o", str(tmp_path / "cli.csv"), "--quiet",
        "--pens", "cmyk", "--points", "2000")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    assert dots.shape == (len(dots), 4) and len(dots) > 1500
    pens = dots[:, 3]
    assert set(np.unique(pens)) <= {0.0, 1.0, 2.0, 3.0}
    assert len(np.unique(pens)) >= 3
    # The pen column of the CSV is the array's.
    csv = np.loadtxt(tmp_path / "py.csv", delimiter=",", skiprows=1)
    assert np.array_equal(np.sort(csv[:, 3]), np.sort(pens))
    # A list of colours, and a pen file given as a path.
    two = pixelpie.stipple(image, pens=["#000000", "#d62728"], points=1000)
    assert set(np.unique(two[:, 3])) == {0.0, 1.0}
    pen_file = tmp_path / "pens.toml"
    pen_file.write_text('[[pen]]\nname = "blue"\ncolour = "#1f77b4"\n[[pen]]\nname = "k"\ncolour = "#000000"\n')
    assert pixelpie.stipple(image, pens=pen_file, points=1000).shape[1] == 4
    for bad in ["rainbow", ["#000000", "#000000"], [], "#12345"]:
        with pytest.raises(ValueError, match="pens"):
            pixelpie.stipple(image, pens=bad, points=1000)


def test_unknown_options_are_refused_with_the_known_ones():
    with pytest.raises(ValueError, match="unexpected option 'pointz'") as e:
        pixelpie.stipple(ASSETS / "default.png", pointz=100)
    assert "points" in str(e.value)


def test_stipple_without_output_returns_the_dots_only(tmp_path):
    dots = pixelpie.stipple(ASSETS / "default.png", points=1500)
    assert abs(len(dots) - 1500) <= 0.03 * 1500
    assert list(tmp_path.iterdir()) == []


def test_analyze_is_the_clis(tmp_path):
    pts, _ = pixelpie.sample(200, 200, radius=5.0, seed=1, periodic=True)
    csv = tmp_path / "p.csv"
    cli("sample", "--width", "200", "--height", "200", "--radius", "5", "--seed", "1",
        "--periodic", "--policy", "smaller", "--quiet", "-o", str(csv))
    import json
    want = json.loads(cli("analyze", str(csv), "--width", "200", "--height", "200",
                          "--periodic").stdout)
    got = pixelpie.analyze(pts, 200, 200, periodic=True)
    assert got == want
    assert got["count"] == len(pts) and got["uncovered_pixels"] == 0


# --- properties, checked with scipy -----------------------------------------


def probes(w: float, h: float, step: float) -> np.ndarray:
    xs = np.arange(0.0, w + 1e-9, step)
    ys = np.arange(0.0, h + 1e-9, step)
    gx, gy = np.meshgrid(xs, ys)
    return np.column_stack([gx.ravel(), gy.ravel()])


def closest_pair(xy: np.ndarray, box=None) -> float:
    tree = cKDTree(xy, boxsize=box)
    d, _ = tree.query(xy, k=2)
    return float(d[:, 1].min())


@pytest.mark.parametrize("periodic", [False, True])
def test_exact_sets_meet_the_disk_condition_and_cover_every_point(periodic):
    r, w, h = 3.0, 240, 180
    pts, stats = pixelpie.sample(w, h, radius=r, exact=True, periodic=periodic, seed=7)
    assert stats["maximal"] and stats["exact"]
    xy = pts[:, :2].astype(np.float64)
    box = (w, h) if periodic else None
    if periodic:
        xy = np.mod(xy, (w, h))
    assert closest_pair(xy, box) >= r
    # Every probe (every 1/8 px, edges included) lies within r of a sample.
    q = probes(w, h, 0.125)
    if periodic:
        q = np.mod(q, (w, h))
    d, _ = cKDTree(xy, boxsize=box).query(q)
    assert d.max() < r


def test_pixel_mode_sets_cover_every_pixel_centre_within_their_slack():
    r, w, h = 4.0, 256, 192
    pts, stats = pixelpie.sample(w, h, radius=r, seed=11)
    assert stats["maximal"] and not stats["exact"]
    xy = pts[:, :2].astype(np.float64)
    # The paper's pixel-resolution bound: at most sqrt(2)/2 px of slack.
    assert closest_pair(xy) >= r - math.sqrt(0.5)
    centres = probes(w - 1, h - 1, 1.0) + 0.5
    d, _ = cKDTree(xy).query(centres)
    assert d.max() < r


def test_the_same_seed_gives_the_same_points_and_another_seed_others():
    a, _ = pixelpie.sample(128, 128, radius=3.0, seed=5)
    b, _ = pixelpie.sample(128, 128, radius=3.0, seed=5)
    c, _ = pixelpie.sample(128, 128, radius=3.0, seed=6)
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def test_a_capped_run_is_reported_not_maximal():
    pts, stats = pixelpie.sample(300, 300, radius=2.0, max_iterations=2)
    assert not stats["maximal"] and stats["iterations"] == 2 and len(pts) > 0


# --- errors ------------------------------------------------------------------


@pytest.mark.parametrize("kwargs,text", [
    (dict(radius=0.0), "radius"),
    (dict(radius=-2.0), "radius"),
    (dict(radius=float("nan")), "radius"),
    (dict(radius=500.0), "radius"),
    (dict(), "give radius"),
    (dict(radius=3.0, points=100), "not both"),
    (dict(radius=3.0, policy="largest"), "policy"),
    (dict(radius=3.0, backend="tpu"), "backend"),
    (dict(radius=3.0, subpixel_bits=9), "sub-pixel"),
    (dict(points=0), "points=0"),
    (dict(radius_map=np.full((10, 10), 2.0)), "radius map"),
    (dict(radius_map=np.full((50, 40), np.nan)), "radius"),
    (dict(radius_map=np.full((50, 40), 2.0), radius=2.0), "uniform"),
    (dict(importance=np.full((50, 40), 0.5), radius=2.0), "min_radius"),
    (dict(importance=np.full((40, 50), 0.5), points=100), "transpose"),
    (dict(importance=np.full((5, 5), 1.5), points=10), "outside [0, 1]"),
    (dict(importance=np.full((5, 5), 0.5)), "importance"),
    (dict(importance=np.zeros(5), points=10), "2-D"),
])
def test_bad_arguments_raise_value_error(kwargs, text):
    with pytest.raises(ValueError, match=None) as e:
        pixelpie.sample(40, 50, **kwargs)
    assert text.lower() in str(e.value).lower(), str(e.value)
    assert "\n" not in str(e.value)


@pytest.mark.parametrize("w,h", [(0, 10), (10, 0), (1 << 20, 1 << 20)])
def test_impossible_sizes_raise_value_error(w, h):
    with pytest.raises(ValueError):
        pixelpie.sample(w, h, radius=2.0)


def test_the_gpu_backend_is_not_built_in():
    with pytest.raises(RuntimeError, match="gpu"):
        pixelpie.sample(64, 64, radius=3.0, backend="gpu")


def test_unreadable_files_raise_os_error(tmp_path):
    missing = tmp_path / "missing.png"
    empty = tmp_path / "empty.png"
    empty.write_bytes(b"")
    corrupt = tmp_path / "corrupt.png"
    corrupt.write_bytes(b"\x89PNG\r\n\x1a\nnot a png at all")
    for path in [missing, empty, corrupt]:
        with pytest.raises(OSError) as e:
            pixelpie.sample(64, 64, importance=path, points=100)
        assert path.name in str(e.value)
        with pytest.raises(OSError):
            pixelpie.stipple(path, tmp_path / "out.svg")
    assert not (tmp_path / "out.svg").exists()


def test_unwritable_outputs_raise_os_error_and_leave_nothing(tmp_path):
    target = tmp_path / "no-such-dir" / "out.svg"
    with pytest.raises(OSError, match="cannot write"):
        pixelpie.stipple(ASSETS / "default.png", target, points=500)
    assert not target.parent.exists()


@pytest.mark.parametrize("kwargs,text", [
    (dict(output="drawing.gif"), "extension"),
    (dict(output="drawing.svg", scale=2.0), "scale"),
    (dict(dot="huge"), "dot"),
    (dict(order="random"), "order"),
    (dict(tones="sepia"), "tones"),
    (dict(dot_ratio=0.0), "dot_ratio=0"),
    (dict(pen_mm=0.3, output="x.svg"), "width_mm"),
    (dict(dot_radius=3.0), "dot_radius"),
    (dict(ink="teal"), "ink"),
    (dict(white_cutoff=2.0), "cutoff"),
    (dict(gamma=-1.0), "gamma"),
])
def test_bad_stipple_arguments_raise_value_error(tmp_path, kwargs, text):
    if "output" in kwargs:
        kwargs["output"] = tmp_path / kwargs["output"]
    with pytest.raises(ValueError) as e:
        pixelpie.stipple(ASSETS / "default.png", points=300, **kwargs)
    assert text.lower() in str(e.value).lower(), str(e.value)
    assert list(tmp_path.iterdir()) == []


def test_bad_analyze_arguments_raise_value_error():
    pts = np.zeros((4, 2))
    with pytest.raises(ValueError):
        pixelpie.analyze(pts, 0, 10)
    with pytest.raises(ValueError):
        pixelpie.analyze(np.zeros((4, 1)), 10, 10)
    with pytest.raises(ValueError):
        pixelpie.analyze(pts, 10, 10, radius=-1)


# --- cancellation and the GIL ------------------------------------------------


def test_progress_is_called_after_every_iteration():
    seen = []
    pts, stats = pixelpie.sample(300, 300, radius=2.0, progress=lambda *a: seen.append(a))
    assert len(seen) == stats["iterations"] > 3
    assert [s[0] for s in seen] == list(range(1, len(seen) + 1))
    assert seen[-1][1] == len(pts) and seen[-1][2] == 0 and seen[-1][3] == 300 * 300


def test_an_exception_in_progress_stops_the_run_and_is_raised():
    calls = []

    def progress(*a):
        calls.append(a)
        raise ZeroDivisionError("stop here")

    with pytest.raises(ZeroDivisionError, match="stop here"):
        pixelpie.sample(400, 400, radius=2.0, progress=progress)
    assert len(calls) == 1


@pytest.mark.parametrize("exact", [False, True])
def test_ctrl_c_cancels_between_iterations(exact):
    # interrupt_main() is what Ctrl-C does: it trips the SIGINT flag. The
    # library checks for signals after every iteration and stops there, so
    # exactly one iteration runs (a full run takes many).
    calls = []

    def progress(*a):
        calls.append(a)
        if len(calls) == 1:
            _thread.interrupt_main()

    with pytest.raises(KeyboardInterrupt):
        pixelpie.sample(600, 600, radius=2.0, exact=exact, progress=progress)
    assert len(calls) == 1
    _, stats = pixelpie.sample(600, 600, radius=2.0, exact=exact)
    assert stats["iterations"] > 3


def test_ctrl_c_cancels_a_stipple_too():
    calls = []

    def progress(*a):
        calls.append(a)
        _thread.interrupt_main()

    with pytest.raises(KeyboardInterrupt):
        pixelpie.stipple(ASSETS / "default.png", points=5000, progress=progress)
    assert len(calls) == 1


def test_the_gil_is_released_while_sampling():
    # While one thread samples, the main thread keeps running Python code.
    started, done = threading.Event(), threading.Event()
    counts = []

    def work():
        pixelpie.sample(2048, 2048, radius=2.0, exact=True,
                        progress=lambda *a: started.set())
        done.set()

    t = threading.Thread(target=work)
    t.start()
    assert started.wait(60)
    n = 0
    while not done.is_set():
        n += 1
    t.join()
    counts.append(n)
    assert counts[0] > 1000, counts


# --- one definition of the options -------------------------------------------


def _stub_parameters(name):
    """The parameter names of function ``name`` in the type stubs."""
    import ast

    stubs = Path(pixelpie.__file__).with_name("__init__.pyi")
    tree = ast.parse(stubs.read_text())
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name == name:
            a = node.args
            return {x.arg for x in a.args + a.kwonlyargs}
    raise AssertionError(f"{name} is not in the stubs")


@pytest.mark.parametrize("function,options", [
    ("stipple", pixelpie.stipple_options),
    ("sample", pixelpie.sample_options),
])
def test_the_stubs_cover_every_option_of_the_job(function, options):
    missing = set(options()) - _stub_parameters(function)
    assert not missing, f"{function}'s stubs lack {sorted(missing)}"


def test_sample_reads_its_defaults_from_the_library():
    d = pixelpie.sample_options()
    assert d["policy"] == "smaller" and d["subpixel_bits"] == 3
    assert pixelpie.stipple_options()["dot_ratio"] == 0.3


@pytest.mark.parametrize("call,error", [
    (lambda: pixelpie.sample(-1, 10, radius=2.0), ValueError),
    (lambda: pixelpie.sample(100.7, 100, radius=2.0), TypeError),
    (lambda: pixelpie.sample("100", 100, radius=2.0), TypeError),
    (lambda: pixelpie.sample(100, 100, points=-5), ValueError),
    (lambda: pixelpie.sample(100, 100, radius=2.0, seed=-1), ValueError),
    (lambda: pixelpie.sample(100, 100, points=50.5), TypeError),
    (lambda: pixelpie.stipple(ASSETS / "default.png", points=-5), ValueError),
    (lambda: pixelpie.stipple(ASSETS / "default.png", width=100.7), TypeError),
    (lambda: pixelpie.stipple(ASSETS / "default.png", points="100"), TypeError),
    (lambda: pixelpie.stipple(ASSETS / "default.png", pens=3), TypeError),
    (lambda: pixelpie.stipple(ASSETS / "default.png", width=0), ValueError),
    (lambda: pixelpie.stipple(ASSETS / "default.png", pens="nonsense"), ValueError),
    (lambda: pixelpie.analyze(np.array([[1.0, np.nan]]), 10, 10), ValueError),
    (lambda: pixelpie.analyze(np.array([[1.0, np.inf], [2.0, 2.0]]), 10, 10), ValueError),
    (lambda: pixelpie.analyze(np.array([[1.0, 1.0, np.nan]]), 10, 10), ValueError),
])
def test_bad_values_and_types_raise_value_or_type_error(call, error):
    with pytest.raises(error) as e:
        call()
    assert "\n" not in str(e.value)
    assert "pens: pens:" not in str(e.value)


def test_analyze_names_continuous_maximality_apart_from_the_runs():
    pts, stats = pixelpie.sample(128, 128, radius=4.0, seed=1)
    report = pixelpie.analyze(pts, 128, 128)
    assert stats["maximal"] is True
    assert "maximal" not in report and "continuous_maximal" in report


def test_stipple_takes_an_array_and_returns_the_svg(tmp_path):
    grey = np.tile(np.linspace(0.0, 1.0, 200, dtype=np.float32), (120, 1))
    dots = pixelpie.stipple(grey, points=800, seed=2)
    # Dark on the left: more ink there than on the right (domain pixels).
    x = dots[:, 0] / dots[:, 0].max()
    ink = dots[:, 2] ** 2
    assert ink[x < 0.3].sum() > 2 * ink[x > 0.7].sum()
    # The same picture as uint8 and as float gives the same drawing when
    # the values are the same 8-bit levels.
    levels = np.round(grey * 255).astype(np.uint8)
    a = pixelpie.stipple(levels, points=800, seed=2)
    b = pixelpie.stipple(levels.astype(np.float32) / 255.0, points=800, seed=2)
    assert np.array_equal(a, b)
    # Colour arrays draw with pens.
    rgb = np.zeros((80, 100, 3), dtype=np.uint8)
    rgb[:, :50] = (200, 30, 30)
    rgb[:, 50:] = (30, 30, 200)
    cdots = pixelpie.stipple(rgb, points=600, pens="cmyk")
    assert cdots.shape[1] == 4 and len(set(cdots[:, 3].tolist())) >= 2
    # The SVG in memory is the file's text.
    out = tmp_path / "d.svg"
    text = pixelpie.stipple(ASSETS / "default.png", out, points=500, svg=True)
    assert isinstance(text, str) and text == out.read_text()
    with pytest.raises(ValueError):
        pixelpie.stipple(np.zeros((0, 5)), points=10)
    with pytest.raises(TypeError):
        pixelpie.stipple(np.zeros((5, 5), dtype=np.complex64), points=10)


def test_stipple_of_a_pil_image_is_the_files_drawing():
    from PIL import Image

    path = ASSETS / "default.png"
    with Image.open(path) as img:
        from_pil = pixelpie.stipple(img, points=1500, seed=4)
    from_file = pixelpie.stipple(path, points=1500, seed=4)
    assert np.array_equal(from_pil, from_file)


def python_blocks(page: Path) -> list:
    """The ```python blocks of a page."""
    return re.findall(r"^```python\n(.*?)^```", page.read_text(), re.M | re.S)


@pytest.mark.parametrize("page", ["README.md", "docs/python.md"])
def test_the_docs_python_examples_run_as_written(tmp_path, page):
    # Each block as a script of its own, as a reader runs it (a process pool
    # needs a real __main__).
    blocks = python_blocks(ROOT / page)
    assert blocks, page
    (tmp_path / "assets").symlink_to(ASSETS)
    out = []
    for i, block in enumerate(blocks):
        script = tmp_path / f"block{i}.py"
        script.write_text(block)
        run = subprocess.run([sys.executable, str(script)], cwd=tmp_path,
                             capture_output=True, text=True, timeout=300)
        assert run.returncode == 0, f"{page} block {i}:\n{block}\n{run.stderr}"
        out.append(run.stdout)
    # What they say: the sample is maximal, the drawing is written, and
    # every check a block prints holds.
    assert out[0].split()[1] == "True", out[0]
    assert not any("False" in o for o in out), out
    assert (tmp_path / "stipple.png").stat().st_size > 0
