#!/usr/bin/env python3
"""PixelPie ▸ Stipple, an Inkscape effect: the selected photo as pen-plotter layers.

Inkscape runs it as ``python pixelpie_stipple.py --id=PHOTO [--points=…] in.svg
> out.svg`` (``pixelpie_stipple.inx`` declares the menu entry and the
options). For each selected ``<image>`` — embedded (a ``data:`` URI) or
linked (a path, relative to the document) — it draws the picture with
``pixelpie stipple`` at the size the photo has on the page, in mm, with a
pen (``--pen-mm``), and adds the drawing's layers to the document as new
top-level layers, labelled as ``stipple`` labels them ("1 stipple", or one a
pen, "1 yellow" … "4 black", and refill parts "2 black 2/35"), which
AxiDraw's software numbers (``-m layers -l N``). The photo stays in its layer.

Where the drawing goes: the image's x, y, width and height, its
``preserveAspectRatio`` (``none`` stretches the picture over the box, so the
domain is given the box's aspect and the dots stay round; ``meet`` draws the
picture's fitted rectangle; ``slice`` draws only the visible part, through
``--crop``) and every transform above it, up to the root. The drawing's own
coordinates (mm, the CLI's page) are mapped onto that rectangle by one
transform on a group inside each new layer, so the dots are the CLI's, moved.

How it stipples: through the ``pixelpie`` Python package when this Python can
import it (``pixelpie.stipple(..., svg=True)``, the CLI's file byte for byte),
otherwise through the ``pixelpie`` binary: the path on the Advanced tab
(``--pixelpie``), else ``pixelpie`` on PATH. ``--via`` forces one.

Errors (nothing selected, no image, no pixelpie, a missing linked file, an
option the CLI refuses) stop it with one line, through
:class:`inkex.AbortExtension`: Inkscape shows the line, leaves the document
unchanged, and the script exits non-zero with no traceback.
"""

import base64
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import urllib.parse
import warnings

import inkex
from inkex import Transform

#: The CLI's options the extension passes, as (name, kind): the .inx params
#: carry the same names. ``kind``: how a value becomes an argument, and which
#: value means "not given" (the CLI's own default).
CLI_OPTIONS = (
    ("points", "count"),  # 0: not given (the CLI's count, a line's from its pen)
    ("style", "text"),
    ("line-smooth", "flag"),
    ("dot", "text"),
    ("dot-path", "text"),
    ("order", "text"),
    ("seed", "int"),
    ("pen-mm", "float"),
    ("ink", "text"),  # "": black (and --pens cannot take it)
    ("pens", "text"),  # "": one pen in --ink
    ("choose", "count"),  # 0: every pen of --pens
    ("layer-order", "text"),
    ("refill-mm", "positive"),  # 0: no refill parts
    ("paper-colour", "text"),  # "": white
    ("tones", "text"),
    ("gamma", "float"),
    ("black-level", "float"),
    ("white-level", "float"),
    ("invert", "flag"),
)

#: Media types of embedded pictures, with the file extension the CLI reads.
MEDIA_TYPES = {
    "image/png": ".png",
    "image/jpeg": ".jpg",
    "image/jpg": ".jpg",
    "image/tiff": ".tif",
    "image/bmp": ".bmp",
    "image/x-ms-bmp": ".bmp",
    "image/webp": ".webp",
    "image/x-exr": ".exr",
    "image/aces": ".exr",
}

#: CSS units in user units (px): an attribute "10mm" is 10 × 96 / 25.4.
UNITS = {
    "": 1.0,
    "px": 1.0,
    "mm": 96.0 / 25.4,
    "cm": 96.0 / 2.54,
    "q": 96.0 / 101.6,
    "in": 96.0,
    "pt": 96.0 / 72.0,
    "pc": 16.0,
}

INSTALL_HINT = (
    "install the pixelpie package into Inkscape's Python (pip install pixelpie), "
    "put the pixelpie binary on PATH, or give its path on the Advanced tab (--pixelpie)"
)


def length(value, default=None, percent_of=None):
    """A length attribute ("12", "12.5mm", "50%") in user units, or ``default``."""
    if value is None or not str(value).strip():
        return default
    match = re.fullmatch(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([a-zA-Z%]*)\s*", str(value))
    if not match:
        return default
    number, unit = float(match.group(1)), match.group(2).lower()
    if unit == "%":
        return default if percent_of is None else number / 100.0 * percent_of
    if unit not in UNITS:
        return default
    return number * UNITS[unit]


def user_units_per_mm(svg):
    """The document's user units in a mm of the page (its width over its viewBox)."""
    viewbox = [float(v) for v in re.split(r"[\s,]+", (svg.get("viewBox") or "").strip()) if v]
    width = length(svg.get("width"))
    if len(viewbox) == 4 and viewbox[2] > 0 and width:
        return viewbox[2] / (width / UNITS["mm"])
    return UNITS["mm"]  # no viewBox (or no width): user units are px


def transform_to_root(elem):
    """The transform from ``elem``'s own coordinates to the document's user units.

    Every ``transform`` from ``elem`` up to, not including, the root ``<svg>``:
    the new layers are the root's children, so the root's own transform (if
    any) applies to them as to the photo.
    """
    total = Transform()
    node = elem
    while node is not None and node.getparent() is not None:
        total = Transform(node.get("transform")) @ total
        node = node.getparent()
    return total


def aspect_ratio(value):
    """``preserveAspectRatio`` as (align, slice): align is "none" or e.g. "xMidYMid"."""
    words = (value or "").split()
    if words and words[0] == "defer":
        words = words[1:]
    align = words[0] if words else "xMidYMid"
    if align != "none" and not re.fullmatch(r"x(Min|Mid|Max)Y(Min|Mid|Max)", align):
        align = "xMidYMid"
    return align, len(words) > 1 and words[1] == "slice"


def align_fractions(align):
    """xMinYMax → (0, 1): where the picture sits in the spare room, per axis."""
    part = {"Min": 0.0, "Mid": 0.5, "Max": 1.0}
    return part[align[1:4]], part[align[5:8]]


class Placement:
    """Where the drawing of one image goes, and the CLI options that size it.

    ``rect`` (x, y, w, h) is the drawn part of the picture in the image's own
    coordinates; ``to_root`` maps those to the document's user units;
    ``extra`` holds ``--width-mm`` (the rectangle's width on the page, in mm),
    and ``--crop`` (slice) or ``--width``/``--height`` (a stretched picture).
    """

    def __init__(self, image, picture, domain, uu_per_mm):
        pic_w, pic_h = picture
        x = length(image.get("x"), 0.0)
        y = length(image.get("y"), 0.0)
        w = length(image.get("width"), float(pic_w))
        h = length(image.get("height"), float(pic_h))
        if not (w > 0 and h > 0):
            raise inkex.AbortExtension(
                f"image '{image.get('id')}' has no size (width {image.get('width')!r}, "
                f"height {image.get('height')!r}): give it a width and height (Object ▸ Transform)"
            )
        self.extra = []
        align, slice_ = aspect_ratio(image.get("preserveAspectRatio"))
        if align == "none":
            self.rect = (x, y, w, h)
            if abs((w / h) / (pic_w / pic_h) - 1.0) > 0.005:
                # Stretched: a domain of the box's aspect keeps the dots round.
                dom_w = domain[0]
                self.extra += ["--width", str(dom_w), "--height", str(max(1, round(dom_w * h / w)))]
        else:
            fx, fy = align_fractions(align)
            scale = (max if slice_ else min)(w / pic_w, h / pic_h)
            left = x + (w - pic_w * scale) * fx
            top = y + (h - pic_h * scale) * fy
            if slice_:
                # The visible part of the picture, in its pixels, whole.
                cx0 = max(0, math.floor((x - left) / scale + 1e-6))
                cy0 = max(0, math.floor((y - top) / scale + 1e-6))
                cx1 = min(pic_w, math.ceil((x + w - left) / scale - 1e-6))
                cy1 = min(pic_h, math.ceil((y + h - top) / scale - 1e-6))
                if (cx0, cy0, cx1, cy1) != (0, 0, pic_w, pic_h):
                    self.extra += ["--crop", f"{cx0},{cy0},{cx1 - cx0},{cy1 - cy0}"]
                self.rect = (left + cx0 * scale, top + cy0 * scale, (cx1 - cx0) * scale, (cy1 - cy0) * scale)
            else:
                self.rect = (left, top, pic_w * scale, pic_h * scale)
        self.to_root = transform_to_root(image)
        a, b = self.to_root.a, self.to_root.b
        self.width_mm = self.rect[2] * math.hypot(a, b) / uu_per_mm
        if not self.width_mm > 0:
            raise inkex.AbortExtension(f"image '{image.get('id')}' is drawn at zero width: undo its transform")
        self.extra += ["--width-mm", repr(self.width_mm)]

    def drawing_transform(self, viewbox):
        """The drawing's coordinates (its SVG viewBox) onto ``rect``, in user units."""
        vx, vy, vw, vh = viewbox
        x, y, w, h = self.rect
        return self.to_root @ Transform(translate=(x, y)) @ Transform(scale=(w / vw, h / vh)) @ Transform(
            translate=(-vx, -vy)
        )


class Engine:
    """``pixelpie stipple``, through the Python package or the binary."""

    def __init__(self, via, binary_path):
        self.module = None
        self.binary = None
        if via in ("auto", "package"):
            try:
                import pixelpie  # pylint: disable=import-outside-toplevel

                if hasattr(pixelpie, "stipple") and hasattr(pixelpie, "plan"):
                    self.module = pixelpie
            except Exception:  # pylint: disable=broad-except
                self.module = None  # not installed, or built for another Python
            if self.module is None and via == "package":
                raise inkex.AbortExtension(
                    f"this Python ({sys.executable}) cannot import the pixelpie package: "
                    "pip install pixelpie into it, or set 'Stipple with' to auto or binary (--via)"
                )
        if self.module is None:
            if binary_path:
                path = os.path.expanduser(binary_path)
                if not (os.path.isfile(path) and os.access(path, os.X_OK)):
                    raise inkex.AbortExtension(
                        f"no pixelpie binary at '{binary_path}': fix the path on the Advanced tab (--pixelpie)"
                    )
                self.binary = path
            else:
                self.binary = shutil.which("pixelpie")
            if self.binary is None:
                raise inkex.AbortExtension(f"pixelpie is not found: {INSTALL_HINT}")

    @property
    def name(self):
        """How it stipples, in words."""
        return "the pixelpie package" if self.module is not None else self.binary

    def _run(self, args):
        proc = subprocess.run(
            [self.binary, "stipple", *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            check=False,
        )
        err = proc.stderr.decode("utf-8", "replace")
        if proc.returncode != 0:
            raise inkex.AbortExtension("pixelpie stipple: " + first_line(err, f"exit status {proc.returncode}"))
        return proc.stdout.decode("utf-8", "replace"), err

    def picture(self, path, args, out_svg):
        """The picture's size in pixels and the domain's, from the CLI's plan.

        A pen needs a page width (``--width-mm``): any one does for the plan.
        """
        args = [*args, "--width-mm", "100"]
        if self.module is not None:
            plan = self._call(self.module.plan, path, args)
        else:
            out, _ = self._run([path, "-o", out_svg, "--plan", "-q", *args])
            try:
                plan = json.loads(out)
            except ValueError:
                raise inkex.AbortExtension(
                    f"{self.binary} printed no plan: is it pixelpie 0.1 or later? ({first_line(out, 'no output')})"
                ) from None
        return tuple(plan["picture"]), tuple(plan["domain"])

    def stipple(self, path, args, out_svg):
        """The drawing's SVG text, and the warnings it gave."""
        if self.module is not None:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                text = self._call(self.module.stipple, path, args, svg=True)
            return text, [str(w.message) for w in caught]
        _, err = self._run([path, "-o", out_svg, "-q", *args])
        with open(out_svg, encoding="utf-8") as stream:
            text = stream.read()
        return text, [line for line in err.splitlines() if line.strip()]

    @staticmethod
    def _call(func, path, args, **more):
        try:
            return func(path, **keywords(args), **more)
        except (ValueError, RuntimeError, TypeError, OSError) as err:
            raise inkex.AbortExtension("pixelpie: " + first_line(str(err), type(err).__name__)) from None


def first_line(text, default):
    """The first non-empty line of a message, without the CLI's "error: " prefix."""
    for line in text.splitlines():
        line = line.strip()
        if line:
            return re.sub(r"^error:\s*", "", line)
    return default


def keywords(args):
    """CLI arguments (``["--pen-mm", "0.3", "--invert"]``) as the package's keywords."""
    out = {}
    i = 0
    while i < len(args):
        name = args[i][2:].replace("-", "_")
        if i + 1 < len(args) and not args[i + 1].startswith("--"):
            value = args[i + 1]
            i += 2
        else:
            value = True
            i += 1
        if isinstance(value, str):
            for kind in (int, float):
                try:
                    value = kind(value)
                    break
                except ValueError:
                    pass
        out[name] = value
    return out


class PixelpieStipple(inkex.EffectExtension):
    """Stipple the selected photo into numbered pen layers (see the module's doc)."""

    def add_arguments(self, pars):
        pars.add_argument("--tab", type=str, default="drawing")
        pars.add_argument("--points", type=int, default=10000)
        pars.add_argument("--style", type=str, default="dots", choices=["dots", "line"])
        pars.add_argument("--line-smooth", type=inkex.Boolean, default=False)
        pars.add_argument("--dot", type=str, default="fixed", choices=["fixed", "sized", "proportional"])
        pars.add_argument("--dot-path", type=str, default="spiral", choices=["spiral", "circle", "touch"])
        pars.add_argument("--order", type=str, default="tsp", choices=["tsp", "none"])
        pars.add_argument("--seed", type=int, default=0)
        pars.add_argument("--pen-mm", type=float, default=0.3)
        pars.add_argument("--ink", type=str, default="")
        pars.add_argument("--pens", type=str, default="")
        pars.add_argument("--choose", type=int, default=0)
        pars.add_argument("--layer-order", type=str, default="light-first", choices=["light-first", "pens"])
        pars.add_argument("--refill-mm", type=float, default=0.0)
        pars.add_argument("--paper-colour", type=str, default="")
        pars.add_argument("--tones", type=str, default="display", choices=["display", "linear"])
        pars.add_argument("--gamma", type=float, default=1.0)
        pars.add_argument("--black-level", type=float, default=0.0)
        pars.add_argument("--white-level", type=float, default=1.0)
        pars.add_argument("--invert", type=inkex.Boolean, default=False)
        pars.add_argument("--pause", type=str, default="layers", choices=["layers", "pens", "none"])
        pars.add_argument("--via", type=str, default="auto", choices=["auto", "package", "binary"])
        pars.add_argument("--pixelpie", type=str, default="")

    def cli_args(self):
        """The options as ``pixelpie stipple`` arguments (those left at "not given" out)."""
        args = []
        for name, kind in CLI_OPTIONS:
            value = getattr(self.options, name.replace("-", "_"))
            if kind == "flag":
                if value:
                    args.append("--" + name)
                continue
            if kind == "text":
                value = str(value).strip()
                if not value:
                    continue
            elif kind in ("count", "positive") and not value > 0:
                continue
            elif kind == "float":
                value = repr(float(value))
            args += ["--" + name, str(value)]
        return args

    def images(self):
        """The selected images, and those inside selected groups, in document order."""
        selected = list(self.svg.selection.values())
        if not selected:
            raise inkex.AbortExtension(
                "Nothing is selected: select the photo (an image) and run Extensions ▸ PixelPie ▸ Stipple again"
            )
        found = []
        for elem in selected:
            if isinstance(elem, inkex.Image):
                found.append(elem)
            else:
                found += [e for e in elem.iterdescendants() if isinstance(e, inkex.Image)]
        unique = list({id(e): e for e in found}.values())
        if not unique:
            kinds = sorted({elem.TAG for elem in selected})
            raise inkex.AbortExtension(
                f"No image is selected (the selection is: {', '.join(kinds)}): select the photo and run it again"
            )
        return unique

    def picture_file(self, image, folder):
        """The image's picture as a file the CLI reads: embedded ones are written out."""
        href = image.get("xlink:href") or image.get("href") or ""
        label = image.get("id") or "the image"
        if href.startswith("data:"):
            head, _, data = href.partition(",")
            media = head[5:].split(";")[0].strip().lower()
            if media not in MEDIA_TYPES:
                raise inkex.AbortExtension(
                    f"image '{label}' is embedded as {media or 'an unknown type'}: pixelpie reads PNG, JPEG, TIFF, "
                    "BMP, WebP and EXR; embed the photo as one of those"
                )
            try:
                raw = base64.b64decode(data) if ";base64" in head else urllib.parse.unquote_to_bytes(data)
            except ValueError:
                raise inkex.AbortExtension(f"image '{label}' has a broken data URI: embed the photo again") from None
            path = os.path.join(folder, (label if re.fullmatch(r"[\w.-]+", label) else "picture") + MEDIA_TYPES[media])
            with open(path, "wb") as stream:
                stream.write(raw)
            return path
        if not href:
            raise inkex.AbortExtension(f"image '{label}' has no picture (no href): link or embed a photo")
        name = href
        if name.startswith("file:"):
            name = urllib.parse.unquote(urllib.parse.urlparse(name).path)
        candidates = []
        if os.path.isabs(os.path.expanduser(name)):
            candidates.append(os.path.expanduser(name))
        else:
            folder_of_doc = self.svg_path()
            if folder_of_doc:
                candidates.append(os.path.join(folder_of_doc, name))
        absref = image.get("sodipodi:absref")
        if absref:
            candidates.append(absref)
        for path in candidates:
            if os.path.isfile(path):
                return os.path.abspath(path)
        if not candidates:
            raise inkex.AbortExtension(
                f"image '{label}' links '{href}' relative to the document, which is not saved: save it first"
            )
        raise inkex.AbortExtension(
            f"image '{label}' links '{href}', which is not found (looked at {candidates[0]}): relink or embed it"
        )

    def effect(self):
        images = self.images()
        engine = Engine(self.options.via, self.options.pixelpie.strip())
        base = self.cli_args()
        uu_per_mm = user_units_per_mm(self.svg)
        top_number = max([layer_number(g.get("inkscape:label")) or 0 for g in self.top_layers()] + [0])
        drawings = []
        with tempfile.TemporaryDirectory(prefix="pixelpie-inkscape-") as folder:
            for image in images:
                path = self.picture_file(image, folder)
                picture, domain = engine.picture(path, base, os.path.join(folder, "plan.svg"))
                place = Placement(image, picture, domain, uu_per_mm)
                text, said = engine.stipple(path, base + place.extra, os.path.join(folder, "drawing.svg"))
                drawings.append((image, place, text))
                for line in said:
                    self.msg(f"pixelpie ({image.get('id')}): {line}")
        # Nothing is added before every image is drawn: an error leaves the document as it was.
        for image, place, text in drawings:
            top_number = self.add_layers(text, place, top_number)

    def top_layers(self):
        """The document's top-level layers."""
        return [g for g in self.svg if isinstance(g, inkex.Layer)]

    def add_layers(self, text, place, top_number):
        """The drawing's layers as new top-level layers, numbered after ``top_number``."""
        drawing = inkex.load_svg(text.encode("utf-8")).getroot()
        viewbox = [float(v) for v in re.split(r"[\s,]+", drawing.get("viewBox").strip())]
        matrix = place.drawing_transform(viewbox)
        offset = top_number
        position = 0
        first = True
        last_pen = None
        for g in list(drawing):
            if not isinstance(g, inkex.Group) or g.get("inkscape:groupmode") != "layer":
                continue
            label = g.get("inkscape:label") or "stipple"
            if not label.startswith("%"):  # "%": a documentation layer (the paper), not plotted
                # The CLI's own pause marks ("!2 black 2/35"): this effect sets its own (--pause).
                label = label[1:] if label.startswith("!") else label
                position += 1
                number = layer_number(label)
                if number is None:
                    # A colour drawing's layers are named by pen alone ("cyan"):
                    # numbered by place, as the CLI numbers refill parts.
                    label = f"{position} {label}"
                    number = position
                label = re.sub(r"^\d+", str(number + offset), label)
                top_number = max(top_number, number + offset)
                pen = re.sub(r"\s+\d+/\d+$", "", label.split(" ", 1)[-1])
                pause = self.options.pause == "layers" or (self.options.pause == "pens" and pen != last_pen)
                if pause and not first:
                    label = "!" + label
                first = False
                last_pen = pen
            layer = inkex.Layer.new(label)
            layer.set("id", self.svg.get_unique_id("pixelpie-layer"))
            if g.get("style"):
                layer.set("style", g.get("style"))  # a blend mode: with the layers below
            wrap = inkex.Group()
            # Twelve digits: inkex's own str(Transform) keeps six, 0.03 mm on a metre.
            wrap.set("transform", "matrix({})".format(" ".join(f"{v:.12g}" for v in matrix.to_hexad())))
            for name, value in g.attrib.items():
                if name not in ("id", "style") and not name.startswith("{"):
                    wrap.set(name, value)
            for child in list(g):
                wrap.append(child)
            layer.append(wrap)
            self.svg.append(layer)
        return top_number


def layer_number(label):
    """The number AxiDraw reads at the start of a layer's label ("!" allowed), or None."""
    match = re.match(r"\s*!?\s*(\d+)", label or "")
    return int(match.group(1)) if match else None


if __name__ == "__main__":
    PixelpieStipple().run()
