"""Tests of the Inkscape effect PixelPie ▸ Stipple (python/inkscape/pixelpie_stipple.py).

Each test runs the effect as Inkscape does (``python pixelpie_stipple.py
--id=PHOTO … in.svg > out.svg``, in a subprocess, or in-process through
``inkex.tester``) on a document made here from the project's pictures, and
checks the result against the ``pixelpie stipple`` command line run on its own:
the dots, moved into the image's box (worked out here, not by the effect), lie
within 0.01 mm of the CLI's. They need inkex (PyPI ``inkex``, in the venv
.ci/inkscape.sh makes) and the pixelpie binary (``PIXELPIE_BIN``, default
``target/release/pixelpie``): without it they fail. The Python-package tests
need the pixelpie wheel unpacked in ``PIXELPIE_INKEX_PACKAGE``; they fail
without it when ``PIXELPIE_EXPECT_PACKAGE=1`` (CI), else they skip.
"""

import base64
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import inkex
from inkex import Transform
from inkex.tester import TestCase

HERE = os.path.dirname(os.path.abspath(__file__))
EXT_DIR = os.path.dirname(HERE)
ROOT = os.path.dirname(os.path.dirname(EXT_DIR))
SCRIPT = os.path.join(EXT_DIR, "pixelpie_stipple.py")
INX = os.path.join(EXT_DIR, "pixelpie_stipple.inx")
ROCKET = os.path.join(ROOT, "assets", "rocket.jpg")  # 480 × 320
DEFAULT = os.path.join(ROOT, "assets", "default.png")  # 512 × 512
MM = 96 / 25.4  # user units (px) in a mm, in a document without a viewBox

sys.path.insert(0, EXT_DIR)
import pixelpie_stipple  # noqa: E402  pylint: disable=wrong-import-position


def pixelpie_binary():
    """The pixelpie binary the tests compare with: required."""
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    path = os.environ.get("PIXELPIE_BIN") or os.path.join(target, "release", "pixelpie")
    if not (os.path.isfile(path) and os.access(path, os.X_OK)):
        raise AssertionError(f"no pixelpie binary at {path}: cargo build --release, or set PIXELPIE_BIN")
    return os.path.abspath(path)


def svg_document(body, width="210mm", height="297mm", viewbox="0 0 210 297"):
    """An A4 document (mm user units by default) around ``body``."""
    box = f' viewBox="{viewbox}"' if viewbox else ""
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"
  xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
  xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd"
  width="{width}" height="{height}"{box}>
<sodipodi:namedview id="namedview1" inkscape:document-units="mm"/>
{body}
</svg>
"""


def data_uri(path):
    """A picture as an embedded image's href."""
    media = "image/png" if path.endswith(".png") else "image/jpeg"
    with open(path, "rb") as stream:
        return f"data:{media};base64," + base64.b64encode(stream.read()).decode("ascii")


def to_root(elem):
    """Every transform from ``elem`` up to (not including) the root ``<svg>``."""
    total = Transform()
    while elem is not None and elem.getparent() is not None:
        total = Transform(elem.get("transform")) @ total
        elem = elem.getparent()
    return total


def dot_centres(root):
    """Every dot's centre (its ``data-dot`` x and y) in the document's user units, in order."""
    out = []
    for path in root.xpath("//*[@data-dot]"):
        x, y, _ = (float(v) for v in path.get("data-dot").split())
        point = to_root(path).apply_to_point((x, y))
        out.append((point.x, point.y))
    return out


def layers(root):
    """The top-level layers, as (label, element)."""
    return [(g.get("inkscape:label"), g) for g in root if isinstance(g, inkex.Layer)]


class Run:
    """One run of the effect: its exit status, output document (or None) and stderr."""

    def __init__(self, proc):
        self.returncode = proc.returncode
        self.stdout = proc.stdout
        self.stderr = proc.stderr.decode("utf-8", "replace")
        self.root = inkex.load_svg(proc.stdout).getroot() if proc.returncode == 0 and proc.stdout else None


class StippleTestBase(TestCase):
    """Runs the effect as Inkscape does, and pixelpie stipple for reference."""

    effect_class = pixelpie_stipple.PixelpieStipple

    def setUp(self):
        super().setUp()
        self.binary = pixelpie_binary()
        self.dir = tempfile.mkdtemp(prefix="pixelpie-inkscape-test-")
        # PATH with pixelpie on it, and one without.
        self.bin_dir = os.path.join(self.dir, "bin")
        os.mkdir(self.bin_dir)
        os.symlink(self.binary, os.path.join(self.bin_dir, "pixelpie"))
        self.bare_path = os.pathsep.join(
            p for p in os.environ.get("PATH", "").split(os.pathsep) if p and not os.path.exists(os.path.join(p, "pixelpie"))
        )

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)
        super().tearDown()

    def write(self, name, text):
        path = os.path.join(self.dir, name)
        with open(path, "w", encoding="utf-8") as stream:
            stream.write(text)
        return path

    def run_effect(self, doc, *args, path_with_pixelpie=True, pythonpath=None):
        """``python pixelpie_stipple.py ARGS doc`` with pixelpie on PATH (or not) and no package."""
        env = dict(os.environ)
        env["PATH"] = (self.bin_dir + os.pathsep if path_with_pixelpie else "") + self.bare_path
        env.pop("PYTHONPATH", None)
        env.pop("DOCUMENT_PATH", None)
        if pythonpath:
            env["PYTHONPATH"] = pythonpath
        proc = subprocess.run(
            [sys.executable, SCRIPT, *args, doc], stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, cwd=self.dir, check=False
        )
        return Run(proc)

    def run_cli(self, picture, *args):
        """``pixelpie stipple picture -o ref.svg ARGS``: the reference drawing's root."""
        out = os.path.join(self.dir, "reference.svg")
        subprocess.run([self.binary, "stipple", picture, "-o", out, "-q", *args], check=True)
        return inkex.load_svg(out).getroot()

    def assertDrawn(self, run):  # pylint: disable=invalid-name
        """The effect succeeded, quietly, and returned a document."""
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertNotIn("Traceback", run.stderr)
        self.assertEqual(run.stderr.strip(), "", "a drawing with no warning prints nothing (Inkscape would show it)")
        self.assertIsNotNone(run.root)

    def assertRefused(self, run, *words):  # pylint: disable=invalid-name
        """A non-zero exit, one line naming ``words``, no traceback, no document."""
        self.assertNotEqual(run.returncode, 0)
        self.assertEqual(run.stdout, b"", "no document is written")
        lines = run.stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, run.stderr)
        self.assertNotIn("Traceback", run.stderr)
        for word in words:
            self.assertIn(word, lines[0])
        return lines[0]

    def assertSameDots(self, got, reference, mapping, tolerance):  # pylint: disable=invalid-name
        """``got`` (user units) are ``reference`` (the CLI's mm) mapped, in order, within ``tolerance``."""
        self.assertEqual(len(got), len(reference))
        worst = 0.0
        for (gx, gy), (rx, ry) in zip(got, reference):
            point = mapping.apply_to_point((rx, ry))
            worst = max(worst, math.hypot(gx - point.x, gy - point.y))
        self.assertLess(worst, tolerance, f"a dot lies {worst} from the CLI's, moved")
        return worst


class EmbeddedImage(StippleTestBase):
    """The targets' document: A4, an embedded photo in a translated layer."""

    def document(self):
        return svg_document(
            '<g inkscape:groupmode="layer" id="layer1" inkscape:label="Photo" transform="translate(12.5,30)">'
            f'<image id="PHOTO" x="10" y="20" width="150" height="100" preserveAspectRatio="none" '
            f'xlink:href="{data_uri(ROCKET)}"/></g>'
        )

    def test_embedded_photo_in_translated_layer_is_stippled_onto_its_box(self):
        doc = self.write("a4.svg", self.document())
        run = self.run_effect(doc, "--id=PHOTO", "--points=3000")
        self.assertDrawn(run)
        labels = [label for label, _ in layers(run.root)]
        self.assertEqual(labels, ["Photo", "1 stipple"])
        photo = run.root.getElementById("PHOTO")
        self.assertIsNotNone(photo, "the image stays")
        self.assertEqual(photo.getparent().get("inkscape:label"), "Photo", "in its layer")
        self.assertTrue(photo.get("xlink:href").startswith("data:image/jpeg;base64,"))
        dots = dot_centres(run.root)
        self.assertLessEqual(abs(len(dots) - 3000), 90, f"{len(dots)} dots for 3000")
        # The box: the layer's translate(12.5, 30) and the image's x, y, size, in mm.
        x0, y0, x1, y1 = 22.5, 50.0, 172.5, 150.0
        xs, ys = [d[0] for d in dots], [d[1] for d in dots]
        for low, high, a, b in ((min(xs), max(xs), x0, x1), (min(ys), max(ys), y0, y1)):
            self.assertGreaterEqual(low, a - 1e-9)
            self.assertLessEqual(high, b + 1e-9)
            self.assertLess(low - a, 1.0, "the dots fill the box within 1 mm")
            self.assertLess(b - high, 1.0, "the dots fill the box within 1 mm")

    def test_dots_are_the_clis_moved_into_the_box_within_a_hundredth_of_a_mm(self):
        doc = self.write("a4.svg", self.document())
        run = self.run_effect(doc, "--id=PHOTO", "--points=3000")
        self.assertDrawn(run)
        # The CLI with the effect's defaults spelled as the CLI's own: the
        # 150 mm box is the drawing's width.
        ref = self.run_cli(ROCKET, "--points", "3000", "--pen-mm", "0.3", "--order", "tsp", "--width-mm", "150")
        width, height = (float(v) for v in ref.get("viewBox").split()[2:])
        self.assertAlmostEqual(width, 150.0)
        mapping = Transform(translate=(22.5, 50.0)) @ Transform(scale=(150.0 / width, 100.0 / height))
        self.assertSameDots(dot_centres(run.root), dot_centres(ref), mapping, 0.01)
        # The pen is the pen: 0.3 mm on the page.
        path = run.root.xpath("//*[@data-dot]")[0]
        scale = to_root(path.getparent())
        self.assertAlmostEqual(float(path.getparent().get("stroke-width")) * math.hypot(scale.a, scale.b), 0.3, places=3)

    def test_in_process_with_inkex_tester(self):
        """The same document through inkex.tester's effect runner, in this process."""
        doc = self.write("a4.svg", self.document())
        old = os.environ.get("PATH", "")
        os.environ["PATH"] = self.bin_dir + os.pathsep + old
        try:
            effect = self.assertEffect(doc, args=["--id=PHOTO", "--points=500", "--via=binary"])
        finally:
            os.environ["PATH"] = old
        root = effect.svg
        self.assertEqual([label for label, _ in layers(root)], ["Photo", "1 stipple"])
        self.assertLessEqual(abs(len(dot_centres(root)) - 500), 15)


class LinkedImage(StippleTestBase):
    """A linked photo, its path relative to the document."""

    def test_linked_relative_path_is_read_from_the_documents_folder(self):
        shutil.copy(DEFAULT, os.path.join(self.dir, "photo.png"))
        body = (
            '<g inkscape:groupmode="layer" id="layer1" inkscape:label="Layer 1">'
            '<image id="PHOTO" x="30" y="40" width="120" height="120" preserveAspectRatio="none" xlink:href="photo.png"/></g>'
        )
        doc = self.write("linked.svg", svg_document(body))
        run = self.run_effect(doc, "--id=PHOTO", "--points=800", "--order=none")
        self.assertDrawn(run)
        self.assertEqual(run.root.getElementById("PHOTO").get("xlink:href"), "photo.png", "the link is kept")
        ref = self.run_cli(DEFAULT, "--points", "800", "--pen-mm", "0.3", "--width-mm", "120")
        width, height = (float(v) for v in ref.get("viewBox").split()[2:])
        mapping = Transform(translate=(30, 40)) @ Transform(scale=(120 / width, 120 / height))
        self.assertSameDots(dot_centres(run.root), dot_centres(ref), mapping, 0.01)

    def test_linked_file_uri_and_missing_file(self):
        shutil.copy(DEFAULT, os.path.join(self.dir, "photo.png"))
        uri = "file://" + os.path.join(self.dir, "photo.png")
        body = f'<image id="PHOTO" x="0" y="0" width="50" height="50" xlink:href="{uri}"/>'
        run = self.run_effect(self.write("uri.svg", svg_document(body)), "--id=PHOTO", "--points=200")
        self.assertDrawn(run)
        self.assertLessEqual(abs(len(dot_centres(run.root)) - 200), 6)
        body = '<image id="PHOTO" x="0" y="0" width="50" height="50" xlink:href="gone.png"/>'
        run = self.run_effect(self.write("gone.svg", svg_document(body)), "--id=PHOTO", "--points=200")
        self.assertRefused(run, "gone.png", "relink or embed")


class TransformedLayer(StippleTestBase):
    """Rotations, scales and a viewBox in px: the drawing follows every transform."""

    def test_image_under_rotated_scaled_layer_and_own_transform(self):
        layer_t, image_t = "translate(40,60) rotate(30) scale(0.8)", "matrix(1,0,0.2,1,5,-3)"
        body = (
            f'<g inkscape:groupmode="layer" id="layer1" inkscape:label="Photo" transform="{layer_t}">'
            f'<g transform="translate(3,4)"><image id="PHOTO" x="10" y="20" width="90" height="60" '
            f'preserveAspectRatio="none" transform="{image_t}" xlink:href="{data_uri(ROCKET)}"/></g></g>'
        )
        doc = self.write("rotated.svg", svg_document(body))
        run = self.run_effect(doc, "--id=PHOTO", "--points=1000")
        self.assertDrawn(run)
        self.assertEqual([label for label, _ in layers(run.root)], ["Photo", "1 stipple"])
        chain = Transform(layer_t) @ Transform("translate(3,4)") @ Transform(image_t)
        # The drawing's width on the page: the image's 90 along its x axis, scaled.
        width_mm = 90 * math.hypot(chain.a, chain.b)
        self.assertAlmostEqual(width_mm, 72.0, places=6)
        ref = self.run_cli(ROCKET, "--points", "1000", "--pen-mm", "0.3", "--order", "tsp", "--width-mm", repr(width_mm))
        width, height = (float(v) for v in ref.get("viewBox").split()[2:])
        mapping = chain @ Transform(translate=(10, 20)) @ Transform(scale=(90 / width, 60 / height))
        self.assertSameDots(dot_centres(run.root), dot_centres(ref), mapping, 0.01)

    def test_document_in_px_with_a_scaled_viewbox(self):
        """A document whose user unit is 0.5 px: --width-mm is the photo's width on paper."""
        body = f'<image id="PHOTO" x="100" y="100" width="600" height="400" preserveAspectRatio="none" xlink:href="{data_uri(ROCKET)}"/>'
        doc = self.write("px.svg", svg_document(body, width="800px", height="1000px", viewbox="0 0 1600 2000"))
        run = self.run_effect(doc, "--id=PHOTO", "--points=600")
        self.assertDrawn(run)
        width_mm = 600 * 0.5 / MM  # 600 user units of half a px
        ref = self.run_cli(ROCKET, "--points", "600", "--pen-mm", "0.3", "--order", "tsp", "--width-mm", repr(width_mm))
        width, height = (float(v) for v in ref.get("viewBox").split()[2:])
        mapping = Transform(translate=(100, 100)) @ Transform(scale=(600 / width, 400 / height))
        uu_per_mm = 2 * MM
        self.assertSameDots(dot_centres(run.root), dot_centres(ref), mapping, 0.01 * uu_per_mm)


class AspectRatio(StippleTestBase):
    """preserveAspectRatio: meet draws the fitted picture, slice its visible part."""

    def test_xmidymid_meet_draws_the_fitted_rectangle(self):
        # A 3:2 picture in a 100 × 100 box: drawn 100 × 66.67, 16.67 from the top.
        body = f'<image id="PHOTO" x="20" y="30" width="100" height="100" preserveAspectRatio="xMidYMid meet" xlink:href="{data_uri(ROCKET)}"/>'
        run = self.run_effect(self.write("meet.svg", svg_document(body)), "--id=PHOTO", "--points=1000")
        self.assertDrawn(run)
        top = 30 + (100 - 100 * 320 / 480) / 2
        ref = self.run_cli(ROCKET, "--points", "1000", "--pen-mm", "0.3", "--order", "tsp", "--width-mm", "100")
        width, height = (float(v) for v in ref.get("viewBox").split()[2:])
        mapping = Transform(translate=(20, top)) @ Transform(scale=(100 / width, 100 * 320 / 480 / height))
        self.assertSameDots(dot_centres(run.root), dot_centres(ref), mapping, 0.01)
        ys = [d[1] for d in dot_centres(run.root)]
        self.assertGreater(min(ys), top - 1e-6)
        self.assertLess(max(ys), top + 100 * 320 / 480 + 1e-6)
        self.assertLess(min(ys) - top, 1.0)

    def test_no_attribute_is_xmidymid_meet(self):
        body = f'<image id="PHOTO" x="0" y="0" width="60" height="60" xlink:href="{data_uri(ROCKET)}"/>'
        run = self.run_effect(self.write("default.svg", svg_document(body)), "--id=PHOTO", "--points=300")
        self.assertDrawn(run)
        ys = [d[1] for d in dot_centres(run.root)]
        self.assertGreater(min(ys), 10 - 1e-6)
        self.assertLess(max(ys), 50 + 1e-6)

    def test_xminymin_slice_draws_the_visible_part(self):
        # A 3:2 picture sliced into a 50 × 50 box, left-aligned: the left 320 × 320 pixels.
        body = f'<image id="PHOTO" x="10" y="10" width="50" height="50" preserveAspectRatio="xMinYMin slice" xlink:href="{data_uri(ROCKET)}"/>'
        run = self.run_effect(self.write("slice.svg", svg_document(body)), "--id=PHOTO", "--points=500")
        self.assertDrawn(run)
        ref = self.run_cli(ROCKET, "--points", "500", "--pen-mm", "0.3", "--order", "tsp", "--width-mm", "50", "--crop", "0,0,320,320")
        width, height = (float(v) for v in ref.get("viewBox").split()[2:])
        mapping = Transform(translate=(10, 10)) @ Transform(scale=(50 / width, 50 / height))
        self.assertSameDots(dot_centres(run.root), dot_centres(ref), mapping, 0.01)

    def test_none_with_another_aspect_stretches_the_domain_not_the_dots(self):
        body = f'<image id="PHOTO" x="0" y="0" width="120" height="40" preserveAspectRatio="none" xlink:href="{data_uri(ROCKET)}"/>'
        run = self.run_effect(self.write("stretch.svg", svg_document(body)), "--id=PHOTO", "--points=400")
        self.assertDrawn(run)
        wrap = run.root.xpath("//*[@data-dot]")[0].getparent().getparent()
        matrix = Transform(wrap.get("transform"))
        self.assertAlmostEqual(matrix.a, matrix.d, places=2, msg="the dots stay round: one scale")
        ys = [d[1] for d in dot_centres(run.root)]
        self.assertLess(max(ys), 40 + 1e-6)
        self.assertGreater(max(ys), 39)


class Colour(StippleTestBase):
    """--pens=cmyk: one numbered layer a pen; refill parts numbered in order."""

    def document(self):
        return svg_document(
            '<g inkscape:groupmode="layer" id="layer1" inkscape:label="Photo" transform="translate(5,5)">'
            f'<image id="PHOTO" x="0" y="0" width="120" height="80" preserveAspectRatio="none" xlink:href="{data_uri(ROCKET)}"/></g>'
        )

    def test_cmyk_gives_one_numbered_layer_per_pen(self):
        run = self.run_effect(self.write("cmyk.svg", self.document()), "--id=PHOTO", "--points=2000", "--pens=cmyk")
        self.assertDrawn(run)
        new = layers(run.root)[1:]
        # AxiDraw pauses before each pen after the first, as the CLI's labels say.
        self.assertEqual([label for label, _ in new], ["1 yellow", "!2 cyan", "!3 magenta", "!4 black"])
        colours = [g.xpath(".//*[@stroke]")[0].get("stroke") for _, g in new]
        self.assertEqual(colours, ["#ffff00", "#00ffff", "#ff00ff", "#000000"])
        counts = [len(g.xpath(".//*[@data-dot]")) for _, g in new]
        self.assertTrue(all(n > 0 for n in counts), counts)
        self.assertLessEqual(abs(sum(counts) - 2000), 60)
        ref = self.run_cli(ROCKET, "--points", "2000", "--pens", "cmyk", "--pen-mm", "0.3", "--order", "tsp", "--width-mm", "120")
        # The CLI names a pen's layer by its pen ("cyan"; numbered with refill
        # parts), after the first with AxiDraw's pause mark ("!cyan").
        self.assertEqual([label for label, _ in layers(ref)], ["yellow", "!cyan", "!magenta", "!black"])
        width, height = (float(v) for v in ref.get("viewBox").split()[2:])
        mapping = Transform(translate=(5, 5)) @ Transform(scale=(120 / width, 80 / height))
        self.assertSameDots(dot_centres(run.root), dot_centres(ref), mapping, 0.01)

    def test_refill_parts_paper_and_pauses(self):
        args = ("--id=PHOTO", "--points=1500", "--pens=cmyk", "--refill-mm=3000", "--paper-colour=kraft", "--pause=pens")
        run = self.run_effect(self.write("refill.svg", self.document()), *args)
        self.assertDrawn(run)
        labels = [label for label, _ in layers(run.root)][1:]
        self.assertEqual(labels[0], "% paper (not plotted)")
        numbers, pens = [], []
        for label in labels[1:]:
            match = re.fullmatch(r"(!?)(\d+) (\w+) (\d+)/(\d+)", label)
            self.assertIsNotNone(match, label)
            numbers.append(int(match.group(2)))
            self.assertEqual(match.group(1) == "!", bool(pens) and pens[-1] != match.group(3), label)
            pens.append(match.group(3))
        self.assertEqual(numbers, list(range(1, len(numbers) + 1)))
        self.assertEqual(sorted(set(pens), key=pens.index), ["yellow", "cyan", "magenta", "black"])
        self.assertGreater(len(numbers), 4, "refill parts")

    def test_a_second_run_numbers_after_the_layers_there(self):
        first = self.run_effect(self.write("once.svg", self.document()), "--id=PHOTO", "--points=300", "--pens=cmyk")
        self.assertDrawn(first)
        again = self.write("twice.svg", first.stdout.decode("utf-8"))
        second = self.run_effect(again, "--id=PHOTO", "--points=300")
        self.assertDrawn(second)
        self.assertEqual([label for label, _ in layers(second.root)][-1], "5 stipple")


class Refusals(StippleTestBase):
    """What stops the effect: one line, a non-zero exit, no traceback, no document."""

    def document(self):
        return svg_document(
            f'<rect id="RECT" x="0" y="0" width="10" height="10"/>'
            f'<image id="PHOTO" x="0" y="0" width="50" height="50" xlink:href="{data_uri(DEFAULT)}"/>'
        )

    def test_nothing_selected(self):
        run = self.run_effect(self.write("doc.svg", self.document()), "--points=300")
        self.assertRefused(run, "Nothing is selected", "select the photo")

    def test_no_image_selected(self):
        run = self.run_effect(self.write("doc.svg", self.document()), "--id=RECT", "--points=300")
        self.assertRefused(run, "No image is selected", "rect")

    def test_no_pixelpie_anywhere(self):
        run = self.run_effect(self.write("doc.svg", self.document()), "--id=PHOTO", path_with_pixelpie=False)
        self.assertRefused(run, "pixelpie is not found", "PATH", "--pixelpie")

    def test_a_wrong_binary_path(self):
        run = self.run_effect(self.write("doc.svg", self.document()), "--id=PHOTO", "--pixelpie=/nowhere/pixelpie")
        self.assertRefused(run, "/nowhere/pixelpie", "--pixelpie")

    def test_an_option_the_cli_refuses_names_it(self):
        run = self.run_effect(self.write("doc.svg", self.document()), "--id=PHOTO", "--pens=cmyk", "--choose=9")
        self.assertRefused(run, "--choose")

    def test_the_binary_path_option_is_used(self):
        run = self.run_effect(
            self.write("doc.svg", self.document()), "--id=PHOTO", "--points=200", f"--pixelpie={self.binary}", path_with_pixelpie=False
        )
        self.assertDrawn(run)


class PythonPackage(StippleTestBase):
    """Through the pixelpie package (the wheel unpacked on PYTHONPATH): the binary's drawing."""

    def setUp(self):
        super().setUp()
        self.package = os.environ.get("PIXELPIE_INKEX_PACKAGE", "")
        if not os.path.isdir(os.path.join(self.package, "pixelpie")):
            if os.environ.get("PIXELPIE_EXPECT_PACKAGE") == "1":
                raise AssertionError(f"no pixelpie package in PIXELPIE_INKEX_PACKAGE={self.package!r}")
            self.skipTest("PIXELPIE_INKEX_PACKAGE is not a folder holding the pixelpie package")

    def test_package_draws_what_the_binary_draws(self):
        body = (
            '<g inkscape:groupmode="layer" id="layer1" inkscape:label="Photo" transform="translate(7,9)">'
            f'<image id="PHOTO" x="3" y="4" width="90" height="60" preserveAspectRatio="none" xlink:href="{data_uri(ROCKET)}"/></g>'
        )
        doc = self.write("pkg.svg", svg_document(body))
        for extra in ((), ("--pens=cmyk",)):
            binary = self.run_effect(doc, "--id=PHOTO", "--points=800", "--via=binary", *extra)
            package = self.run_effect(
                doc, "--id=PHOTO", "--points=800", "--via=package", *extra, path_with_pixelpie=False, pythonpath=self.package
            )
            self.assertDrawn(binary)
            self.assertDrawn(package)
            self.assertEqual([l for l, _ in layers(package.root)], [l for l, _ in layers(binary.root)])
            self.assertSameDots(dot_centres(package.root), dot_centres(binary.root), Transform(), 1e-9)

    def test_auto_prefers_the_package(self):
        body = f'<image id="PHOTO" x="0" y="0" width="40" height="40" xlink:href="{data_uri(DEFAULT)}"/>'
        doc = self.write("auto.svg", svg_document(body))
        run = self.run_effect(doc, "--id=PHOTO", "--points=200", path_with_pixelpie=False, pythonpath=self.package)
        self.assertDrawn(run)

    def test_package_forced_but_missing(self):
        body = f'<image id="PHOTO" x="0" y="0" width="40" height="40" xlink:href="{data_uri(DEFAULT)}"/>'
        run = self.run_effect(self.write("nopkg.svg", svg_document(body)), "--id=PHOTO", "--via=package")
        self.assertRefused(run, "cannot import the pixelpie package", "--via")


class InxFile(unittest.TestCase):
    """The .inx against the script: inkex's own check, which catches a missing param."""

    def check(self, folder):
        return subprocess.run(
            [sys.executable, "-m", "inkex.tester.test_inx_file", "pixelpie_stipple.inx"],
            cwd=folder,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            check=False,
        )

    def test_inx_matches_the_script(self):
        proc = self.check(EXT_DIR)
        self.assertEqual(proc.returncode, 0, proc.stdout.decode())
        self.assertIn("Ran 2 tests", proc.stdout.decode())

    def test_the_check_catches_a_param_missing_from_the_inx(self):
        folder = tempfile.mkdtemp(prefix="pixelpie-inx-")
        try:
            shutil.copy(SCRIPT, folder)
            with open(INX, encoding="utf-8") as stream:
                text = stream.read()
            broken = re.sub(r'\s*<param name="seed"[^>]*>0</param>', "", text)
            self.assertNotEqual(broken, text)
            with open(os.path.join(folder, "pixelpie_stipple.inx"), "w", encoding="utf-8") as stream:
                stream.write(broken)
            proc = self.check(folder)
            self.assertNotEqual(proc.returncode, 0)
            self.assertIn("Script args missing from inx", proc.stdout.decode())
        finally:
            shutil.rmtree(folder, ignore_errors=True)

    def test_options_are_the_clis(self):
        """Each option the effect passes is one `pixelpie stipple --help` lists."""
        helptext = subprocess.run([pixelpie_binary(), "stipple", "--help"], stdout=subprocess.PIPE, check=True).stdout.decode()
        for name, _ in pixelpie_stipple.CLI_OPTIONS:
            self.assertRegex(helptext, rf"\n\s+--{re.escape(name)}\b", name)


if __name__ == "__main__":
    unittest.main()
