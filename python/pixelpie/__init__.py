"""PixelPie: maximal Poisson-disk sampling by rasterization, and stippling.

The system of Ip, Yalcin, Luebke & Varshney, *PixelPie: Maximal Poisson-disk
Sampling with Rasterization* (HPG 2013), from the Rust library's CPU
backend: the same points as the ``pixelpie`` command line, bit for bit.

* :func:`sample` -- a maximal Poisson-disk set as an (N, 3) float32 array
  of x, y and radius, uniform, from a radius map or from an image;
* :func:`stipple` -- a picture as a stipple drawing (SVG or PNG), or with
  ``style="line"`` as one continuous pen line: a :class:`Drawing`, with its
  dots (or line), plan, files and pen paths;
* :func:`plan` -- what :func:`stipple` would do, without drawing;
* :func:`analyze` -- the measures of ``pixelpie analyze`` for any point set.

The library works without the GIL, on threads of the calling process's own
(a child made by ``fork`` makes its own), and Ctrl-C raises
``KeyboardInterrupt`` within a few milliseconds in any stage, leaving no
output file. Bad values raise ``ValueError``, bad types ``TypeError``, files
that cannot be read or written ``OSError`` with its ``errno`` and
``filename`` (``FileNotFoundError``, ``PermissionError``, ...); what the
command line warns of is warned as :class:`PixelpieWarning`.
"""

from __future__ import annotations

import json
import math
import operator
import os
import warnings
from typing import Any, Callable, Dict, Iterator, List, NamedTuple, Optional, Tuple, Union

import numpy as np

from . import _pixelpie

__all__ = [
    "sample",
    "sample_options",
    "stipple",
    "stipple_options",
    "plan",
    "analyze",
    "Drawing",
    "Pen",
    "PenPaths",
    "Stroke",
    "PixelpieWarning",
    "__version__",
]
__version__: str = _pixelpie.__version__

PathLike = Union[str, bytes, "os.PathLike[str]", "os.PathLike[bytes]"]
Progress = Callable[[int, int, int, int], object]


class PixelpieWarning(UserWarning):
    """What the command line prints as ``warning: ...``, with its words: a
    count short of its target, a set left not maximal, a PNG too coarse for
    its dots, a picture cut short, a job file from another version."""


def _warn(messages: List[str]) -> None:
    for m in messages:
        warnings.warn(m, PixelpieWarning, stacklevel=3)


def _as_path(value: Any) -> Optional[str]:
    """``value`` as a path string when it is one (``str``, ``bytes`` or
    ``os.PathLike``), else ``None``."""
    if isinstance(value, (str, bytes, os.PathLike)):
        return os.fsdecode(value)
    return None


def _readable(path: str) -> str:
    """``path``, opened once: a missing or unreadable file raises Python's
    own ``FileNotFoundError``, ``PermissionError`` or ``IsADirectoryError``,
    with its ``errno`` and ``filename``."""
    with open(path, "rb"):
        pass
    return path


def _max_memory(value: Any) -> Optional[int]:
    """The ``max_memory`` keyword in bytes: a number of bytes or a size
    such as ``"8G"``; ``None`` keeps the default (4 GB, or half the
    machine's memory when less)."""
    if value is None:
        return None
    if isinstance(value, str):
        return int(_pixelpie.parse_size(value))
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(
            f"max_memory must be a number of bytes or a size such as '8G', not {type(value).__name__}"
        )
    if value < 1:
        raise ValueError(f"max_memory {value} must be at least one byte")
    return int(value)


def _path(p: Optional[PathLike]) -> Optional[str]:
    return None if p is None else os.fsdecode(p)


def _grid(values: Any, name: str) -> np.ndarray:
    a = np.ascontiguousarray(values, dtype=np.float32)
    if a.ndim != 2:
        raise ValueError(f"{name} must be a 2-D (height, width) array, not {a.ndim}-D")
    return a


def _count(value: Any, name: str) -> int:
    """A positional size: ``TypeError`` for another type (a float or a
    string), ``ValueError`` for a negative one."""
    if isinstance(value, bool):
        raise TypeError(f"{name} must be an integer, not bool")
    try:
        n = operator.index(value)
    except TypeError:
        raise TypeError(f"{name} must be an integer, not {type(value).__name__}") from None
    if n < 0:
        raise ValueError(f"{name} {n} must not be negative")
    return n


def sample_options() -> Dict[str, Any]:
    """The options :func:`sample` takes, with their defaults (``None``:
    chosen by the job). They come from the library's point-set job, so they
    are ``pixelpie sample``'s, with underscores."""
    return json.loads(_pixelpie.sample_defaults())


def sample(
    width: Optional[int] = None,
    height: Optional[int] = None,
    *,
    radius_map: Any = None,
    importance: Any = None,
    backend: str = "auto",
    progress: Optional[Progress] = None,
    max_memory: Union[int, str, None] = None,
    **options: Any,
) -> Tuple[np.ndarray, Dict[str, Any]]:
    """Samples a maximal Poisson-disk set on a ``width`` x ``height`` domain,
    as ``pixelpie sample`` does: the same options, the same defaults, the
    same exclusions, the same points.

    Give one of:

    * ``radius`` -- the disk radius in pixels, or ``points`` -- about that
      many points (within 3%), the radius found for it;
    * ``radius_map`` -- a (height, width) array of radii in pixels (at
      least 1), or the path of a single-channel EXR; ``points`` scales it;
    * ``importance`` -- a picture as :func:`stipple` takes it (a path, an
      (H, W, C) array or a PIL image, decoded as a file is), or a (H, W)
      grey array whose values are taken as they are (uint8 over 255,
      uint16 over 65535, float in [0, 1]; 0 = black; linear unless
      ``tones`` says otherwise), resized to the domain (its aspect kept):
      dark pixels get small disks. ``min_radius`` is then the black pixels' radius (white
      gets 8 times it, or ``max_radius``), ``points`` a count target; give
      at least one. ``radius`` is refused here, as on the command line.

    The other options (:func:`sample_options` lists them with their
    defaults): ``policy`` (``"smaller"``, the default, ``"prior"``,
    ``"current"`` or ``"bigger"``: how disks of different radii keep apart,
    paper 3.4), ``seed``, ``subpixel_bits`` (0 to 7), ``periodic``
    (tileable sets), ``exact`` (no sub-pixel slack, maximal in the
    continuous domain), ``batch``, ``max_iterations`` (a capped set is not
    maximal: ``stats["maximal"]`` says so), and the importance map's
    ``tones``, ``mapping``, ``min_radius``, ``max_radius``, ``gamma``,
    ``black_level``, ``white_level``, ``invert``, ``white_cutoff`` and
    ``hdr_white``. ``backend`` is ``"auto"``, ``"cpu"`` or ``"gpu"`` (this
    package is built without the GPU backend: ``"gpu"`` raises
    ``RuntimeError``). ``progress(iteration, points, empty, pixels)`` is
    called after every iteration; an exception it raises stops the run.

    Returns ``(points, stats)``: an (N, 3) float32 array of x, y and radius
    in acceptance order, and the run's statistics (``points``,
    ``iterations``, ``maximal`` -- no pixel left empty --, ``exact``,
    ``seconds``, per-stage seconds, ...), as ``pixelpie sample --stats``
    writes them, with ``target``, the count asked for (``None`` without
    one). A count short of its target, or a set left not maximal, warns
    (:class:`PixelpieWarning`). A bad value raises ``ValueError``, a wrong
    type ``TypeError``, a missing file ``FileNotFoundError``.
    """
    # The options' types are the job's own: its serde form refuses a float,
    # a string or a negative number for a count (ValueError naming it).
    given = {k: v for k, v in options.items() if v is not None}
    if width is not None:
        given["width"] = _count(width, "width")
    if height is not None:
        given["height"] = _count(height, "height")
    rmap = values = pixels = None
    if radius_map is not None:
        path = _as_path(radius_map)
        if path is not None:
            given["radius_map"] = _readable(path)
        else:
            rmap = _grid(radius_map, "radius_map")
    if importance is not None:
        path = _as_path(importance)
        if path is not None:
            given["importance"] = _readable(path)
        elif _is_pil(importance) or np.ndim(importance) == 3:
            pixels = _picture(importance, "importance")
        else:
            values = _grey_values(importance, "importance")
    points, stats, said = _pixelpie.sample(
        json.dumps(_finite(given), default=_option),
        rmap,
        values,
        pixels,
        backend,
        progress,
        _max_memory(max_memory),
    )
    _warn(said)
    return points, stats


#: The range of a whole number an option takes (the library's 64 bits).
_WHOLE = (-(2**63), 2**64 - 1)


def _finite(options: Dict[str, Any]) -> Dict[str, Any]:
    """``options`` with every number checked: NaN and infinities raise
    ``ValueError`` naming the option (JSON has no word for them), and so
    does a whole number beyond 64 bits (JSON would carry it as a float)."""
    for name, v in options.items():
        if isinstance(v, float) and not math.isfinite(v):
            raise ValueError(f"{name}={v} must be a finite number")
        if isinstance(v, (int, np.integer)) and not isinstance(v, bool):
            if v > _WHOLE[1]:
                raise ValueError(f"{name}={v} is too large: at most {_WHOLE[1]}")
            if v < _WHOLE[0]:
                raise ValueError(f"{name}={v} is too small: at least {_WHOLE[0]}")
    return options


def _option(value: Any) -> Any:
    """A keyword argument as JSON: numpy scalars become Python numbers."""
    if hasattr(value, "item"):
        return value.item()
    raise TypeError(f"option value {value!r} is not a number, string or bool")


def stipple_options() -> Dict[str, Any]:
    """The options :func:`stipple` takes, with their defaults (``None``:
    chosen by the job, as the command line's help says). They come from the
    library's drawing job, so they are the command line's, with
    underscores."""
    return json.loads(_pixelpie.stipple_defaults())


def _is_pil(value: Any) -> bool:
    return type(value).__module__.startswith("PIL.") and hasattr(value, "mode")


#: PIL modes taken as they are (8 bits a channel), and those converted first.
_PIL_AS_IS = ("L", "LA", "RGB", "RGBA")
_PIL_CONVERT = {
    "1": "L",
    "La": "LA",
    "RGBa": "RGBA",
    "RGBX": "RGB",
    "CMYK": "RGB",
    "YCbCr": "RGB",
    "HSV": "RGB",
}
_PIL_16 = ("I;16", "I;16L", "I;16B", "I;16N")


def _pil_pixels(image: Any, name: str) -> np.ndarray:
    """A PIL image's pixels as an array the picture rule takes: every
    common mode, each read as its values mean."""
    mode = image.mode
    if mode in ("P", "PA"):
        # The palette's colours, not its indices; its transparency kept.
        has_alpha = mode == "PA" or "transparency" in image.info
        return np.asarray(image.convert("RGBA" if has_alpha else "RGB"))
    if mode in _PIL_AS_IS:
        return np.asarray(image)
    if mode in _PIL_CONVERT:
        return np.asarray(image.convert(_PIL_CONVERT[mode]))
    if mode in _PIL_16:
        return np.asarray(image).astype(np.uint16)
    if mode in ("I", "F"):
        # 32-bit values: scaled by the range they fill, [0, 1] (F only),
        # [0, 255] or [0, 65535].
        a = np.asarray(image)
        if a.size == 0:
            return a.astype(np.uint16)
        lo, hi = float(a.min()), float(a.max())
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise ValueError(f"{name}: the PIL image of mode {mode!r} holds NaN or infinite values")
        if lo < 0 or hi > 65535:
            raise ValueError(
                f"{name}: the PIL image of mode {mode!r} holds values from {lo:g} to {hi:g}; "
                "a picture's values lie in [0, 1], [0, 255] or [0, 65535]"
            )
        if mode == "F" and hi <= 1.0:
            return a.astype(np.float32)
        if hi <= 255:
            return np.round(a.astype(np.float64) * 257.0).astype(np.uint16)
        return np.round(a.astype(np.float64)).astype(np.uint16)
    raise ValueError(
        f"{name}: PIL images of mode {mode!r} are not supported; convert it first "
        "(image.convert('RGB') or image.convert('L'))"
    )


def _picture(image: Any, name: str = "image") -> Optional[np.ndarray]:
    """A picture given as an array or a PIL image, as sRGB-encoded 16-bit
    values of shape (H, W) or (H, W, channels); ``None`` for a path. The
    one input rule of every picture argument: uint8 (0 to 255), uint16 (0
    to 65535), float (0 to 1) or bool arrays, and PIL images of every
    common mode; anything else is refused by name."""
    if _as_path(image) is not None:
        return None
    if _is_pil(image):
        a = _pil_pixels(image, name)
    elif isinstance(image, np.ndarray):
        a = image
    elif isinstance(image, (list, tuple)):
        a = np.asarray(image)
        if a.dtype.kind in "iu" and a.size and 0 <= a.min() and a.max() <= 255:
            a = a.astype(np.uint8)
    else:
        raise TypeError(
            f"{name} must be a path, a numpy array or a PIL image, not {type(image).__name__}"
        )
    if a.dtype == np.uint8:
        a = a.astype(np.uint16) * 257
    elif a.dtype == np.uint16:
        a = a.astype(np.uint16, copy=False)
    elif a.dtype == bool:
        a = a.astype(np.uint16) * 65535
    elif a.dtype.kind == "f":
        a = _unit(a, name)
        a = np.round(a.astype(np.float64) * 65535.0).astype(np.uint16)
    else:
        raise TypeError(
            f"{name}: a picture array must be uint8 (0 to 255), uint16 (0 to 65535), "
            f"float (0 to 1) or bool, not {a.dtype}; convert it, e.g. with "
            ".astype(np.uint8)"
        )
    if a.ndim not in (2, 3):
        raise ValueError(f"{name}: a picture array must be (H, W) or (H, W, C), not {a.ndim}-D")
    return np.ascontiguousarray(a)


def _unit(a: np.ndarray, name: str) -> np.ndarray:
    """A float array checked to hold values in [0, 1]: NaN, infinities and
    values outside refused, naming the range found."""
    if a.size == 0:
        return a
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: the array holds NaN or infinite values")
    lo, hi = float(a.min()), float(a.max())
    if lo < 0.0 or hi > 1.0:
        hint = " (divide by 255)" if hi <= 255.0 and lo >= 0.0 else ""
        raise ValueError(
            f"{name}: a float array must hold values in [0, 1]; this one's lie outside "
            f"[0, 1], from {lo:g} to {hi:g}{hint}"
        )
    return a


def _grey_values(values: Any, name: str) -> np.ndarray:
    """A (H, W) grey array's values in [0, 1] as float32, taken as they
    are: uint8 over 255, uint16 over 65535, float checked to lie in [0, 1]."""
    a = np.asarray(values)
    if a.dtype == np.uint8:
        a = a.astype(np.float32) / 255.0
    elif a.dtype == np.uint16:
        a = a.astype(np.float32) / 65535.0
    elif a.dtype == bool:
        a = a.astype(np.float32)
    elif a.dtype.kind == "f":
        a = _unit(a, name)
    else:
        raise TypeError(
            f"{name}: a grey array must be uint8, uint16, float (0 to 1) or bool, not {a.dtype}"
        )
    return _grid(a, name)


def _pens(value: Any) -> Any:
    """The ``pens`` option checked for its type; a pen file is opened once
    (``FileNotFoundError`` when missing)."""
    path = _as_path(value)
    if path is not None:
        if not isinstance(value, str) or value.strip().lower().endswith(".toml"):
            _readable(path)
        return path
    if isinstance(value, (list, tuple)) and all(isinstance(v, (str, dict)) for v in value):
        return list(value)
    raise TypeError(
        "pens must be 'cmyk', 'black', a pen file's path (.toml), or a list of "
        f"'#rrggbb' colours, not {type(value).__name__}"
    )


def stipple(
    image: Any,
    output: Optional[PathLike] = None,
    *,
    backend: str = "auto",
    progress: Optional[Progress] = None,
    svg: bool = False,
    job: Optional[PathLike] = None,
    max_memory: Union[int, str, None] = None,
    **options: Any,
) -> Any:
    """Draws ``image`` as stipples, as ``pixelpie stipple`` does.

    ``image`` is a file's path (``str``, ``bytes`` or ``os.PathLike``), a
    numpy array -- (H, W) grey, (H, W, 2) grey and alpha, (H, W, 3) RGB or
    (H, W, 4) RGBA; uint8, uint16, float in [0, 1] or bool; sRGB-encoded as
    in an image file -- or a PIL image of any common mode (``L``, ``LA``,
    ``RGB``, ``RGBA``, ``P`` through its palette, ``CMYK`` and ``YCbCr``
    converted to RGB, ``1``, ``I;16``, and ``I`` and ``F`` scaled by the
    range their values fill: [0, 1], [0, 255] or [0, 65535]). Anything else
    is refused by name. With ``output`` (``.svg``, ``.png``, ``.csv`` or
    ``.json``) the drawing is written there: the same file as the command
    line writes for the same options (nothing when interrupted).

    Returns a :class:`Drawing`: its ``dots`` (an (N, 3) float32 array of x,
    y and drawn radius in domain pixels, in drawing order; with ``pens`` an
    (N, 4) array whose fourth column is each dot's pen), its ``domain``,
    ``plan``, counts, pens, files and pen paths. It also behaves as its
    ``dots`` array where code indexes it (``d[:, 0]``, ``len(d)``,
    ``np.asarray(d)``). With ``style="line"`` it draws no dots but one
    continuous line per pen, and behaves as the line's points instead
    (:attr:`Drawing.line`). With ``svg=True`` the SVG's text instead.

    ``options`` are the command line's, with underscores, and the same
    defaults (the library's drawing job, ``pixelpie::job::Job``, holds
    them all; :func:`stipple_options` lists them): ``points`` (default
    10 000 unless ``min_radius`` or ``dot_radius`` is given), ``width``,
    ``height``, ``dot`` (``"sized"``: small dots in light areas, the
    default; ``"fixed"``: all alike; ``"proportional"``: a fraction of each
    disk, a texture that does not reproduce tones), ``dot_factor``,
    ``dot_ratio``, ``dot_radius``, ``spacing`` (``"local"``: sized dots
    for the spacing they have; ``"radius"``: for their sample radius, as
    earlier versions), ``correction`` (``"on"``: sized dots corrected
    toward the picture's tones by rendering; ``"off"``: the curves alone,
    as earlier versions), ``relax`` (weighted Lloyd steps, over-relaxed; by
    default 2 for corrected sized dots up to 200 000 dots, else none; in
    colour each pen's dots relax on their own),
    ``order`` (``"tsp"``: a short pen-plotter path), ``style``
    (``"dots"``, the default, or ``"line"``: one continuous pen-down line
    through the points, TSP art whose ink reproduces the tones; its count
    follows from the pen and the page, ``pen_mm`` with ``width_mm`` or
    ``paper``, or without a pen ``points`` sets the line's width), and
    ``line_smooth`` (``True``: the line as smooth curves through its
    points; needs ``style="line"``), ``scale`` (PNG pixels
    per domain pixel), ``width_mm`` and ``pen_mm`` (SVG in millimetres,
    drawn with a pen), ``paper`` (``"a4"``, ``"letter"``, ``"WxHmm"``, ...:
    the SVG is the sheet, instead of ``width_mm``), ``margin`` (mm) and
    ``landscape``, ``size_px`` (the SVG's size in px, for saxi's command
    line), ``dot_path`` (``"spiral"``, ``"circle"`` or ``"touch"``:
    how the pen draws a dot), ``ink`` (``"#rrggbb"``), ``policy`` (default
    ``"smaller"``), ``seed``, ``subpixel_bits``, ``periodic``, ``exact``,
    ``tones`` (``"display"``: reproduce the grey a viewer sees;
    ``"linear"``: linear light), ``mapping``, ``min_radius``,
    ``max_radius``, ``gamma``, ``black_level``, ``white_level``,
    ``invert``, ``white_cutoff`` and ``hdr_white``; ``pens`` draws in colour
    with several pens sampled together: ``"cmyk"``, a list of ``"#rrggbb"``
    colours, or the path of a ``.toml`` pen file; ``choose`` (with an
    inventory of up to 64 pens in ``pens``) draws with the K of them the
    render model predicts closest to the picture's colours (``Drawing.pens``
    says which); ``paper_colour`` (``"black"``, ``"kraft"``, ``"grey"``
    or ``"#rrggbb"``: the inks on that paper); ``crop`` (``"x,y,w,h"``)
    and ``rotate`` (90, 180 or 270) frame the picture; ``refill_mm`` and
    ``layer_order`` shape the pen layers; ``poster`` (``(width, height)``
    in mm, with ``paper`` the sheet) draws the picture whole at the
    poster's size and cuts it into sheets: the drawing is the whole, its
    :attr:`Drawing.sheets` the sheets, :attr:`Drawing.poster` the manifest
    and ``output`` a folder of one SVG a sheet and ``poster.json``. An unknown name or a bad value
    raises ``ValueError`` (``TypeError`` for a wrong type).

    ``job`` is a job file (``pixelpie stipple --save-job``, the app's
    presets): its settings, with ``options`` over them, as ``--job`` takes
    it; a file from another version warns (``UserWarning``).

    ``max_memory`` (bytes, or ``"8G"``) is the memory a picture may take,
    as ``--max-memory``: a picture whose drawing would need more, said
    from its header, raises ``MemoryError`` before it is decoded (default
    4 GB, or half the machine's memory when less).
    """
    given, job_file = _job(options, job)
    pixels = _picture(image)
    native = _pixelpie.stipple(
        None if pixels is not None else _readable(os.fsdecode(image)),
        pixels,
        _path(output),
        given,
        job_file,
        backend,
        progress,
        _max_memory(max_memory),
    )
    # The warnings first, the file after: a warning turned into an error
    # (warnings.filterwarnings("error")) leaves no file.
    _warn(native.warnings())
    native.write_output()
    drawing = Drawing(native)
    if svg:
        return drawing.svg().decode("utf-8")
    return drawing


def _job(options: Dict[str, Any], job: Optional[PathLike]) -> Tuple[str, Optional[str]]:
    """The keyword options as the native functions take them (JSON), and
    the job file's path; a job file from another version warns. The
    library lays the options over the file, as the command line does."""
    given = {
        k: os.fsdecode(v) if isinstance(v, os.PathLike) else v
        for k, v in options.items()
        if v is not None
    }
    if "pens" in given:
        given["pens"] = _pens(given["pens"])
    if "poster" in given:
        given["poster"] = _poster(given["poster"])
    job_file = None
    if job is not None:
        job_file = _readable(os.fsdecode(job))
        _, warning = _pixelpie.read_job(job_file)
        if warning:
            warnings.warn(f"{job_file}: {warning}", PixelpieWarning, stacklevel=3)
    return json.dumps(_finite(given), default=_option), job_file


def _poster(value: Any) -> Any:
    """``poster=(w, h)`` in mm as the library spells it, ``"WxHmm"``; a
    paper's name (``"a0"``) or such a string as it is."""
    if isinstance(value, str):
        return value
    try:
        w, h = value
    except (TypeError, ValueError):
        raise TypeError(
            f"poster must be (width, height) in mm or a paper's name, not {value!r}"
        ) from None
    for v in (w, h):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise TypeError(f"poster must be (width, height) in mm, not {value!r}")
    return f"{float(w)!r}x{float(h)!r}mm"


def _plan_json(text: str) -> Dict[str, Any]:
    """A plan's JSON as a dict. The library's JSON of a line drawing's plan
    (this version's) names two fields ``line``: the one-line summary, then
    the line's own plan (an object); the summary keeps ``line`` and the
    line's plan is ``line_plan``, as a plan's keys are once the library
    names it so."""

    def pairs(items: List[Tuple[str, Any]]) -> Dict[str, Any]:
        out: Dict[str, Any] = {}
        for key, value in items:
            if key == "line" and isinstance(value, dict):
                key = "line_plan"
            out[key] = value
        return out

    plan: Dict[str, Any] = json.loads(text, object_pairs_hook=pairs)
    return plan


def plan(
    image: Any,
    *,
    job: Optional[PathLike] = None,
    max_memory: Union[int, str, None] = None,
    **options: Any,
) -> Dict[str, Any]:
    """The plan of the drawing :func:`stipple` would make of ``image`` with
    these ``options`` (and ``job`` file), as ``pixelpie stipple --plan``
    prints it: every decision made once (``domain``, ``points``, ``dots``,
    ``dot``, ``relax``, ``spread``, ``corrected`` and ``why``, the correction's
    ``render``, ``order``, an estimated ``seconds``, ``style``) and its
    one-line summary, ``line``. With ``style="line"``, ``line_plan`` is the
    line's: its ``width_px`` and ``width_mm`` (the thinnest pen's), the
    count its pen ``needed`` for the picture's tones, ``why`` the count is
    what it is, and each pen's points (``pens``). Nothing is drawn."""
    given, job_file = _job(options, job)
    pixels = _picture(image)
    return _plan_json(
        _pixelpie.plan(
            None if pixels is not None else _readable(os.fsdecode(image)),
            pixels,
            given,
            job_file,
            _max_memory(max_memory),
        )
    )


class Pen(NamedTuple):
    """A pen of a colour drawing."""

    #: Its name.
    name: str
    #: Its colour, ``"#rrggbb"``.
    colour: str
    #: Its own width in mm, when its pen file gives one.
    width_mm: Optional[float]


class PenPaths(NamedTuple):
    """One layer's pen paths, as the plotter draws them
    (:meth:`Drawing.paths`)."""

    #: The layer's name, as the SVG's.
    name: str
    #: The pen's colour, ``"#rrggbb"``.
    colour: str
    #: The pen's width in mm.
    pen_mm: float
    #: One (K, 2) float64 array of x, y in mm on the page per dot, in
    #: drawing order; in a line drawing, one: the layer's line (its part
    #: with ``refill_mm``; smooth curves flattened within 0.01 mm).
    paths: List[np.ndarray]


class Stroke(NamedTuple):
    """One pen's line in a line drawing (``style="line"``,
    :attr:`Drawing.strokes`)."""

    #: (N, 2) float32 x, y in domain pixels of the points the pen's centre
    #: passes through, in drawing order (read-only).
    points: np.ndarray
    #: The line's width in domain pixels (the pen's).
    width: float
    #: Whether it is drawn as smooth curves through its points
    #: (``line_smooth``) rather than straight between them.
    smooth: bool


class Drawing:
    """A stipple drawing, as :func:`stipple` returns it.

    * ``dots`` -- (N, 3) float32 x, y and drawn radius in domain pixels, in
      drawing order; in colour (N, 4), the fourth column each dot's pen;
      empty in a line drawing;
    * ``style`` -- what the pen draws: ``"dots"`` or ``"line"``;
    * ``line`` and ``strokes`` -- a line drawing's line (``style="line"``):
      its points, (N, 2) float32 x, y in domain pixels in drawing order (in
      colour (N, 3), the third column each point's pen), and each pen's
      line as a :class:`Stroke`; empty in a drawing of dots;
    * ``domain`` -- (width, height) of the domain in pixels: the frame of
      ``dots``, as :func:`analyze` takes it
      (``analyze(d.dots, *d.domain)``);
    * ``asked`` and ``reached`` -- the dot count asked for (``None`` when
      the radii set it) and the count drawn; in a line drawing, the points
      its line was planned for and those it passes through;
    * ``plan`` -- the plan it was made by (:func:`plan`);
    * ``pens`` -- the pens of a colour drawing (:class:`Pen`), else ``None``;
    * ``warnings`` -- what the run warned of;
    * ``stages`` -- seconds in each stage (prepare, sample, relax, order,
      size);
    * ``sheets`` and ``poster`` -- a poster's sheets (``poster=(w, h)``),
      row by row, each a :class:`Drawing` on its sheet's page, and its
      manifest (``poster.json`` as a dict); ``[]`` and ``None`` otherwise;
    * :meth:`to_mm`, :meth:`svg`, :meth:`png`, :meth:`save`, :meth:`paths`,
      :meth:`plot_stats` and :meth:`to_vpype`.

    It behaves as its ``dots`` array where code indexes it: ``d[:, 0]``,
    ``len(d)``, ``d.shape``, ``np.asarray(d)`` and array methods; a line
    drawing, which draws no dots, as its ``line`` array (``len(d)`` is the
    count of the line's points, ``reached``).
    """

    __slots__ = (
        "_native", "_dots", "_line", "_strokes", "domain", "asked", "reached", "plan", "pens",
        "warnings", "stages", "style", "sheets", "poster",
    )

    #: Drawings of up to this many dots show as SVG in Jupyter, larger ones
    #: as PNG (an SVG of a million circles is more than a notebook wants).
    SVG_REPR_DOTS = 50_000

    def __init__(self, native: Any) -> None:
        self._native = native
        dots: np.ndarray = native.dots()
        # Read-only: the files (svg(), png(), save()) are made from the
        # library's drawing, so an edit here would silently not be drawn.
        dots.flags.writeable = False
        self._dots = dots
        self.style: str = native.style
        strokes = []
        for points, width, smooth in native.strokes():
            points.flags.writeable = False
            strokes.append(Stroke(points, float(width), bool(smooth)))
        self._strokes: List[Stroke] = strokes
        self._line = _line_of(strokes, colour=native.pens() is not None)
        self.domain: Tuple[int, int] = tuple(native.domain)  # type: ignore[assignment]
        self.asked: Optional[int] = native.asked
        self.reached: int = native.reached
        self.plan: Dict[str, Any] = _plan_json(native.plan())
        pens = native.pens()
        self.pens: Optional[List[Pen]] = None if pens is None else [Pen(*p) for p in pens]
        self.warnings: List[str] = list(native.warnings())
        self.stages: Dict[str, float] = dict(native.stages())
        self.sheets: List["Drawing"] = [Drawing(s) for s in native.sheets()]
        poster = native.poster(None)
        self.poster: Optional[Dict[str, Any]] = None if poster is None else json.loads(poster)

    def __repr__(self) -> str:
        w, h = self.domain
        if self.style == "line":
            lines = len(self._strokes)
            what = "a line" if lines == 1 else f"{lines} lines"
            return f"<pixelpie.Drawing: {what} through {self.reached} points on {w}x{h} px>"
        return f"<pixelpie.Drawing: {self.reached} dots on {w}x{h} px>"

    @property
    def dots(self) -> np.ndarray:
        """(N, 3) float32 x, y and drawn radius in domain pixels, in drawing
        order; in colour (N, 4), the fourth column each dot's pen. Read-only
        (what ``svg()``, ``png()`` and ``save()`` draw): edit a copy,
        ``d.dots.copy()``. Empty in a line drawing, which draws no dots
        (:attr:`line`)."""
        return self._dots

    @property
    def line(self) -> np.ndarray:
        """A line drawing's points (``style="line"``): (N, 2) float32 x, y
        in domain pixels that the pen's centre passes through, in drawing
        order; in colour (N, 3), the third column each point's pen, each
        pen's line after the one before (:attr:`strokes` holds them one by
        one). The line runs straight between them, or with ``line_smooth``
        in smooth curves through them (:meth:`paths` gives what the pen
        draws). Read-only; empty, (0, 2), in a drawing of dots."""
        return self._line

    @property
    def strokes(self) -> List[Stroke]:
        """A line drawing's lines, one per pen in the pens' order (one for a
        grey drawing), each a :class:`Stroke`: its points, width in domain
        pixels and whether it is smooth. Empty in a drawing of dots."""
        return list(self._strokes)

    def _array(self) -> np.ndarray:
        """The array the drawing behaves as: its line's points in a line
        drawing, else its dots."""
        return self._line if self.style == "line" else self._dots

    def __copy__(self) -> "Drawing":
        # The library's drawing is immutable: a copy shares it.
        return Drawing(self._native)

    def __deepcopy__(self, memo: Dict[int, Any]) -> "Drawing":
        copied = Drawing(self._native)
        memo[id(self)] = copied
        return copied

    def _repr_svg_(self) -> Optional[str]:
        """Jupyter's picture of the drawing: its SVG, up to
        :attr:`SVG_REPR_DOTS` dots (``None`` above: the PNG shows)."""
        if self.reached > self.SVG_REPR_DOTS:
            return None
        return self.svg().decode("utf-8")

    def _repr_png_(self) -> Optional[bytes]:
        """Jupyter's picture of a drawing of over :attr:`SVG_REPR_DOTS`
        dots: its PNG (``None`` below: the SVG shows)."""
        if self.reached <= self.SVG_REPR_DOTS:
            return None
        return self.png()

    def __reduce__(self) -> Any:
        raise TypeError(
            "a pixelpie.Drawing holds the library's drawing and does not pickle: "
            "return drawing.dots, drawing.svg() or drawing.png() from a worker"
        )

    # The array's behaviour: the dots' (a line drawing's, its line's).
    def __array__(self, dtype: Any = None, copy: Optional[bool] = None) -> np.ndarray:
        if copy:
            return np.array(self._array(), dtype=dtype, copy=True)
        return np.asarray(self._array(), dtype=dtype)

    def __len__(self) -> int:
        return len(self._array())

    def __getitem__(self, key: Any) -> Any:
        return self._array()[key]

    def __iter__(self) -> Iterator[np.ndarray]:
        return iter(self._array())

    def __getattr__(self, name: str) -> Any:
        # Array attributes and methods (shape, dtype, min, astype, ...).
        if name.startswith("_"):
            raise AttributeError(name)
        return getattr(self._array(), name)

    @property
    def page(self) -> Optional[Tuple[float, float]]:
        """The page's size in mm (the sheet, or ``width_mm`` and its
        height), when it has one."""
        t = self._native.transform()
        return None if t is None else (float(t[1][0]), float(t[1][1]))

    def to_mm(self, xy: Any) -> np.ndarray:
        """Domain pixels to mm on the page: an (N, 2) (or wider: its first
        two columns) array of x, y in pixels as float64 mm, the page's
        origin at its top left. ``ValueError`` when the page has no size in
        mm (give ``paper`` or ``width_mm``)."""
        t = self._native.transform()
        if t is None:
            raise ValueError("the drawing's page has no size in mm: give paper or width_mm")
        (scale, ox, oy), _ = t
        a = np.asarray(xy, dtype=np.float64)
        if a.ndim != 2 or a.shape[1] < 2:
            raise ValueError(f"xy must be an (N, 2) array, not of shape {a.shape}")
        return np.stack([ox + a[:, 0] * scale, oy + a[:, 1] * scale], axis=1)

    def svg(self) -> bytes:
        """The SVG file the job writes."""
        data: bytes = self._native.encode("svg")
        return data

    def png(self) -> bytes:
        """The PNG file the job writes (at its ``scale``)."""
        data: bytes = self._native.encode("png")
        return data

    def save(self, path: PathLike) -> None:
        """Writes the drawing to ``path`` in the format of its extension
        (``.svg``, ``.png``, ``.csv`` or ``.json``), atomically; a poster
        to folder ``path``: one SVG a sheet and ``poster.json``."""
        self._native.save(os.fsdecode(path))

    def paths(self) -> List[PenPaths]:
        """The pen paths as the plotter draws them, layer by layer in
        plotting order (the SVG's layers: ``layer_order``, ``refill_mm``),
        each dot's path in mm on the page; in a line drawing one path per
        layer, the pen's line (with ``refill_mm``, its parts, one per layer,
        each starting where the one before ended), its points
        :meth:`to_mm` of :attr:`line`'s, or with ``line_smooth`` the curves
        through them flattened within 0.01 mm. Needs a pen and a page size
        (``pen_mm``, and ``paper`` or ``width_mm``): ``ValueError``
        otherwise."""
        return [PenPaths(*layer) for layer in self._native.paths()]

    def plot_stats(self, plotter: Any = None) -> List[Dict[str, Any]]:
        """How a pen plotter draws the drawing, pen by pen in plotting
        order, as ``--plot-stats`` prints it: ``pen``, ``dots``, ``lifts``,
        ``pen_down_mm``, ``pen_up_mm``, ``pen_down_s``, ``pen_up_s`` and the
        estimated ``seconds``, as AxiDraw's own software plans the plot
        (its defaults; docs/plotter.md); a line drawing's ``dots`` are 0,
        its line one pen-down path. ``plotter`` overrides the profile: a
        built-in one's name (``"axidraw"``, ``"saxi"``), a profile file's
        path (TOML) or a dict of its keys, AxiDraw's option names or saxi's
        (``{"speed_pendown": 50, "accel": 100}``,
        ``{"pen_down_max_velocity": 30}``). Needs a pen and a page size, as
        :meth:`paths` does."""
        if plotter is None:
            text = None
        elif isinstance(plotter, dict):
            lines = []
            for key, value in plotter.items():
                if not (isinstance(key, str) and isinstance(value, (int, float))):
                    raise TypeError(
                        f"plotter: {key!r} = {value!r}: expected a key and a number"
                    )
                if isinstance(value, bool):  # const_speed
                    lines.append(f"{key} = {'true' if value else 'false'}")
                elif isinstance(value, int) and key in ("model", "resolution"):
                    lines.append(f"{key} = {value}")
                else:
                    lines.append(f"{key} = {float(value)!r}")
            text = "\n".join(lines)
        elif isinstance(plotter, str) and plotter in ("axidraw", "saxi"):
            text = plotter
        elif isinstance(plotter, (str, bytes, os.PathLike)):
            path = os.fsdecode(plotter)
            with open(path, encoding="utf-8") as f:
                text = f.read()
        else:
            raise TypeError(
                f"plotter must be a profile file's path or a dict, not {type(plotter).__name__}"
            )
        stats: List[Dict[str, Any]] = json.loads(self._native.plot_stats(text))
        return stats

    def to_vpype(self) -> Any:
        """The pen paths as a ``vpype.Document`` (layer k for the k-th layer
        of :meth:`paths`, with its name, colour and pen width, and the page
        size; a line drawing's line one path per layer), when vpype is
        installed (``pip install "pixelpie[vpype]"``)."""
        try:
            import vpype  # type: ignore[import-not-found]
        except ImportError as e:
            raise ImportError(
                'Drawing.to_vpype needs vpype: pip install "pixelpie[vpype]"'
            ) from e
        px = 96.0 / 25.4  # vpype's unit: CSS pixels per mm
        doc = vpype.Document()
        page = self.page
        if page is not None:
            doc.page_size = (page[0] * px, page[1] * px)
        for k, layer in enumerate(self.paths(), start=1):
            lines = vpype.LineCollection(
                [(p[:, 0] + 1j * p[:, 1]) * px for p in layer.paths]
            )
            doc.add(lines, layer_id=k)
            props = doc.layers[k]
            props.set_property("vp_name", layer.name)
            props.set_property("vp_color", vpype.Color(layer.colour))
            props.set_property("vp_pen_width", layer.pen_mm * px)
        return doc


def _line_of(strokes: List[Stroke], colour: bool) -> np.ndarray:
    """The points of ``strokes`` one after the other, read-only: (N, 2), or
    in colour (N, 3) with each point's pen (its stroke's index)."""
    columns = 3 if colour else 2
    parts = [s.points for s in strokes]
    if colour:
        parts = [
            np.column_stack([p, np.full(len(p), k, dtype=np.float32)])
            for k, p in enumerate(parts)
        ]
    line = (
        np.concatenate(parts).astype(np.float32, copy=False)
        if parts
        else np.zeros((0, columns), dtype=np.float32)
    )
    if len(parts) == 1 and not colour:
        line = parts[0]
    line.flags.writeable = False
    return line


def analyze(
    points: Any,
    width: float,
    height: float,
    *,
    periodic: bool = False,
    radius: Optional[float] = None,
) -> Dict[str, Any]:
    """The measures of ``pixelpie analyze`` for ``points`` on a domain.

    ``points`` is an (N, 2) array of x and y, or (N, 3) with a radius
    column (the covering radius of each point, unless ``radius`` gives one
    for all). Returns a dict: ``count``, ``min_distance``, ``rho``,
    ``uncovered_pixels``, ``density``, ``largest_gap`` (the largest empty
    circle: ``radius`` and its centre ``at``), ``maximal`` (continuous coverage),
    ``angle_std`` and ``angle_edges``.
    """
    a = np.ascontiguousarray(points, dtype=np.float64)
    if a.ndim != 2:
        raise ValueError(f"points must be an (N, 2) or (N, 3) array, not {a.ndim}-D")
    return _pixelpie.analyze(
        a,
        float(width),
        float(height),
        bool(periodic),
        None if radius is None else float(radius),
    )
