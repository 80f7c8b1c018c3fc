"""Tests of the vpype plugin (`vpype pixelpie`) and of G-code and HPGL
through vpype.

* The plugin loads through the ``vpype.plugins`` entry point.
* Each pen is a layer with the pen's name, colour and width, and as many
  paths as the command line draws dots for that pen with the same options.
* A grey drawing gives vpype the same paths as the command line's SVG read
  by vpype; the page is the sheet.
* HPGL (vpype's ``write --device hp7475a``) selects one pen per layer
  (SP1..SP4) and puts it down once per path; no dot is cut by the
  plotter's reach: ``--device`` fits the drawing inside it, and without it a
  warning names the plotters that would cut dots; G-code (vpype-gcode's
  ``gwrite`` with our profile) pauses for one pen change per layer and
  lowers the pen once per path.
* Bad input is a usage error, with no traceback; ``--help`` lists each
  choice's values, the command line's.

They run in a venv holding vpype, vpype-gcode and the wheel with its
``vpype`` extra (``bash .ci/vpype-plugin.sh``). Without vpype they are
skipped, unless ``PIXELPIE_EXPECT_VPYPE=1``, where they fail. The CLI is
``$PIXELPIE_BIN``, or ``target/release/pixelpie`` of this checkout.
"""

from __future__ import annotations

import importlib.metadata
import importlib.util
import io
import logging
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

EXPECT = os.environ.get("PIXELPIE_EXPECT_VPYPE") == "1"
if importlib.util.find_spec("vpype") is None or importlib.util.find_spec("vpype_cli") is None:
    if EXPECT:
        raise ImportError(
            "PIXELPIE_EXPECT_VPYPE=1 but vpype is not installed in this Python "
            f"({sys.executable}): bash .ci/vpype-plugin.sh installs it"
        )
    pytest.skip("vpype is not installed (pip install 'pixelpie[vpype]')", allow_module_level=True)

import vpype as vp  # noqa: E402
import vpype_cli  # noqa: E402

import pixelpie  # noqa: E402
from pixelpie import vpype_plugin  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
ASSETS = ROOT / "assets"
CLI = Path(os.environ.get("PIXELPIE_BIN", ROOT / "target" / "release" / "pixelpie"))
PROFILE = Path(vpype_plugin.GCODE_PROFILE)
PX_PER_MM = 96 / 25.4
# In plotting order: the lightest ink first (--layer-order light-first).
CMYK = [("yellow", "#ffff00"), ("cyan", "#00ffff"), ("magenta", "#ff00ff"), ("black", "#000000")]

# The options of the colour drawing, for the plugin and for the CLI (the
# plugin's defaults written out: --paper a4 --pen-mm 0.3).
COLOUR = ["--points", "2000", "--pens", "cmyk", "--seed", "3"]
COLOUR_CLI = COLOUR + ["--paper", "a4", "--pen-mm", "0.3"]


def vpype_exe() -> str:
    """vpype of this Python's venv, else on PATH."""
    exe = Path(sys.executable).with_name("vpype")
    if exe.is_file():
        return str(exe)
    found = shutil.which("vpype")
    assert found, f"no vpype executable next to {sys.executable} or on PATH"
    return found


def run_vpype(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    out = subprocess.run([vpype_exe(), *args], capture_output=True, text=True)
    if check:
        assert out.returncode == 0, f"vpype {' '.join(args)} failed:\n{out.stdout}\n{out.stderr}"
    return out


def cli(*args: str) -> None:
    assert CLI.is_file(), f"the pixelpie binary is missing at {CLI} (cargo build --release)"
    subprocess.run([str(CLI), *args, "--quiet"], capture_output=True, text=True, check=True)


# The cmyk pens' indices (cyan, magenta, yellow, black) in plotting order.
LAYER_PENS = [2, 0, 1, 3]


def in_layers(counts: list) -> list:
    """Dots per pen (in the pens' order) in the layers' plotting order."""
    return [counts[k] for k in LAYER_PENS]


def cli_pen_counts(tmp_path: Path, image: Path, args: list) -> list:
    """Dots per pen that `pixelpie stipple` draws, from its CSV's pen column."""
    out = tmp_path / "cli.csv"
    cli("stipple", str(image), "-o", str(out), *args)
    pens = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)[:, 3].astype(int)
    return np.bincount(pens, minlength=4).tolist()


def plugin(*args: str) -> vp.Document:
    """The document after `vpype pixelpie ARGS` (in this process)."""
    return vpype_cli.execute("pixelpie " + " ".join(f"'{a}'" for a in args))


def paths(layer: vp.LineCollection) -> list:
    return [np.asarray(line) for line in layer]


def same_path(p: np.ndarray, q: np.ndarray) -> bool:
    """The same points, to float rounding (vpype's reader scales mm to px in
    another order of operations: 1e-13 px apart at most)."""
    return p.shape == q.shape and bool(np.allclose(p, q, rtol=0, atol=1e-9))


def same_document(a: vp.Document, b: vp.Document) -> None:
    assert sorted(a.layers) == sorted(b.layers)
    assert a.page_size == b.page_size and a.metadata == b.metadata
    for lid in a.layers:
        assert a.layers[lid].metadata == b.layers[lid].metadata, lid
        pa, pb = paths(a.layers[lid]), paths(b.layers[lid])
        assert len(pa) == len(pb), lid
        assert all(same_path(p, q) for p, q in zip(pa, pb)), lid


@pytest.fixture(scope="module")
def colour(tmp_path_factory):
    """The cmyk drawing of rocket.jpg: the plugin's document, and the CLI's dots per pen."""
    image = ASSETS / "rocket.jpg"
    doc = plugin(str(image), *COLOUR)
    counts = cli_pen_counts(tmp_path_factory.mktemp("cli"), image, COLOUR_CLI)
    return image, doc, counts


# --- the plugin ---------------------------------------------------------------


def test_the_plugin_loads_through_its_entry_point():
    eps = importlib.metadata.entry_points(group="vpype.plugins")
    ours = [ep for ep in eps if ep.name == "pixelpie"]
    assert [ep.value for ep in ours] == ["pixelpie.vpype_plugin:pixelpie"]
    helped = run_vpype("pixelpie", "--help").stdout
    assert "Stipple a photo with PixelPie" in helped
    for option in ["--points", "--pens", "--paper", "--landscape", "--margin", "--pen-mm", "--seed", "--order"]:
        assert option in helped, option
    listed = run_vpype("--help").stdout
    assert re.search(r"^\s+pixelpie\s", listed, re.M), listed


def cli_choices() -> dict:
    """Each option of `pixelpie stipple --help` with "Possible values", and
    its values in order."""
    assert CLI.is_file(), f"the pixelpie binary is missing at {CLI} (cargo build --release)"
    text = subprocess.run([str(CLI), "stipple", "--help"], capture_output=True, text=True, check=True).stdout
    blocks = re.split(r"^\s+(?:-\w, )?(--[\w-]+)\b.*$", text, flags=re.M)
    return {
        name: re.findall(r"^\s+- ([\w-]+):", body, re.M)
        for name, body in zip(blocks[1::2], blocks[2::2])
        if "Possible values:" in body
    }


def test_help_lists_each_choices_values():
    helped = run_vpype("pixelpie", "--help").stdout
    assert "CHOICE" not in helped
    cli_values = cli_choices()
    assert len(vpype_plugin.CHOICES) == 6
    for name, values in vpype_plugin.CHOICES.items():
        option = "--" + name.replace("_", "-")
        # The command line's values, in its order ...
        assert cli_values[option] == values, option
        # ... listed beside the option, as click lists a choice's.
        shown = re.escape(f"{option} [{'|'.join(values)}]")
        assert re.search(rf"^\s+{shown}(\s|$)", helped, re.M), (option, helped)


def luminance(c: vp.Color) -> float:
    return 0.2126 * c.red + 0.7152 * c.green + 0.0722 * c.blue


def test_layers_go_from_the_lightest_ink_unless_layer_order_pens(colour):
    image, doc, _ = colour
    names = [doc.layers[lid].property(vp.METADATA_FIELD_NAME) for lid in (1, 2, 3, 4)]
    assert names == ["yellow", "cyan", "magenta", "black"]
    light = [luminance(doc.layers[lid].property(vp.METADATA_FIELD_COLOR)) for lid in (1, 2, 3, 4)]
    assert light == sorted(light, reverse=True) and light[0] > light[-1]
    # --layer-order pens: cyan, magenta, yellow, black, as --pens cmyk names
    # them, each with the same dots.
    pens = plugin(str(image), *COLOUR, "--layer-order", "pens")
    assert [pens.layers[lid].property(vp.METADATA_FIELD_NAME) for lid in (1, 2, 3, 4)] == [
        "cyan", "magenta", "yellow", "black"]
    for pen in range(4):
        assert len(pens.layers[pen + 1]) == len(doc.layers[LAYER_PENS.index(pen) + 1]), pen


def test_cmyk_gives_one_layer_per_pen_with_its_colour_and_width(colour):
    _, doc, counts = colour
    assert sorted(doc.layers) == [1, 2, 3, 4]
    for lid, (name, rgb) in enumerate(CMYK, start=1):
        layer = doc.layers[lid]
        assert layer.property(vp.METADATA_FIELD_NAME) == name
        assert layer.property(vp.METADATA_FIELD_COLOR) == vp.Color(rgb)
        assert layer.property(vp.METADATA_FIELD_PEN_WIDTH) == pytest.approx(0.3 * PX_PER_MM)
    # The sheet, in vpype's unit (CSS px): A4 portrait.
    assert doc.page_size == pytest.approx((210 * PX_PER_MM, 297 * PX_PER_MM))
    # The source is the photo, not the temporary SVG.
    assert doc.property(vp.METADATA_FIELD_SOURCE) == (ASSETS / "rocket.jpg").absolute()


def test_each_layer_has_the_clis_dots_for_its_pen(colour):
    _, doc, counts = colour
    got = [len(doc.layers[lid]) for lid in (1, 2, 3, 4)]
    assert got == in_layers(counts)
    assert sum(got) > 1800 and min(got) > 0, got


def test_the_python_package_draws_the_same_dots(colour):
    image, doc, counts = colour
    dots = pixelpie.stipple(image, points=2000, pens="cmyk", seed=3, paper="a4", pen_mm=0.3)
    assert np.bincount(dots[:, 3].astype(int), minlength=4).tolist() == counts


def test_grey_paths_are_the_clis_svg_read_by_vpype(tmp_path):
    image = ASSETS / "default.png"
    opts = ["--points", "2000", "--seed", "5", "--order", "tsp", "--dot-path", "touch"]
    svg = tmp_path / "cli.svg"
    cli("stipple", str(image), "-o", str(svg), *opts, "--paper", "a4", "--pen-mm", "0.3")
    want = vpype_cli.execute(f"read --no-crop '{svg}'")
    got = plugin(str(image), *opts)
    assert sorted(got.layers) == sorted(want.layers) == [1]
    # The page is A4 in vpype's own mm, as its paper sizes are; vpype's
    # reader takes an inch as 25.39999 mm.
    assert got.page_size == (210 * PX_PER_MM, 297 * PX_PER_MM) == vp.convert_page_size("a4")
    assert got.page_size == pytest.approx(want.page_size, rel=1e-6)
    a, b = paths(got.layers[1]), paths(want.layers[1])
    assert len(a) == len(b) == svg.read_text().count("<path")
    assert all(same_path(p, q) for p, q in zip(a, b))
    assert got.layers[1].property(vp.METADATA_FIELD_COLOR) == vp.Color("black")
    # One-touch dots: two points 0.01 mm apart (vpype drops zero-length paths).
    lengths = [abs(p[-1] - p[0]) / PX_PER_MM for p in a if len(p) == 2]
    assert lengths and max(lengths) == pytest.approx(0.01, abs=2e-3)


def test_spiral_dots_keep_their_paths(tmp_path):
    # Sized spirals (the default dot path) read back path for path.
    image = ASSETS / "default.png"
    opts = ["--points", "800", "--width-mm", "120", "--pen-mm", "0.2", "--dot", "sized"]
    svg = tmp_path / "cli.svg"
    cli("stipple", str(image), "-o", str(svg), *opts)
    got = plugin(str(image), *opts)
    assert len(got.layers[1]) == svg.read_text().count("<path")
    assert max(len(p) for p in got.layers[1]) > 10  # spirals, not only touches
    assert got.page_size[0] == pytest.approx(120 * PX_PER_MM)


def test_defaults_are_a4_a_03_mm_pen_and_10000_dots(tmp_path):
    image = ASSETS / "default.png"
    svg = tmp_path / "cli.svg"
    cli("stipple", str(image), "-o", str(svg), "--paper", "a4", "--pen-mm", "0.3", "--points", "10000")
    doc = plugin(str(image))
    assert len(doc.layers[1]) == svg.read_text().count("<path")
    assert doc.page_size == pytest.approx((210 * PX_PER_MM, 297 * PX_PER_MM), rel=1e-6)
    assert vpype_plugin.job_options() == {"paper": "a4", "pen_mm": 0.3, "points": 10000}
    assert vpype_plugin.job_options(width_mm=150, extra={"dot_radius": 2}) == {
        "width_mm": 150, "pen_mm": 0.3, "dot_radius": 2}


def test_options_go_before_or_after_the_image():
    takes = {"--points": True, "-n": True, "--landscape": False}
    move = vpype_plugin._options_first
    assert move(["a.jpg", "-n", "5", "--landscape", "write", "o.svg"], takes) == [
        "-n", "5", "--landscape", "a.jpg", "write", "o.svg"]
    assert move(["a.jpg", "--points=5", "stat"], takes) == ["--points=5", "a.jpg", "stat"]
    assert move(["--points", "5", "a.jpg", "stat"], takes) == ["--points", "5", "a.jpg", "stat"]
    assert move(["a.jpg"], takes) == ["a.jpg"]
    # The next command's options are left to it.
    assert move(["a.jpg", "write", "--landscape", "o.svg"], takes) == ["a.jpg", "write", "--landscape", "o.svg"]
    image = str(ASSETS / "default.png")
    before = run_vpype("pixelpie", "--points", "300", image, "stat").stdout
    after = run_vpype("pixelpie", image, "--points", "300", "stat").stdout
    count = re.findall(r"Path count: (\d+)", before)
    assert count and count == re.findall(r"Path count: (\d+)", after)


@pytest.mark.parametrize("dot_path", ["spiral", "circle", "touch"])
def test_the_fast_reader_is_vpypes_read(tmp_path, dot_path):
    # The plugin reads pixelpie's own paths itself (vpype's reader takes
    # ~4 ms a dot): the document must be the one vpype's reader makes.
    svg = tmp_path / "cli.svg"
    cli("stipple", str(ASSETS / "rocket.jpg"), "-o", str(svg), "--points", "400", "--pens", "cmyk",
        "--paper", "a4", "--pen-mm", "0.3", "--dot", "sized", "--dot-path", dot_path)
    text = svg.read_text()
    fast = vpype_plugin.read_drawing(text)
    whole = vpype_plugin._read_svg(text, 0.1 * PX_PER_MM)
    # The page is the sheet in vpype's mm (vpype's reader: 5e-7 larger).
    assert fast.page_size == vp.convert_page_size("a4")
    assert whole.page_size == pytest.approx(fast.page_size, rel=1e-6)
    whole.page_size = fast.page_size
    same_document(fast, whole)
    assert sorted(fast.layers) == [1, 2, 3, 4]


def test_other_svgs_are_read_by_vpype_whole():
    svg = (
        '<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" '
        'width="100mm" height="50mm" viewBox="0 0 100 50">'
        '<g inkscape:label="2 red" stroke="#ff0000" transform="translate(10 0)"><path d="M 0 0 L 10 10"/></g>'
        '<g inkscape:label="blue" stroke="#0000ff"><circle cx="20" cy="20" r="5"/></g></svg>'
    )
    assert vpype_plugin._pen_paths(svg) is None
    doc = vpype_plugin.read_drawing(svg)
    assert sorted(doc.layers) == [1, 2]
    assert doc.layers[1].property(vp.METADATA_FIELD_NAME) == "2 red"
    assert np.asarray(doc.layers[1][0])[0] == pytest.approx(10 * 96 / 25.4, rel=1e-5)
    assert len(doc.layers[2][0]) > 10  # the circle, in segments


def test_paper_landscape_and_margin(tmp_path):
    image = ASSETS / "default.png"
    doc = plugin(str(image), "--points", "500", "--paper", "a5", "--landscape", "--margin", "20")
    assert doc.page_size == pytest.approx((210 * PX_PER_MM, 148 * PX_PER_MM))
    x0, y0, x1, y1 = (v / PX_PER_MM for v in doc.bounds())
    # The square photo fills the 108 mm between the margins, centred; the
    # dots at its edges reach past by up to their radius (500 dots: 2.5 mm).
    assert 20 - 2.5 <= y0 < 20 + 2.5 and 128 - 2.5 < y1 <= 128 + 2.5, (y0, y1)
    assert (x0 + x1) / 2 == pytest.approx(105, abs=1.5)
    assert (y0 + y1) / 2 == pytest.approx(74, abs=1.5)


def test_layer_option_moves_the_pens():
    image = str(ASSETS / "rocket.jpg")
    doc = vpype_cli.execute(f"rect 0 0 10 10 pixelpie '{image}' --points 400 --pens cmyk -l new")
    assert sorted(doc.layers) == [1, 2, 3, 4, 5]
    assert doc.layers[2].property(vp.METADATA_FIELD_NAME) == "yellow"
    doc = plugin(image, "--points", "400", "--pens", "#000000,#d62728", "-l", "3")
    assert sorted(doc.layers) == [3, 4]
    # The lighter ink first.
    assert doc.layers[3].property(vp.METADATA_FIELD_COLOR) == vp.Color("#d62728")


def test_pen_file_names_with_digits_keep_their_layers(tmp_path):
    # vpype takes the digits of a layer's name as its number; our layers
    # keep the plotting order (the lighter ink first) whatever their names.
    pens = tmp_path / "pens.toml"
    pens.write_text(
        '[[pen]]\nname = "Pilot 05 black"\ncolour = "#000000"\nwidth_mm = 0.5\n'
        '[[pen]]\nname = "Stabilo 88 red"\ncolour = "#d62728"\nwidth_mm = 0.4\n'
    )
    doc = plugin(str(ASSETS / "rocket.jpg"), "--points", "600", "--pens", str(pens))
    assert sorted(doc.layers) == [1, 2]
    assert [doc.layers[i].property(vp.METADATA_FIELD_NAME) for i in (1, 2)] == ["Stabilo 88 red", "Pilot 05 black"]
    widths = [doc.layers[i].property(vp.METADATA_FIELD_PEN_WIDTH) / PX_PER_MM for i in (1, 2)]
    assert widths == pytest.approx([0.4, 0.5])


def test_extra_options_reach_the_job(tmp_path):
    image = ASSETS / "default.png"
    svg = tmp_path / "cli.svg"
    cli("stipple", str(image), "-o", str(svg), "--points", "500", "--invert", "--gamma", "1.5",
        "--paper", "a4", "--pen-mm", "0.3")
    doc = plugin(str(image), "--points", "500", "-o", "invert=true", "--option", "gamma=1.5")
    assert len(doc.layers[1]) == svg.read_text().count("<path")


@pytest.mark.parametrize(
    "args,message",
    [
        (["missing.jpg"], "does not exist"),
        (["{image}", "--paper", "a9"], "a9"),
        (["{image}", "--pen-mm", "-1"], "pen-mm"),
        (["{image}", "--paper", "a4", "--width-mm", "100"], "exclude"),
        (["{image}", "--option", "nonsense"], "NAME=VALUE"),
        (["{image}", "--option", "bogus=1"], "bogus"),
        (["{image}", "--order", "fast"], "fast"),
        (["{image}", "--points", "many"], "many"),
        (["{image}", "--layer-order", "dark-first"], "dark-first"),
        (["{image}", "--device", "hp9999"], "vpype knows no plotter of that name"),
        (["{image}", "--paper", "a5", "--device", "hp7475a"], "has no paper of this 148 x 210 mm sheet"),
        (["{image}", "--width-mm", "150", "--device", "hp7475a"], "give --paper"),
        (["{image}", "--style", "lines"], "lines"),
        (["{image}", "--line-smooth"], "--line-smooth needs --style line"),
    ],
)
def test_bad_input_is_a_usage_error_without_traceback(tmp_path, args, message):
    image = str(ASSETS / "default.png")
    out = run_vpype("pixelpie", *[a.format(image=image) for a in args], check=False)
    assert out.returncode != 0
    assert "Traceback" not in out.stderr, out.stderr
    assert "Error" in out.stderr and message in out.stderr, out.stderr


def test_the_module_imports_without_vpype():
    # The plain package has no vpype: the module still imports, and its
    # command is a stand-in that says how to install the extra.
    code = (
        "import sys; sys.modules['vpype'] = None; sys.modules['vpype_cli'] = None\n"
        "import pixelpie.vpype_plugin as m\n"
        "try:\n    m.pixelpie()\nexcept ImportError as e:\n    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "pixelpie[vpype]" in out.stdout


# --- line drawings (--style line) -----------------------------------------------

#: A small line drawing: about 3000 points.
LINE = ["--style", "line", "--width-mm", "60", "--pen-mm", "0.8", "--seed", "2"]


def test_a_line_is_the_clis_svg_read_by_vpype_one_path(tmp_path):
    image = ASSETS / "rocket.jpg"
    svg = tmp_path / "cli.svg"
    cli("stipple", str(image), "-o", str(svg), *LINE)
    # vpype reads our line SVG as one path ...
    want = vpype_cli.execute(f"read --no-crop '{svg}'")
    assert sorted(want.layers) == [1] and len(want.layers[1]) == 1
    # ... and the plugin gives it the same, read fast.
    got = plugin(str(image), *LINE)
    assert vpype_plugin._pen_paths(svg.read_text()) is not None
    assert sorted(got.layers) == [1] and len(got.layers[1]) == 1
    assert got.page_size == pytest.approx(want.page_size, rel=1e-6)
    (a,), (b,) = paths(got.layers[1]), paths(want.layers[1])
    assert same_path(a, b)
    assert got.layers[1].metadata == want.layers[1].metadata
    assert got.layers[1].property(vp.METADATA_FIELD_PEN_WIDTH) == pytest.approx(0.8 * PX_PER_MM)
    # The Python drawing's line, in order, to the file's 0.01 mm.
    d = pixelpie.stipple(image, style="line", width_mm=60, pen_mm=0.8, seed=2)
    line = d.paths()[0].paths[0] * PX_PER_MM
    assert a.shape == (len(d.line),)
    assert np.abs(a.real - line[:, 0]).max() < 0.0051 * PX_PER_MM
    assert np.abs(a.imag - line[:, 1]).max() < 0.0051 * PX_PER_MM


def test_line_defaults_take_the_count_the_pen_needs():
    opts = vpype_plugin.job_options(style="line")
    assert opts == {"style": "line", "paper": "a4", "pen_mm": 0.3}
    assert vpype_plugin.job_options(style="line", points=5000, line_smooth=True) == {
        "style": "line", "points": 5000, "line_smooth": True, "paper": "a4", "pen_mm": 0.3}
    assert vpype_plugin.job_options(style="dots")["points"] == vpype_plugin.DEFAULT_POINTS


def test_a_refilled_line_is_one_path_per_layer_each_from_the_last_ones_end():
    doc = plugin(str(ASSETS / "rocket.jpg"), *LINE, "-o", "refill_mm=400")
    n = len(doc.layers)
    assert n > 2 and sorted(doc.layers) == list(range(1, n + 1))
    parts = []
    for lid in range(1, n + 1):
        assert doc.layers[lid].property(vp.METADATA_FIELD_NAME) == f"{lid} black {lid}/{n}"
        (part,) = paths(doc.layers[lid])
        parts.append(part)
    for before, after in zip(parts, parts[1:]):
        assert abs(after[0] - before[-1]) < 1e-9


def test_a_smooth_line_is_one_path_as_vpype_reads_it(tmp_path):
    image = ASSETS / "rocket.jpg"
    svg = tmp_path / "cli.svg"
    cli("stipple", str(image), "-o", str(svg), *LINE, "--line-smooth")
    want = vpype_cli.execute(f"read --no-crop '{svg}'")
    got = plugin(str(image), *LINE, "--line-smooth")
    assert len(got.layers) == len(want.layers) == 1
    (a,), (b,) = paths(got.layers[1]), paths(want.layers[1])
    assert same_path(a, b)
    # Curves, in more segments than the line has points.
    straight = plugin(str(image), *LINE)
    assert len(a) > len(paths(straight.layers[1])[0])


def test_colour_lines_are_one_path_per_pen():
    doc = plugin(str(ASSETS / "rocket.jpg"), *LINE, "--pens", "cmyk")
    assert sorted(doc.layers) == [1, 2, 3, 4]
    names = [doc.layers[lid].property(vp.METADATA_FIELD_NAME) for lid in (1, 2, 3, 4)]
    assert names == [name for name, _ in CMYK]
    assert [len(doc.layers[lid]) for lid in (1, 2, 3, 4)] == [1, 1, 1, 1]


def test_a_line_drawing_becomes_a_vpype_document_of_one_path_per_layer():
    d = pixelpie.stipple(ASSETS / "rocket.jpg", style="line", width_mm=60, pen_mm=0.8,
                         refill_mm=400.0)
    doc = d.to_vpype()
    layers = d.paths()
    assert len(layers) > 2 and sorted(doc.layers) == list(range(1, len(layers) + 1))
    for k, layer in enumerate(layers, start=1):
        (line,) = doc.layers[k]
        (path,) = layer.paths
        assert np.allclose(np.asarray(line), (path[:, 0] + 1j * path[:, 1]) * PX_PER_MM)


# --- through vpype: SVG, HPGL and G-code ---------------------------------------


def test_pipeline_to_svg(tmp_path, colour):
    image, _, counts = colour
    out = tmp_path / "out.svg"
    run_vpype("pixelpie", str(image), *COLOUR, "linesort", "write", str(out))
    # vpype writes a layer per pen, in its colour, a <polyline> per path.
    text = out.read_text()
    layers = re.findall(r'<g [^>]*inkscape:label="(\w+)"[^>]*>(.*?)</g>', text, re.S)
    assert [name for name, _ in layers] == [name for name, _ in CMYK]
    assert [body.count("<polyline") for _, body in layers] == in_layers(counts)
    for (name, rgb), (_, body) in zip(CMYK, layers):
        assert re.search(rf'<g [^>]*stroke="{rgb}"[^>]*inkscape:label="{name}"', text) or re.search(
            rf'<g [^>]*inkscape:label="{name}"[^>]*stroke="{rgb}"', text
        ), name
    assert 'width="21.0' in text and 'height="29.7' in text


def test_hpgl_through_vpype(tmp_path, colour):
    image, _, counts = colour
    out = tmp_path / "out.hpgl"
    # The HP 7475A takes A4 sideways and reaches 274 x 192 mm of it: the
    # landscape photo on a landscape sheet with 20 mm margins keeps every dot
    # inside (none is cropped into pieces).
    margins = ["--landscape", "--margin", "20"]
    run_vpype(
        "pixelpie", str(image), *COLOUR, *margins,
        "write", "--device", "hp7475a", "--page-size", "a4", "--landscape", str(out),
    )
    hpgl = out.read_text()
    assert hpgl.startswith("IN;DF;") and hpgl.rstrip().endswith("SP0;IN;")
    pens = re.findall(r"SP(\d+);", hpgl)
    assert pens == ["1", "2", "3", "4", "0"]
    # One pen-down per path, pen by pen.
    blocks = re.split(r"SP[1-4];", hpgl)[1:]
    assert [b.count("PD") for b in blocks] == in_layers(counts)
    # The same dots on a landscape sheet with 20 mm margins.
    assert counts == cli_pen_counts(tmp_path, image, COLOUR_CLI + margins)


def hpgl_strokes(hpgl: str) -> list:
    """The number of points of each pen-down stroke of vpype's HPGL (``PD``
    and the relative moves from the stroke's first point), in order."""
    return [len(moves.split(",")) // 2 + 1 for moves in re.findall(r"PD([-\d,]+);", hpgl)]


def path_points(doc: vp.Document) -> list:
    """The number of points of each path, layer by layer."""
    return [len(line) for lid in sorted(doc.layers) for line in doc.layers[lid]]


def hpgl_of(lines: list, page_size, device: str = "hp7475a") -> list:
    """hpgl_strokes of ``lines`` written alone by vpype's HPGL writer, as
    `write --device DEVICE` writes a page of ``page_size``."""
    doc = vp.Document(page_size=page_size)
    doc.add(vp.LineCollection(lines), 1)
    paper = vp.config_manager.get_plotter_config(device).paper_config_from_size(page_size)
    out = io.StringIO()
    vp.write_hpgl(out, doc, page_size=paper.name, landscape=page_size[0] > page_size[1], center=False,
                  device=device, velocity=None, quiet=True)
    return hpgl_strokes(out.getvalue())


def test_plotter_reach_is_what_vpypes_hpgl_writer_keeps():
    # Every plotter and paper of vpype's configuration, both ways round: a
    # short path 0.3 mm inside each edge of the reach comes out whole, one
    # 0.3 mm outside is cropped away.
    checked = set()
    for device in vp.config_manager.get_plotter_list():
        try:
            plotter = vp.config_manager.get_plotter_config(device)
        except ValueError:
            continue  # vpype 1.15's designmate ("285mmmm")
        for paper in plotter.paper_configs:
            if paper.paper_size is None or paper.x_range is None:
                continue
            w, h = sorted(paper.paper_size)
            for page in ((w, h), (h, w)):
                reach = vpype_plugin.plotter_reach(device, page)
                if reach.paper != paper.name:
                    continue  # another paper of this size comes first, as in vpype
                x0, y0, x1, y1 = reach.box
                d, cx, cy = 0.3 * PX_PER_MM, (x0 + x1) / 2, (y0 + y1) / 2
                for x, y, inside in [(x0 + d, cy, True), (x1 - d, cy, True), (cx, y0 + d, True),
                                     (cx, y1 - d, True), (x0 - d, cy, False), (x1 + d, cy, False),
                                     (cx, y0 - d, False), (cx, y1 + d, False)]:
                    line = np.array([x + 1j * y, x + 0.1 + 1j * y])
                    assert hpgl_of([line], page, device) == ([2] if inside else []), (device, paper.name, page)
                checked.add((device, paper.name, page))
    assert len(checked) >= 30 and {d for d, _, _ in checked} >= {"hp7475a", "hp7550", "artisan", "dxy"}
    assert vpype_plugin.plotter_reach("hp7475a", vp.convert_page_size("a5")) is None


def test_device_keeps_every_dot_within_the_plotters_reach(tmp_path, caplog):
    # The pipeline, with pixelpie told the plotter: 8000 dots on A4,
    # written by vpype for the HP 7475A (the paper found from the page).
    image = ASSETS / "astronaut.jpg"
    out = tmp_path / "out.hpgl"
    with caplog.at_level(logging.INFO):
        doc = vpype_cli.execute(
            f"pixelpie '{image}' --points 8000 --device hp7475a write --device hp7475a '{out}'", global_opt="-v")
    # One pen-down per dot, each with all its points: no dot is cut.
    strokes = hpgl_strokes(out.read_text())
    assert len(strokes) == len(doc.layers[1]) > 7900
    assert strokes == path_points(doc)
    # The margin pixelpie chose, wider than the default 10 mm, is the
    # command line's for the same dots.
    found = re.search(r"--margin ([\d.]+) keeps every dot within hp7475a's reach", caplog.text)
    assert found, caplog.text
    assert 10 < float(found.group(1)) < 20
    svg = tmp_path / "cli.svg"
    cli("stipple", str(image), "-o", str(svg), "--points", "8000", "--paper", "a4", "--pen-mm", "0.3",
        "--margin", found.group(1))
    want = vpype_plugin.read_drawing(svg.read_text())
    assert all(same_path(p, q) for p, q in zip(paths(doc.layers[1]), paths(want.layers[1])))
    assert len(want.layers[1]) == len(doc.layers[1])


def test_without_a_device_a_warning_names_the_dots_each_plotter_would_cut(tmp_path, caplog):
    # The pipeline as it was written: pixelpie is not told the
    # plotter, and keeps its 10 mm margin.
    image = ASSETS / "astronaut.jpg"
    out = tmp_path / "out.hpgl"
    with caplog.at_level(logging.WARNING):
        doc = vpype_cli.execute(f"pixelpie '{image}' --points 8000 write --device hp7475a '{out}'")
    found = re.search(r"hp7475a cuts (\d+) \(--margin ([\d.]+) keeps them whole\)", caplog.text)
    assert found, caplog.text
    cut, margin = int(found.group(1)), found.group(2)
    assert "--device NAME" in caplog.text
    # vpype's writer cuts the dots written: not one stroke per dot of its points.
    lines = [line for lid in sorted(doc.layers) for line in doc.layers[lid]]
    assert hpgl_strokes(out.read_text()) != [len(line) for line in lines]
    # Exactly the dots the warning counts: the others come out whole, each
    # of those is cut or cropped away.
    x0, y0, x1, y1 = vpype_plugin.plotter_reach("hp7475a", doc.page_size).box
    b = vpype_plugin._dot_bounds(doc)
    past = (b[:, 0] < x0) | (b[:, 1] < y0) | (b[:, 2] > x1) | (b[:, 3] > y1)
    assert past.sum() == cut > 50
    inside = [line for line, p in zip(lines, past) if not p]
    assert hpgl_of(inside, doc.page_size) == [len(line) for line in inside]
    for line in (line for line, p in zip(lines, past) if p):
        assert hpgl_of([line], doc.page_size) != [len(line)]
    # The margin the warning gives keeps every dot whole.
    caplog.clear()
    out = tmp_path / "margin.hpgl"
    with caplog.at_level(logging.WARNING):
        doc = vpype_cli.execute(f"pixelpie '{image}' --points 8000 --margin {margin} write --device hp7475a '{out}'")
    assert "hp7475a" not in caplog.text
    assert hpgl_strokes(out.read_text()) == path_points(doc)


def test_a_margin_too_narrow_for_the_device_is_refused(tmp_path, caplog):
    image = str(ASSETS / "rocket.jpg")
    refused = run_vpype("pixelpie", image, "--points", "3000", "--margin", "12", "--device", "hp7475a", check=False)
    assert refused.returncode == 2 and "Traceback" not in refused.stderr
    found = re.search(r"(\d+) of (\d+) dots lie past what hp7475a reaches .* give --margin ([\d.]+) or more",
                      refused.stderr)
    assert found, refused.stderr
    assert 0 < int(found.group(1)) < int(found.group(2))
    # The margin it names is enough.
    out = tmp_path / "out.hpgl"
    doc = vpype_cli.execute(
        f"pixelpie '{image}' --points 3000 --margin {found.group(3)} --device hp7475a write --device hp7475a '{out}'")
    assert hpgl_strokes(out.read_text()) == path_points(doc)
    # --device none: no HPGL plotter, no check and no warning.
    with caplog.at_level(logging.WARNING):
        vpype_cli.execute(f"pixelpie '{image}' --points 3000 --device none")
    assert "would cut" not in caplog.text


def test_vpypes_default_hpgl_device_is_the_plugins(tmp_path):
    # With vpype's default_hpgl_device, `write out.hpgl` plots on it, and
    # pixelpie fits the drawing to it unasked.
    config = tmp_path / "vpype.toml"
    config.write_text('[command.write]\ndefault_hpgl_device = "hp7475a"\n')
    out = tmp_path / "out.hpgl"
    done = run_vpype("-c", str(config), "-v", "pixelpie", str(ASSETS / "rocket.jpg"), "--points", "3000",
                     "--landscape", "stat", "write", str(out))
    assert "would cut" not in done.stderr
    assert re.search(r"--margin [\d.]+ keeps every dot within hp7475a's reach", done.stderr), done.stderr
    count = int(re.findall(r"Path count: (\d+)", done.stdout)[-1])
    strokes = hpgl_strokes(out.read_text())
    assert len(strokes) == count > 2900


def test_gcode_through_vpype_gcode(tmp_path, colour):
    if importlib.util.find_spec("vpype_gcode") is None:
        if EXPECT:
            pytest.fail("PIXELPIE_EXPECT_VPYPE=1 but vpype-gcode is not installed")
        pytest.skip("vpype-gcode is not installed")
    image, _, counts = colour
    out = tmp_path / "out.gcode"
    assert PROFILE.is_file(), PROFILE
    run_vpype("-c", str(PROFILE), "pixelpie", str(image), *COLOUR, "linesort",
              "gwrite", "--profile", "pixelpie", str(out))
    gcode = out.read_text()
    changes = re.findall(r"^M0 \(pen change: pen (\d), (\w+) (#[0-9a-f]{6})\)$", gcode, re.M)
    assert changes == [(str(i), n, c) for i, (n, c) in enumerate(CMYK, start=1)]
    blocks = re.split(r"^M0 .*$", gcode, flags=re.M)[1:]
    downs = [len(re.findall(r"^G1 Z0 F1000$", b, re.M)) for b in blocks]
    ups = [len(re.findall(r"^G0 Z3$", b, re.M)) for b in blocks]
    assert downs == in_layers(counts)
    assert ups[:3] == [c + 1 for c in in_layers(counts)[:3]]  # each path, then the next pen change
    assert gcode.startswith("; ") and "G21" in gcode and gcode.rstrip().endswith("M2")
    # Bottom-left origin: every move lies on the A4 sheet.
    xy = np.array(re.findall(r"^G[01] X(-?[\d.]+) Y(-?[\d.]+)", gcode, re.M), dtype=float)
    assert xy[:, 0].min() >= 0 and xy[:, 0].max() <= 210
    assert xy[:, 1].min() >= 0 and xy[:, 1].max() <= 297
    # The defaults give way to gwrite -d.
    out2 = tmp_path / "out2.gcode"
    run_vpype("-c", str(PROFILE), "pixelpie", str(image), "--points", "300",
              "gwrite", "--profile", "pixelpie", "-d", "z_down", "-0.5", "-d", "feed", "4000", str(out2))
    text = out2.read_text()
    assert "G1 Z-0.5 F1000" in text and "F4000" in text and "G1 Z0 F" not in text


def test_gcode_for_a_servo_pen_through_vpype_gcode(tmp_path, colour):
    """`pixelpie_servo`: M3 S lowers the pen and M5 lifts it, each followed by
    a G4 dwell; no Z move; one pen change per layer, one pen-down per dot."""
    if importlib.util.find_spec("vpype_gcode") is None:
        if EXPECT:
            pytest.fail("PIXELPIE_EXPECT_VPYPE=1 but vpype-gcode is not installed")
        pytest.skip("vpype-gcode is not installed")
    image, _, counts = colour
    out = tmp_path / "servo.gcode"
    run_vpype("-c", str(PROFILE), "pixelpie", str(image), *COLOUR, "linesort",
              "gwrite", "--profile", "pixelpie_servo", str(out))
    gcode = out.read_text()
    changes = re.findall(r"^M0 \(pen change: pen (\d), (\w+) (#[0-9a-f]{6})\)$", gcode, re.M)
    assert changes == [(str(i), n, c) for i, (n, c) in enumerate(CMYK, start=1)]
    blocks = re.split(r"^M0 .*$", gcode, flags=re.M)[1:]
    assert [len(re.findall(r"^M3 S1000\nG4 P0.15$", b, re.M)) for b in blocks] == in_layers(counts)
    assert [len(re.findall(r"^M5\nG4 P0.15$", b, re.M)) for b in blocks] == in_layers(counts)
    assert not re.search(r"^G[01].*Z", gcode, re.M)
    assert gcode.rstrip().endswith("M2")
    xy = np.array(re.findall(r"^G[01] X(-?[\d.]+) Y(-?[\d.]+)", gcode, re.M), dtype=float)
    assert xy[:, 0].min() >= 0 and xy[:, 0].max() <= 210
    assert xy[:, 1].min() >= 0 and xy[:, 1].max() <= 297
    # The servo's value and dwell give way to gwrite -d.
    out2 = tmp_path / "servo2.gcode"
    run_vpype("-c", str(PROFILE), "pixelpie", str(image), "--points", "300", "gwrite", "--profile",
              "pixelpie_servo", "-d", "s_down", "30", "-d", "dwell", "0.25", str(out2))
    text = out2.read_text()
    assert "M3 S30\nG4 P0.25\n" in text and "S1000" not in text and "P0.15" not in text


# --- the docs' examples -------------------------------------------------------


def shell_lines(page: Path) -> list:
    """The `pixelpie` and `vpype` commands of a page's ```sh blocks, in
    order, continuation lines joined."""
    lines, block = [], re.findall(r"^```sh\n(.*?)^```", page.read_text(), re.M | re.S)
    for text in block:
        for line in text.replace("\\\n", " ").splitlines():
            if line.startswith(("pixelpie ", "vpype ")):
                lines.append(line)
    return lines


@pytest.mark.parametrize("page", ["README.md", "docs/plotter.md"])
def test_the_docs_vpype_examples_run_as_written(tmp_path, page):
    lines = shell_lines(ROOT / page)
    assert any(line.startswith("vpype ") for line in lines), page
    for name in ("assets", "python"):
        (tmp_path / name).symlink_to(ROOT / name)
    shutil.copy(ASSETS / "rocket.jpg", tmp_path / "photo.jpg")
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join([str(CLI.parent), str(Path(vpype_exe()).parent), env.get("PATH", "")])
    for line in lines:
        out = subprocess.run(["sh", "-c", line], cwd=tmp_path, env=env, capture_output=True, text=True)
        assert out.returncode == 0, f"{page}: `{line}` failed:\n{out.stderr}"
    # What they write is there.
    written = (r"(?:\bwrite|\bgwrite --profile \S+(?: -d \S+ \S+)*)"
               r"(?: --device \S+)?(?: --page-size \S+)?(?: --landscape)? (\S+)")
    for name in re.findall(written, " ".join(lines)):
        assert not name.startswith("-"), name
        assert (tmp_path / name).stat().st_size > 0, name


def test_a_drawing_becomes_a_vpype_document_of_its_pen_paths():
    d = pixelpie.stipple(ASSETS / "rocket.jpg", points=1500, pens="cmyk", paper="a5",
                         pen_mm=0.3, seed=2)
    doc = d.to_vpype()
    layers = d.paths()
    assert doc.page_size == pytest.approx((148 * 96 / 25.4, 210 * 96 / 25.4))
    assert sorted(doc.layers) == list(range(1, len(layers) + 1))
    for k, layer in enumerate(layers, start=1):
        lc = doc.layers[k]
        assert lc.property("vp_name") == layer.name
        assert lc.property("vp_pen_width") == pytest.approx(layer.pen_mm * 96 / 25.4)
        assert len(lc) == len(layer.paths)
        # Each line is its dot's path, in vpype's px.
        first = np.asarray(lc[0])
        assert np.allclose(first.real, layer.paths[0][:, 0] * 96 / 25.4)
        assert np.allclose(first.imag, layer.paths[0][:, 1] * 96 / 25.4)
    assert sum(len(doc.layers[k]) for k in doc.layers) == d.reached
