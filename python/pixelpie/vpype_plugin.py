"""The ``pixelpie`` command of vpype, the pen-plotter toolkit.

Installed with the package's ``vpype`` extra (``pip install "pixelpie[vpype]"``,
or ``pip install "./python[vpype]"`` from a checkout), vpype finds it through
the ``vpype.plugins`` entry point::

    vpype pixelpie photo.jpg --points 20000 --pens cmyk linesort write out.svg

It stipples the photo as ``pixelpie stipple`` does, with the same options
(``--style line``: one continuous pen line per pen instead of dots, one path
per layer), and adds the pen paths to vpype's document: one layer per pen, in plotting
order, the lightest ink first (layer 1 is yellow, then cyan, magenta and
black for ``--pens cmyk``; ``--layer-order pens`` keeps the pens' own
order), each named after its pen and carrying its colour and pen width, and
the sheet as the page size. The dots are the command line's for the same
options: the command writes the drawing with :func:`pixelpie.stipple` to a
temporary SVG in pen mode (``--pen-mm``) and reads it with
:func:`vpype.read_multilayer_svg`.

vpype's HPGL writer (``write --device NAME``) crops the page to what the
plotter reaches, cutting a dot there in pieces. With ``--device NAME`` the
drawing is fitted inside that plotter's reach (a wider margin when
``--margin`` is not given, a usage error when the given one is too narrow);
without it, a warning names each plotter of vpype's configuration that
would cut dots on this sheet, with the margin that keeps them whole
(:func:`plotter_reach`, :func:`dots_outside`); ``--device none`` says no
HPGL plotter draws the page. The page is the sheet in vpype's own unit, so
that ``write --device NAME`` finds the plotter's paper from it.

Defaults where the command line has none: an A4 sheet (``--paper a4``, 10 mm
margins, or with ``--device`` the least that keeps every dot within the
plotter's reach; portrait) unless ``--paper`` or ``--width-mm`` is given, a pen
0.3 mm wide unless ``--pen-mm`` is given (a pen file's ``width_mm`` still
sets its own pen's width), and 10 000 dots unless ``--points`` (or a dot
radius, ``-o dot_radius=R`` or ``-o min_radius=R``) is given; a line
(``--style line``) takes the count its pen needs for the photo's tones
unless ``--points`` is given. Options may come before or after the image.

This module imports without vpype; then :data:`pixelpie` is a stand-in that
raises ``ImportError`` saying how to install the extra.
"""

from __future__ import annotations

import html
import io
import json
import logging
import math
import os
import re
import tempfile
from typing import Any, Callable, Dict, List, NamedTuple, Optional, Sequence, Tuple

__all__ = [
    "pixelpie",
    "DEFAULT_PAPER",
    "DEFAULT_PEN_MM",
    "DEFAULT_POINTS",
    "DEFAULT_MARGIN_MM",
    "GCODE_PROFILE",
    "Reach",
    "plotter_reach",
    "dots_outside",
]

#: The sheet when neither ``--paper`` nor ``--width-mm`` is given.
DEFAULT_PAPER = "a4"
#: The pen width in mm when ``--pen-mm`` is not given.
DEFAULT_PEN_MM = 0.3
#: The dot count when neither ``--points`` nor a radius (``-o dot_radius=``,
#: ``-o min_radius=``) is given. (``pixelpie stipple --pen-mm`` without them
#: sizes the darkest dots one pen wide, which at the default domain of 1024 px
#: is under a pixel on A4 with a 0.3 mm pen: an error.)
DEFAULT_POINTS = 10000
#: The vpype-gcode profile ``pixelpie`` (``vpype -c GCODE_PROFILE ... gwrite
#: --profile pixelpie out.gcode``): a pen change (M0) per layer, Z pen lifts.
GCODE_PROFILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "vpype-gcode.toml")
#: vpype's unit: CSS pixels per millimetre.
PX_PER_MM = 96.0 / 25.4
#: The margin in mm on a sheet when ``--margin`` is not given (the command
#: line's), and the least one ``--device`` fits the drawing with.
DEFAULT_MARGIN_MM = 10.0
#: How far inside a plotter's reach ``--device`` keeps every dot, in mm: two
#: HPGL plotter units, against the rounding of the HPGL coordinates.
REACH_INSET_MM = 0.05
#: ``--device none``: no HPGL plotter, no check of its reach.
NO_DEVICE = "none"
#: The choices of the choice options, as ``pixelpie stipple`` takes them.
CHOICES: Dict[str, List[str]] = {
    "dot_path": ["spiral", "circle", "touch"],
    "dot": ["fixed", "sized", "proportional"],
    "order": ["none", "tsp"],
    "policy": ["prior", "current", "bigger", "smaller"],
    "layer_order": ["light-first", "pens"],
    "style": ["dots", "line"],
}

_LABEL = re.compile(r'inkscape:label="([^"]*)"')
_PATH = re.compile(r"<path\b[^>]*/>\s*")
# A group's opening tag, with the opening tag of the group of its paths in
# hundredths that follows it once the paths are gone, if any: a stand-in
# goes where the paths were, so that vpype sees what they inherit.
_GROUP = re.compile(r'<g\b[^>]*>(?:\s*<g transform="scale\(0\.01\)"[^>]*>)?')
# A pen path's d as `pixelpie stipple --pen-mm` writes it: a moveto, then
# one run of relative linetos; and SVG's numbers.
_PEN_D = re.compile(r"M([-+.0-9 ]+)l([-+.0-9 ]+)")
_NUMBER = re.compile(r"[-+]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)")
# The group that holds a layer's pen paths, in hundredths of a mm.
_HUNDREDTHS = "scale(0.01)"


#: A setting the library names in a message, still marked («pen_mm»,
#: «points=0»): an exception's ``_pixelpie_raw``.
_SETTING = re.compile("\u00ab([^\u00bb=]+)(?:=([^\u00bb]*))?\u00bb")


def _flag(m: "re.Match[str]") -> str:
    flag = "--" + m.group(1).replace("_", "-")
    value = m.group(2)
    return flag if value in (None, "true") else f"{flag} {value}"


def _flags_said(e: BaseException) -> str:
    """The library's message of ``e`` with its settings named as this
    command's options (``--pen-mm -1``, as the command line names them),
    not as Python's keywords; the message as it is when it names none."""
    raw = getattr(e, "_pixelpie_raw", None)
    return _SETTING.sub(_flag, raw) if isinstance(raw, str) else str(e)


def _parse_value(text: str) -> Any:
    """A ``--option`` value: JSON (a number, true/false, a list), else the text."""
    try:
        return json.loads(text)
    except ValueError:
        return text


def _parse_options(pairs: Tuple[str, ...]) -> Dict[str, Any]:
    """``NAME=VALUE`` pairs as keyword arguments of :func:`pixelpie.stipple`
    (dashes in NAME become underscores, as the command line's names do)."""
    out: Dict[str, Any] = {}
    for pair in pairs:
        name, sep, value = pair.partition("=")
        name = name.strip().lstrip("-").replace("-", "_")
        if not sep or not name:
            raise ValueError(f"--option {pair!r} must be NAME=VALUE, e.g. --option gamma=1.2")
        out[name] = _parse_value(value)
    return out


def job_options(
    *,
    points: Optional[int] = None,
    pens: Optional[str] = None,
    ink: Optional[str] = None,
    paper: Optional[str] = None,
    landscape: bool = False,
    margin: Optional[float] = None,
    width_mm: Optional[float] = None,
    pen_mm: Optional[float] = None,
    dot_path: Optional[str] = None,
    dot: Optional[str] = None,
    order: Optional[str] = None,
    relax: Optional[int] = None,
    seed: Optional[int] = None,
    policy: Optional[str] = None,
    layer_order: Optional[str] = None,
    style: Optional[str] = None,
    line_smooth: bool = False,
    extra: Optional[Dict[str, Any]] = None,
) -> Dict[str, Any]:
    """The keyword arguments of :func:`pixelpie.stipple` for the command's
    options, with the plugin's defaults (:data:`DEFAULT_PAPER` unless a paper
    or a width is given, :data:`DEFAULT_PEN_MM`, :data:`DEFAULT_POINTS`
    unless a count or a dot radius is given, or the style is ``line``, whose
    count follows from its pen). The same arguments make
    ``pixelpie stipple`` draw the same dots: ``--paper a4 --pen-mm 0.3
    --points 10000`` and so on."""
    opts: Dict[str, Any] = dict(extra or {})
    given = dict(
        points=points,
        pens=pens,
        ink=ink,
        paper=paper,
        margin=margin,
        width_mm=width_mm,
        pen_mm=pen_mm,
        dot_path=dot_path,
        dot=dot,
        order=order,
        relax=relax,
        seed=seed,
        policy=policy,
        layer_order=layer_order,
        style=style,
    )
    for k, v in given.items():
        if v is not None:
            opts[k] = v
    if landscape:
        opts["landscape"] = True
    if line_smooth:
        opts["line_smooth"] = True
    if opts.get("paper") is None and opts.get("width_mm") is None:
        opts["paper"] = DEFAULT_PAPER
    if opts.get("pen_mm") is None:
        opts["pen_mm"] = DEFAULT_PEN_MM
    line = opts.get("style") == "line"
    if not line and all(opts.get(k) is None for k in ("points", "dot_radius", "min_radius")):
        opts["points"] = DEFAULT_POINTS
    return opts


def _read_svg(svg_text: str, quantization: float) -> Any:
    """``svg_text`` read by :func:`vpype.read_multilayer_svg` (not cropped),
    group k (from 1) as layer k whatever the digits in its label, which vpype
    would otherwise take as its layer number; ``vp_name`` is the label,
    without the ``!`` on which AxiDraw's software pauses (the pen change or
    refill before each layer after the first): the pen's name."""
    import vpype as vp

    names: List[str] = []

    def number(m: "re.Match[str]") -> str:
        names.append(html.unescape(m.group(1)).removeprefix("!"))
        return f'inkscape:label="{len(names)}"'

    numbered = _LABEL.sub(number, svg_text)
    doc = vp.read_multilayer_svg(io.StringIO(numbered), quantization, crop=False)
    for lid, layer in doc.layers.items():
        if 1 <= lid <= len(names):
            layer.set_property(vp.METADATA_FIELD_NAME, names[lid - 1])
            layer.set_property("svg_inkscape_label", names[lid - 1])
    return doc


def _pen_paths(svg_text: str) -> Optional[Tuple[List[List[Any]], Tuple[float, float]]]:
    """The polylines of a pixelpie pen drawing, group by group, in the SVG's
    user units, and the viewBox's size; None unless the file is exactly what
    ``pixelpie stipple --pen-mm`` writes: top-level groups without
    transforms, each holding ``<path d="Mx yldx dy...">`` (a point, then
    relative steps), or groups scaled by 0.01 that hold them (the paths in
    hundredths of a mm: the dots' group, then a line's), a viewBox from 0 0.
    Points are kept as vpype keeps them. A smooth line (curves) is not of
    this shape: vpype reads it."""
    import xml.etree.ElementTree as ET

    import numpy as np

    svg_ns = "{http://www.w3.org/2000/svg}"
    root = ET.fromstring(svg_text)
    box = root.get("viewBox", "").split()
    if root.tag != svg_ns + "svg" or len(box) != 4 or box[:2] != ["0", "0"] or "transform" in root.attrib:
        return None
    groups: List[List[Any]] = []
    for g in root:
        if g.tag != svg_ns + "g" or "transform" in g.attrib:
            return None
        lines = []
        # The paths in hundredths of a mm, in groups scaled to mm (the
        # dots', then a line's).
        inner = list(g)
        scale = 1.0
        if inner and all(c.tag == svg_ns + "g" for c in inner):
            if any(c.get("transform") != _HUNDREDTHS for c in inner):
                return None
            inner, scale = [p for c in inner for p in c], 0.01
        for path in inner:
            d = path.get("d", "")
            m = _PEN_D.fullmatch(d)
            if path.tag != svg_ns + "path" or "transform" in path.attrib or m is None:
                return None
            first, steps = _NUMBER.findall(m.group(1)), _NUMBER.findall(m.group(2))
            if len(first) != 2 or not steps or len(steps) % 2:
                return None
            numbers = first + steps
            # The first point, then relative steps: added up in order, as
            # vpype's reader does.
            xy = np.cumsum(np.array(numbers, dtype=np.float64).reshape(-1, 2), axis=0) * scale
            # vpype leaves out a segment of zero length (a point that
            # repeats the one before, as the SVG's 0.01 mm grid can
            # make on a spiral's first turn); a path of one point is dropped.
            lines.append(xy[np.r_[True, np.any(xy[1:] != xy[:-1], axis=1)]])
        groups.append(lines)
    return groups, (float(box[2]), float(box[3]))


_SVG_TAG = re.compile(r"<svg\b[^>]*>")
_MM_SIZE = re.compile(r'\s(width|height)="\s*([0-9.]+)\s*mm\s*"')


def _sheet_px(svg_text: str) -> Optional[Tuple[float, float]]:
    """The page of an SVG whose root gives its width and height in mm, in
    vpype's unit, as vpype's own paper sizes are (``210mm`` is 210 × 96 /
    25.4 px); None otherwise."""
    tag = _SVG_TAG.search(svg_text)
    if tag is None:
        return None
    size = {k: float(v) for k, v in _MM_SIZE.findall(tag.group(0))}
    if set(size) != {"width", "height"}:
        return None
    return size["width"] * PX_PER_MM, size["height"] * PX_PER_MM


def read_drawing(svg_text: str, quantization: float = 0.1 * PX_PER_MM) -> Any:
    """A pixelpie pen-mode SVG as a :class:`vpype.Document`, as vpype's
    ``read --no-crop`` makes it, but with layer k+1 for pen k (whatever digits
    the pens' names hold): each layer named after its pen (``vp_name``), in
    its colour (``vp_color``) and width (``vp_pen_width``); the page is the
    sheet. Paths are not cropped (a cut dot would become two paths).

    The page is the sheet in vpype's unit exactly (A4 is 210 × 96 / 25.4 by
    297 × 96 / 25.4 px), as vpype's paper sizes are: vpype's SVG reader takes
    an inch as 25.39999 mm, a page 5e-7 larger, which ``write --device NAME``
    does not recognise as a sheet of the plotter ("the plotter page size
    could not be inferred"). The paths are vpype reader's.

    vpype's SVG reader (svgelements) takes about 4 ms a dot, so pixelpie's
    own paths -- polylines in mm -- are read here directly, and vpype reads
    the file without them, for the page and each layer's properties. A file
    of any other shape is read by vpype whole. The tests check that both
    give the same document."""
    import vpype as vp

    found = _pen_paths(svg_text)
    if found is None:
        doc = _read_svg(svg_text, quantization)
        sheet = _sheet_px(svg_text)
        if sheet is not None:
            doc.page_size = sheet
        return doc
    groups, (box_w, box_h) = found
    # The file without its paths, one stand-in path in each group that has
    # some (vpype leaves out empty groups).
    bare = _PATH.sub("", svg_text)
    opened = iter(groups)
    stand_in = '<path d="M 0 0 L 1 0"/>'

    def put(m: "re.Match[str]") -> str:
        tag = m.group(0)
        if tag.startswith(f'<g transform="{_HUNDREDTHS}"'):
            # A layer's second group of paths (a line's): its stand-in went
            # in the layer's first.
            return tag
        return tag + (stand_in if next(opened) else "")

    bare = _GROUP.sub(put, bare)
    doc = _read_svg(bare, quantization)
    sx, sy = doc.page_size[0] / box_w, doc.page_size[1] / box_h
    for lid in list(doc.layers):
        layer = vp.LineCollection(metadata=doc.layers[lid].metadata)
        for xy in groups[lid - 1]:
            layer.append(xy[:, 0] * sx + 1j * (xy[:, 1] * sy))
        doc.replace(layer, lid, with_metadata=True)
    sheet = _sheet_px(svg_text)
    if sheet is not None:
        doc.page_size = sheet
    return doc


def stipple_document(image: str, **options: Any) -> Any:
    """Stipples ``image`` with :func:`pixelpie.stipple` (keyword arguments as
    :func:`job_options` returns them) and returns the drawing as a
    :class:`vpype.Document` (:func:`read_drawing`)."""
    from . import stipple

    with tempfile.TemporaryDirectory(prefix="pixelpie-vpype-") as tmp:
        svg = os.path.join(tmp, "drawing.svg")
        stipple(image, svg, **options)
        with open(svg, encoding="utf-8") as f:
            text = f.read()
    return read_drawing(text)


# --- what a plotter reaches ----------------------------------------------------


class Reach(NamedTuple):
    """What an HPGL plotter of vpype's configuration reaches of a page."""

    #: The plotter's name in vpype's configuration (``write --device``).
    device: str
    #: The name of the plotter's paper that the page is (``a4``).
    paper: str
    #: Left, top, right and bottom of the part of the page that vpype's
    #: ``write --device`` keeps, in vpype's unit (CSS px) from the page's
    #: top-left corner; None where the paper sets no limit.
    box: Optional[Tuple[float, float, float, float]]


def _plotter_config(device: str) -> Any:
    """vpype's configuration of plotter ``device``; ValueError naming the
    plotters it knows when it knows none of that name."""
    import vpype as vp

    try:
        config = vp.config_manager.get_plotter_config(device)
    except ValueError as e:  # a broken entry (vpype 1.15's designmate)
        raise ValueError(
            f"--device {device}: vpype's configuration of this plotter cannot be read ({e})"
        ) from None
    if config is None:
        known = ", ".join(vp.config_manager.get_plotter_list())
        raise ValueError(
            f"--device {device}: vpype knows no plotter of that name (it knows {known}; a file "
            f"given to vpype -c, or ~/.vpype.toml, adds more): give one of them, or --device "
            f"{NO_DEVICE} for a plotter that is not driven by HPGL"
        )
    return config


def _same_size(a: Sequence[float], b: Sequence[float]) -> bool:
    """Two sheets alike to 0.01 mm, either way round."""
    tol = 0.01 * PX_PER_MM
    return any(
        abs(a[0] - x) <= tol and abs(a[1] - y) <= tol for x, y in ((b[0], b[1]), (b[1], b[0]))
    )


def plotter_reach(device: str, page_size: Tuple[float, float]) -> Optional[Reach]:
    """What vpype's ``write --device DEVICE`` keeps of a page of
    ``page_size`` (vpype px), the page taken as the plotter's paper of that
    size, turned as vpype turns it when it infers the paper from the page
    (or is given ``--page-size`` with ``--landscape`` exactly for a
    landscape page); ``write --center`` would move the drawing. None when
    the plotter has no paper of this size. ValueError when vpype knows no
    such plotter.

    vpype (1.15's ``vpype.io.write_hpgl``) turns the page onto the paper,
    moves it to the paper's origin, scales it to plotter units and crops
    it to the paper's ``x_range`` and ``y_range``; this is that map, the
    other way round, for the corners of the ranges."""
    plotter = _plotter_config(device)
    paper = next(
        (
            pc
            for pc in plotter.paper_configs
            if pc.paper_size is not None and _same_size(pc.paper_size, page_size)
        ),
        None,
    )
    if paper is None:
        return None
    if paper.x_range is None or paper.y_range is None:
        return Reach(device, paper.name, None)
    # As write_hpgl: the paper's size and orientation, the origin, whether
    # the page is turned onto the paper, then page px -> plotter units.
    size = tuple(paper.paper_size)
    if (paper.paper_orientation == "portrait" and size[0] > size[1]) or (
        paper.paper_orientation == "landscape" and size[0] < size[1]
    ):
        size = size[::-1]
    ox, oy = paper.origin_location
    if paper.origin_location_reference == "botleft":
        oy = size[1] - oy
    landscape = page_size[0] > page_size[1]
    unit = 1 / plotter.plotter_unit_length
    flip = -unit if paper.y_axis_up else unit

    def to_plotter(z: complex) -> complex:
        if landscape != (size[0] > size[1]):
            z = z * complex(math.cos(-math.pi / 2), math.sin(-math.pi / 2)) + complex(0, size[1])
        if paper.rotate_180:
            z = -z + complex(size[0], size[1])
        z -= complex(ox, oy)
        return complex(z.real * unit, z.imag * flip)

    # The map is affine: its matrix from three points, inverted at the
    # ranges' corners.
    o = to_plotter(0)
    ex, ey = to_plotter(1) - o, to_plotter(1j) - o
    det = ex.real * ey.imag - ey.real * ex.imag
    xs, ys = [], []
    for u in paper.x_range:
        for v in paper.y_range:
            du, dv = u - o.real, v - o.imag
            xs.append((du * ey.imag - dv * ey.real) / det)
            ys.append((dv * ex.real - du * ex.imag) / det)
    return Reach(device, paper.name, (min(xs), min(ys), max(xs), max(ys)))


def _dot_bounds(doc: Any) -> Any:
    """Left, top, right, bottom of each path of ``doc`` (N x 4, vpype px):
    each path of a pixelpie drawing is one dot, or a line (a part of it)."""
    import numpy as np

    lines = [line for lid in sorted(doc.layers) for line in doc.layers[lid]]
    if not lines:
        return np.zeros((0, 4))
    pts = np.concatenate(lines)
    starts = np.cumsum([0] + [len(line) for line in lines[:-1]])
    return np.stack(
        [
            np.minimum.reduceat(pts.real, starts),
            np.minimum.reduceat(pts.imag, starts),
            np.maximum.reduceat(pts.real, starts),
            np.maximum.reduceat(pts.imag, starts),
        ],
        axis=1,
    )


def dots_outside(doc: Any, box: Optional[Tuple[float, float, float, float]]) -> int:
    """How many paths of ``doc`` (a pixelpie drawing: a path per dot, or per
    line) reach past ``box`` (a :class:`Reach`'s), where vpype's ``write
    --device`` would cut them."""
    if box is None:
        return 0
    b = _dot_bounds(doc)
    x0, y0, x1, y1 = box
    return int(((b[:, 0] < x0) | (b[:, 1] < y0) | (b[:, 2] > x1) | (b[:, 3] > y1)).sum())


def _margin_to_fit(
    doc: Any, box: Tuple[float, float, float, float], domain: Tuple[int, int], margin: float
) -> Optional[float]:
    """The least margin in mm (rounded up to 0.1 mm, at least ``margin``)
    that keeps every dot of ``doc`` -- drawn on its sheet with ``margin`` --
    :data:`REACH_INSET_MM` inside ``box``; None if none does.

    pixelpie draws the same dots (in domain px) whatever the margin, the
    drawing scaled about the sheet's centre to fit inside the margins
    (``min((W - 2m) / dw, (H - 2m) / dh)`` mm per px). How far the dots
    reach past the drawing's edges here is kept, in mm, at the new scale:
    more than they will, as a smaller dot is drawn smaller."""
    import numpy as np

    W, H = (v / PX_PER_MM for v in doc.page_size)
    dw, dh = domain
    s = min((W - 2 * margin) / dw, (H - 2 * margin) / dh)
    b = _dot_bounds(doc) / PX_PER_MM
    cx, cy = W / 2, H / 2
    # How far the dots reach past each edge of the drawing (0 if not).
    over = np.maximum(
        0.0,
        [
            (cx - s * dw / 2) - b[:, 0].min(),
            (cy - s * dh / 2) - b[:, 1].min(),
            b[:, 2].max() - (cx + s * dw / 2),
            b[:, 3].max() - (cy + s * dh / 2),
        ],
    )
    x0, y0, x1, y1 = (v / PX_PER_MM for v in box)
    inset = REACH_INSET_MM
    most = min(
        2 * (cx - x0 - inset - over[0]) / dw,
        2 * (cy - y0 - inset - over[1]) / dh,
        2 * (x1 - inset - over[2] - cx) / dw,
        2 * (y1 - inset - over[3] - cy) / dh,
    )
    if most <= 0:
        return None
    need = min((W - most * dw) / 2, (H - most * dh) / 2)
    need = math.ceil(round(need * 10, 6)) / 10
    if 2 * need >= min(W, H):
        return None
    return max(need, margin)


def _options_first(args: List[str], takes_value: Dict[str, bool]) -> List[str]:
    """``IMAGE --opt v ... REST`` as ``--opt v ... IMAGE REST``.

    vpype parses each command of its pipeline with options first, then
    arguments, and hands what follows to the next command. So that
    ``vpype pixelpie photo.jpg --points 20000 write out.svg`` works as the
    command line's order reads, the options that follow the image, up to the
    first word that is not one of ours, are moved before it. ``takes_value``
    maps each option name to whether it takes a value."""
    if not args or args[0].startswith("-"):
        return args
    i = 1
    while i < len(args):
        word = args[i]
        name = word.split("=", 1)[0] if word.startswith("--") else word
        if name not in takes_value:
            break
        i += 2 if takes_value[name] and "=" not in word else 1
    i = min(i, len(args))
    return args[1:i] + args[:1] + args[i:]


def _domain(image: str, options: Dict[str, Any]) -> Tuple[int, int]:
    """The domain's size in px of the drawing of ``image`` with ``options``
    (:func:`pixelpie.plan`'s)."""
    from . import plan

    w, h = plan(image, **options)["domain"]
    return int(w), int(h)


def _check_reach(
    drawing: Any,
    device: Optional[str],
    *,
    margin: Optional[float],
    margin_given: bool,
    domain: Callable[[], Tuple[int, int]],
    redraw: Callable[[float], Any],
    noun: str = "dots",
) -> Any:
    """The drawing, checked against what HPGL plotters reach (see the
    module's doc). ``margin`` is the drawing's margin on its sheet (None
    without a sheet), ``domain()`` its size in px, ``redraw(m)`` the same
    drawing with margin ``m``.

    With ``device`` (or vpype's ``default_hpgl_device``), a drawing that
    would be cut is drawn again with the margin that keeps it whole, or,
    when ``margin_given`` or there is no sheet, refused with a ValueError
    naming that margin. Without one, a warning names each plotter of vpype's
    configuration that would cut dots, with that margin. ``noun`` names the
    drawing's paths in the messages ("dots", or a line's "line paths")."""
    import vpype as vp

    configured = device is None
    if configured:
        device = vp.config_manager.get_command_config("write").get("default_hpgl_device")
    if device == NO_DEVICE:
        return drawing
    size: List[Tuple[int, int]] = []

    def fitting(doc: Any, reach: Reach, at: Optional[float]) -> Optional[float]:
        """The margin that keeps every dot of ``doc`` (drawn with margin
        ``at``) within ``reach``, if there is a sheet."""
        if at is None or reach.box is None:
            return None
        if not size:
            size.append(domain())
        return _margin_to_fit(doc, reach.box, size[0], at)

    def dots(doc: Any) -> int:
        return sum(len(layer) for layer in doc.layers.values())

    w_mm, h_mm = (v / PX_PER_MM for v in drawing.page_size)
    sheet = f"{w_mm:g} x {h_mm:g} mm"
    if device is None:
        cut: List[str] = []
        for name in vp.config_manager.get_plotter_list():
            try:
                found = plotter_reach(name, drawing.page_size)
            except ValueError:
                continue  # a plotter whose configuration vpype cannot read
            out = dots_outside(drawing, found.box) if found is not None else 0
            if found is not None and out:
                need = fitting(drawing, found, margin)
                keep = f" (--margin {need:g} keeps them whole)" if need is not None else ""
                cut.append(f"{name} {'cuts ' if not cut else ''}{out}{keep}")
        if cut:
            logging.warning(
                f"pixelpie: vpype's `write --device NAME` would cut the {noun} past the plotter's reach "
                f"in pieces. Of the {dots(drawing)} {noun} on this {sheet} sheet, {', '.join(cut)}. Give "
                f"--device NAME to fit the drawing to your plotter (or --device {NO_DEVICE} if no HPGL "
                "plotter draws it)."
            )
        return drawing

    reach = plotter_reach(device, drawing.page_size)
    if reach is None and configured:
        # vpype's write cannot plot this sheet on its default plotter (it
        # would ask for --page-size): nothing to check.
        logging.info(f"pixelpie: vpype's default_hpgl_device {device} has no paper of this {sheet} sheet")
        return drawing
    if reach is None:
        raise ValueError(
            f"--device {device}: vpype's {device} has no paper of this {sheet} sheet (its papers: "
            f"{_paper_names(device)}): give --paper with one of them, or --device {NO_DEVICE} for a "
            "plotter that is not driven by HPGL"
        )
    where = _reach_words(reach)
    for _ in range(3):
        out = dots_outside(drawing, reach.box)
        if not out:
            return drawing
        need = fitting(drawing, reach, margin)
        if margin_given or need is None:
            hint = (
                f"give --margin {need:g} or more, or leave --margin out to have pixelpie fit it"
                if need is not None
                else "give --paper and a wider --margin"
            )
            raise ValueError(
                f"{out} of {dots(drawing)} {noun} lie past what {device} reaches of {where}, and "
                f"vpype's `write --device {device}` would cut them in pieces: {hint}"
            )
        every = "every dot" if noun == "dots" else f"all the {noun}"
        logging.info(f"pixelpie: --margin {need:g} keeps {every} within {device}'s reach of {where}")
        drawing, margin = redraw(need), need
    if dots_outside(drawing, reach.box):
        raise ValueError(
            f"could not fit the drawing within {device}'s reach of {where}: give a wider --margin"
        )
    return drawing


def _paper_names(device: str) -> str:
    """The papers of ``device`` in vpype's configuration, in words."""
    names = []
    for pc in _plotter_config(device).paper_configs:
        aka = [a for a in pc.aka_names if a.lower() != pc.name.lower()]
        names.append(pc.name + (f" ({', '.join(aka)})" if aka else ""))
    return ", ".join(names)


def _reach_words(reach: Reach) -> str:
    """``reach`` in words: its paper and box in mm."""
    if reach.box is None:
        return f"its {reach.paper} paper"
    x0, y0, x1, y1 = (v / PX_PER_MM for v in reach.box)
    return (
        f"its {reach.paper} paper (x {x0:.1f} to {x1:.1f} mm and y {y0:.1f} to {y1:.1f} mm "
        "from the sheet's top-left corner)"
    )


def _make_command() -> Any:
    import click
    import vpype as vp
    import vpype_cli

    def choice(name: str) -> Dict[str, Any]:
        """A choice option's type and its values in ``--help``."""
        return dict(type=vpype_cli.ChoiceType(CHOICES[name]), metavar="[" + "|".join(CHOICES[name]) + "]")

    class ImageFirst(click.Command):
        """A command that takes its options before or after its image."""

        def parse_args(self, ctx: click.Context, args: List[str]) -> List[str]:
            takes_value: Dict[str, bool] = {}
            for p in self.get_params(ctx):
                if isinstance(p, click.Option):
                    for name in [*p.opts, *p.secondary_opts]:
                        takes_value[name] = not p.is_flag and not p.count
            return super().parse_args(ctx, _options_first(list(args), takes_value))

    @click.command(name="pixelpie", cls=ImageFirst)
    @click.argument("image", type=vpype_cli.PathType(exists=True, dir_okay=False))
    @click.option(
        "-n",
        "--points",
        type=vpype_cli.IntegerType(),
        help=(
            f"About this many dots (all pens together) [default: {DEFAULT_POINTS}]; with --style "
            "line, the line's points [default: what the pen needs for the photo's tones]."
        ),
    )
    @click.option(
        "--pens",
        type=vpype_cli.TextType(),
        help=(
            "Draw in colour with several pens sampled together: cmyk, a list of #rrggbb "
            'colours ("#000000,#d62728") or a .toml pen file. One layer per pen. '
            "[default: one pen in --ink]"
        ),
    )
    @click.option("--ink", type=vpype_cli.TextType(), help="The one pen's colour, #rrggbb [default: black].")
    @click.option(
        "--paper",
        type=vpype_cli.TextType(),
        help=(
            "The sheet: a1 to a6, letter, legal, tabloid or WxHmm; the drawing fits inside "
            f"the margins, centred. [default: {DEFAULT_PAPER} unless --width-mm is given]"
        ),
    )
    @click.option("--landscape", is_flag=True, help="Turn the sheet to landscape.")
    @click.option(
        "--margin",
        type=vpype_cli.FloatType(),
        help=(
            "Margin around the drawing on the sheet, in mm [default: 10, or with --device what "
            "keeps every dot within the plotter's reach]."
        ),
    )
    @click.option(
        "--width-mm",
        type=vpype_cli.FloatType(),
        help="Instead of a sheet: the page's width in mm, the height from the photo's aspect.",
    )
    @click.option(
        "--pen-mm",
        type=vpype_cli.FloatType(),
        help=f"Pen width in mm (a pen file's width_mm wins for its pen) [default: {DEFAULT_PEN_MM}].",
    )
    @click.option(
        "--dot-path",
        **choice("dot_path"),
        help="How a dot wider than the pen is drawn [default: spiral].",
    )
    @click.option(
        "--dot",
        **choice("dot"),
        help="Dot sizes [default: fixed, with a pen].",
    )
    @click.option(
        "--order",
        **choice("order"),
        help="Drawing order: along a Hilbert curve, or a short plotter path [default: none].",
    )
    @click.option(
        "--relax",
        type=vpype_cli.IntegerType(),
        help="Weighted Lloyd steps [default: 2 for corrected dots up to 200 000, else 0].",
    )
    @click.option("-s", "--seed", type=vpype_cli.IntegerType(), help="Sampler seed [default: 0].")
    @click.option(
        "--policy",
        **choice("policy"),
        help="Disk policy for varying radii [default: smaller].",
    )
    @click.option(
        "--layer-order",
        **choice("layer_order"),
        help="Layers from the lightest ink to the darkest, or in the pens' order [default: light-first].",
    )
    @click.option(
        "--style",
        **choice("style"),
        help=(
            "What the pen draws: dots, or one continuous line per pen through the points "
            "(TSP art), whose ink reproduces the tones; one path per layer. A line's count "
            "follows from the pen and the page unless --points is given. [default: dots]"
        ),
    )
    @click.option(
        "--line-smooth",
        is_flag=True,
        help="With --style line: the line as smooth curves through its points.",
    )
    @click.option(
        "-d",
        "--device",
        type=vpype_cli.TextType(),
        help=(
            "The HPGL plotter that will draw the page, by its name in vpype's configuration "
            "(as `write --device`, e.g. hp7475a): the drawing keeps within what it reaches of the "
            f"sheet. '{NO_DEVICE}': no HPGL plotter. [default: vpype's default_hpgl_device; "
            "without one, a warning names the plotters that would cut dots]"
        ),
    )
    @click.option(
        "-o",
        "--option",
        "extra",
        multiple=True,
        type=vpype_cli.TextType(),
        metavar="NAME=VALUE",
        help=(
            "Any other option of `pixelpie stipple` (repeatable), e.g. -o gamma=1.2 "
            "-o invert=true; values are read as JSON, else as text."
        ),
    )
    @click.option(
        "-l",
        "--layer",
        type=vpype_cli.LayerType(accept_new=True),
        help="Layer of the first pen, the next pens on the next layers, or 'new' [default: 1].",
    )
    @vpype_cli.global_processor
    def pixelpie(
        document: vp.Document,
        image: str,
        points: Optional[int],
        pens: Optional[str],
        ink: Optional[str],
        paper: Optional[str],
        landscape: bool,
        margin: Optional[float],
        width_mm: Optional[float],
        pen_mm: Optional[float],
        dot_path: Optional[str],
        dot: Optional[str],
        order: Optional[str],
        relax: Optional[int],
        seed: Optional[int],
        policy: Optional[str],
        layer_order: Optional[str],
        style: Optional[str],
        line_smooth: bool,
        device: Optional[str],
        extra: Tuple[str, ...],
        layer: Optional[int],
    ) -> vp.Document:
        """Stipple a photo with PixelPie (maximal Poisson-disk sampling), one layer per pen.

        The dots are those of `pixelpie stipple IMAGE -o OUT.svg` with the same options
        (and --paper a4 unless --paper or --width-mm is given, --pen-mm 0.3 and
        --points 10000 unless given), each drawn as the pen draws it: a touch, or a
        filled spiral for a dot wider than the pen. Each pen gets its own layer, named
        after it, in its colour and width, the lightest ink first (layer 1); the page
        size is the sheet's. With --style line each pen draws one continuous line instead
        (TSP art), one path per layer, as many points as the pen needs for the photo's
        tones unless --points is given. The options may come before or after IMAGE;
        --option passes any other of `pixelpie stipple`.

        vpype's `write --device NAME` (HPGL) cuts a dot past the plotter's reach in
        pieces: with --device NAME the drawing keeps within that plotter's reach (a
        wider margin, unless --margin is given); without it, a warning names the
        plotters of vpype's configuration that would cut dots on this sheet.

        Examples:

            vpype pixelpie photo.jpg --points 20000 linesort write out.svg

            vpype pixelpie photo.jpg --pens cmyk --paper a3 --landscape --order tsp write out.svg

            vpype pixelpie photo.jpg --style line --paper a5 --pen-mm 0.5 write out.svg

            vpype pixelpie photo.jpg --device hp7475a write --device hp7475a out.hpgl
        """
        try:
            extra_opts = _parse_options(extra)
            opts = job_options(
                points=points,
                pens=pens,
                ink=ink,
                paper=paper,
                landscape=landscape,
                margin=margin,
                width_mm=width_mm,
                pen_mm=pen_mm,
                dot_path=dot_path,
                dot=dot,
                order=order,
                relax=relax,
                seed=seed,
                policy=policy,
                layer_order=layer_order,
                style=style,
                line_smooth=line_smooth,
                extra=extra_opts,
            )
            if device not in (None, NO_DEVICE):
                _plotter_config(device)  # an unknown plotter is refused before the drawing
            drawing = stipple_document(image, **opts)
            given_margin = opts.get("margin")
            drawing = _check_reach(
                drawing,
                device,
                margin=(
                    None
                    if opts.get("paper") is None
                    else DEFAULT_MARGIN_MM if given_margin is None else float(given_margin)
                ),
                margin_given=given_margin is not None,
                domain=lambda: _domain(image, opts),
                redraw=lambda m: stipple_document(image, **{**opts, "margin": m}),
                noun="line paths" if opts.get("style") == "line" else "dots",
            )
        except (ValueError, TypeError) as e:
            raise click.UsageError(f"pixelpie: {_flags_said(e)}") from None
        except OSError as e:
            raise click.BadParameter(f"pixelpie: {_flags_said(e)}", param_hint="IMAGE") from None

        first = 1
        if layer is not None:
            first = layer if layer > 0 else max(document.layers, default=0) + 1
        for lid in sorted(drawing.layers):
            document.add(drawing.layers[lid], first + lid - 1, with_metadata=True)
        document.extend_page_size(drawing.page_size)
        document.add_to_sources(image)
        return document

    pixelpie.help_group = "Generators"
    return pixelpie


try:
    pixelpie = _make_command()
except ImportError as _missing:  # the plain package: vpype is an optional extra
    _why = _missing

    def pixelpie(*args: Any, **kwargs: Any) -> Any:  # type: ignore[no-redef]
        """Stand-in for the vpype command when vpype is not installed."""
        raise ImportError(
            f"the pixelpie vpype plugin needs vpype ({_why}): "
            'pip install "pixelpie[vpype]"'
        ) from _why
