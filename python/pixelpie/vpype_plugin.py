"""The ``pixelpie`` command of vpype, the pen-plotter toolkit.

Installed with the package's ``vpype`` extra (``pip install "pixelpie[vpype]"``,
or ``pip install "./python[vpype]"`` from a checkout), vpype finds it through
the ``vpype.plugins`` entry point::

    vpype pixelpie photo.jpg --points 20000 --pens cmyk linesort write out.svg

It stipples the photo as ``pixelpie stipple`` does, with the same options,
and adds the pen paths to vpype's document: one layer per pen (layer 1 for
the first pen, 2 for the second, ...), each named after its pen and carrying
its colour and pen width, and the sheet as the page size. The dots are the
command line's for the same options: the command writes the drawing with
:func:`pixelpie.stipple` to a temporary SVG in pen mode (``--pen-mm``) and
reads it with :func:`vpype.read_multilayer_svg`.

Defaults where the command line has none: an A4 sheet (``--paper a4``, 10 mm
margins, portrait) unless ``--paper`` or ``--width-mm`` is given, a pen
0.3 mm wide unless ``--pen-mm`` is given (a pen file's ``width_mm`` still
sets its own pen's width), and 10 000 dots unless ``--points`` (or a dot
radius, ``-o dot_radius=R`` or ``-o min_radius=R``) is given. Options may
come before or after the image.

This module imports without vpype; then :data:`pixelpie` is a stand-in that
raises ``ImportError`` saying how to install the extra.
"""

from __future__ import annotations

import html
import io
import json
import os
import re
import tempfile
from typing import Any, Dict, List, Optional, Tuple

__all__ = ["pixelpie", "DEFAULT_PAPER", "DEFAULT_PEN_MM", "DEFAULT_POINTS", "GCODE_PROFILE"]

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

_LABEL = re.compile(r'inkscape:label="([^"]*)"')
_PATH = re.compile(r"<path\b[^>]*/>\s*")
_GROUP = re.compile(r"<g\b[^>]*>")


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
    extra: Optional[Dict[str, Any]] = None,
) -> Dict[str, Any]:
    """The keyword arguments of :func:`pixelpie.stipple` for the command's
    options, with the plugin's defaults (:data:`DEFAULT_PAPER` unless a paper
    or a width is given, :data:`DEFAULT_PEN_MM`, :data:`DEFAULT_POINTS`
    unless a count or a dot radius is given). The same arguments make
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
    )
    for k, v in given.items():
        if v is not None:
            opts[k] = v
    if landscape:
        opts["landscape"] = True
    if opts.get("paper") is None and opts.get("width_mm") is None:
        opts["paper"] = DEFAULT_PAPER
    if opts.get("pen_mm") is None:
        opts["pen_mm"] = DEFAULT_PEN_MM
    if all(opts.get(k) is None for k in ("points", "dot_radius", "min_radius")):
        opts["points"] = DEFAULT_POINTS
    return opts


def _read_svg(svg_text: str, quantization: float) -> Any:
    """``svg_text`` read by :func:`vpype.read_multilayer_svg` (not cropped),
    group k (from 1) as layer k whatever the digits in its label, which vpype
    would otherwise take as its layer number; ``vp_name`` is the label."""
    import vpype as vp

    names: List[str] = []

    def number(m: "re.Match[str]") -> str:
        names.append(html.unescape(m.group(1)))
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
    ``pixelpie stipple --pen-mm`` writes: top-level groups of ``<path
    d="M x y L x y ...">`` with no transforms, a viewBox from 0 0. Points
    are kept as vpype keeps them."""
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
        for path in g:
            t = path.get("d", "").split()
            if (
                path.tag != svg_ns + "path"
                or "transform" in path.attrib
                or len(t) < 6
                or t[0] != "M"
                or t[3] != "L"
                or len(t) % 2
            ):
                return None
            try:
                xy = np.array(t[1:3] + t[4:], dtype=np.float64).reshape(-1, 2)
            except ValueError:
                return None
            # vpype leaves out a segment of zero length (a point that
            # repeats the one before, as the SVG's 0.001 mm rounding can
            # make on a spiral's first turn); a path of one point is dropped.
            lines.append(xy[np.r_[True, np.any(xy[1:] != xy[:-1], axis=1)]])
        groups.append(lines)
    return groups, (float(box[2]), float(box[3]))


def read_drawing(svg_text: str, quantization: float = 0.1 * PX_PER_MM) -> Any:
    """A pixelpie pen-mode SVG as a :class:`vpype.Document`, as vpype's
    ``read --no-crop`` makes it, but with layer k+1 for pen k (whatever digits
    the pens' names hold): each layer named after its pen (``vp_name``), in
    its colour (``vp_color``) and width (``vp_pen_width``); the page is the
    sheet. Paths are not cropped (a cut dot would become two paths).

    vpype's SVG reader (svgelements) takes about 4 ms a dot, so pixelpie's
    own paths -- polylines in mm -- are read here directly, and vpype reads
    the file without them, for the page and each layer's properties. A file
    of any other shape is read by vpype whole. The tests check that both
    give the same document."""
    import vpype as vp

    found = _pen_paths(svg_text)
    if found is None:
        return _read_svg(svg_text, quantization)
    groups, (box_w, box_h) = found
    # The file without its paths, one stand-in path in each group that has
    # some (vpype leaves out empty groups).
    bare = _PATH.sub("", svg_text)
    opened = iter(groups)
    stand_in = '<path d="M 0 0 L 1 0"/>'
    bare = _GROUP.sub(lambda m: m.group(0) + (stand_in if next(opened) else ""), bare)
    doc = _read_svg(bare, quantization)
    sx, sy = doc.page_size[0] / box_w, doc.page_size[1] / box_h
    for lid in list(doc.layers):
        layer = vp.LineCollection(metadata=doc.layers[lid].metadata)
        for xy in groups[lid - 1]:
            layer.append(xy[:, 0] * sx + 1j * (xy[:, 1] * sy))
        doc.replace(layer, lid, with_metadata=True)
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


def _make_command() -> Any:
    import click
    import vpype as vp
    import vpype_cli

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
        help=f"About this many dots (all pens together) [default: {DEFAULT_POINTS}].",
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
        help="Margin around the drawing on the sheet, in mm [default: 10].",
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
        type=vpype_cli.ChoiceType(["spiral", "circle", "touch"]),
        help="How a dot wider than the pen is drawn [default: spiral].",
    )
    @click.option(
        "--dot",
        type=vpype_cli.ChoiceType(["fixed", "sized", "proportional"]),
        help="Dot sizes [default: fixed, with a pen].",
    )
    @click.option(
        "--order",
        type=vpype_cli.ChoiceType(["none", "tsp"]),
        help="Drawing order: as sampled, or a short plotter path [default: none].",
    )
    @click.option("--relax", type=vpype_cli.IntegerType(), help="Weighted Lloyd steps [default: 0].")
    @click.option("-s", "--seed", type=vpype_cli.IntegerType(), help="Sampler seed [default: 0].")
    @click.option(
        "--policy",
        type=vpype_cli.ChoiceType(["prior", "current", "bigger", "smaller"]),
        help="Disk policy for varying radii [default: smaller].",
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
        extra: Tuple[str, ...],
        layer: Optional[int],
    ) -> vp.Document:
        """Stipple a photo with PixelPie (maximal Poisson-disk sampling), one layer per pen.

        The dots are those of `pixelpie stipple IMAGE -o OUT.svg` with the same options
        (and --paper a4 unless --paper or --width-mm is given, --pen-mm 0.3 and
        --points 10000 unless given), each drawn as the pen draws it: a touch, or a
        filled spiral for a dot wider than the pen. Each pen gets its own layer, named
        after it, in its colour and width; the page size is the sheet's. The options
        may come before or after IMAGE; --option passes any other of `pixelpie stipple`.

        Examples:

            vpype pixelpie photo.jpg --points 20000 linesort write out.svg

            vpype pixelpie photo.jpg --pens cmyk --paper a3 --landscape --order tsp write out.svg
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
                extra=extra_opts,
            )
            drawing = stipple_document(image, **opts)
        except (ValueError, TypeError) as e:
            raise click.UsageError(f"pixelpie: {e}") from None
        except OSError as e:
            raise click.BadParameter(f"pixelpie: {e}", param_hint="IMAGE") from None

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
