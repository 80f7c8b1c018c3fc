"""PixelPie: maximal Poisson-disk sampling by rasterization, and stippling.

The system of Ip, Yalcin, Luebke & Varshney, *PixelPie: Maximal Poisson-disk
Sampling with Rasterization* (HPG 2013), from the Rust library's CPU
backend: the same points as the ``pixelpie`` command line, bit for bit.

* :func:`sample` -- a maximal Poisson-disk set as an (N, 3) float32 array
  of x, y and radius, uniform, from a radius map or from an image;
* :func:`stipple` -- a picture as a stipple drawing (SVG or PNG), and its
  dots;
* :func:`analyze` -- the measures of ``pixelpie analyze`` for any point set.

The GIL is released while the library works, and Ctrl-C (KeyboardInterrupt)
stops a run between iterations. Bad arguments raise ``ValueError``; files
that cannot be read or written raise ``OSError``.
"""

from __future__ import annotations

import json
import math
import operator
import os
import warnings
from typing import Any, Callable, Dict, Optional, Tuple, Union

import numpy as np

from . import _pixelpie

__all__ = [
    "sample",
    "sample_options",
    "stipple",
    "stipple_options",
    "analyze",
    "__version__",
]
__version__: str = _pixelpie.__version__

PathLike = Union[str, "os.PathLike[str]"]
Progress = Callable[[int, int, int, int], Any]


def _grid(values: Any, name: str) -> np.ndarray:
    a = np.ascontiguousarray(values, dtype=np.float32)
    if a.ndim != 2:
        raise ValueError(f"{name} must be a 2-D (height, width) array, not {a.ndim}-D")
    return a


def _path(p: Optional[PathLike]) -> Optional[str]:
    return None if p is None else os.fspath(p)


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
    * ``importance`` -- an image path, or a (H, W) array of grey values in
      [0, 1] (0 = black, taken as it is: linear unless ``tones`` says
      otherwise), resized to the domain (its aspect kept): dark pixels get
      small disks. ``min_radius`` is then the black pixels' radius (white
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
    writes them. A bad argument raises ``ValueError`` (``TypeError`` for a
    wrong type).
    """
    # The options' types are the job's own: its serde form refuses a float,
    # a string or a negative number for a count (ValueError naming it).
    given = {k: v for k, v in options.items() if v is not None}
    if width is not None:
        given["width"] = _count(width, "width")
    if height is not None:
        given["height"] = _count(height, "height")
    rmap = values = None
    if radius_map is not None:
        if isinstance(radius_map, (str, os.PathLike)):
            given["radius_map"] = os.fspath(radius_map)
        else:
            rmap = _grid(radius_map, "radius_map")
    if importance is not None:
        if isinstance(importance, (str, os.PathLike)):
            given["importance"] = os.fspath(importance)
        else:
            values = _grid(importance, "importance")
    return _pixelpie.sample(
        json.dumps(_finite(given), default=_option), rmap, values, backend, progress
    )


def _finite(options: Dict[str, Any]) -> Dict[str, Any]:
    """``options`` with every float checked: NaN and infinities raise
    ``ValueError`` naming the option (JSON has no word for them)."""
    for name, v in options.items():
        if isinstance(v, float) and not math.isfinite(v):
            raise ValueError(f"{name} {v} must be a finite number")
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


def _picture(image: Any) -> Optional[np.ndarray]:
    """A picture given as an array or a PIL image, as sRGB-encoded 16-bit
    values of shape (H, W) or (H, W, channels); ``None`` for a path."""
    if isinstance(image, (str, os.PathLike)):
        return None
    a = np.asarray(image)
    if a.dtype == np.uint8:
        a = a.astype(np.uint16) * 257
    elif a.dtype == np.uint16:
        pass
    elif a.dtype.kind == "f":
        if not np.all(np.isfinite(a)):
            raise ValueError("the picture array holds NaN or infinite values")
        a = np.round(np.clip(a, 0.0, 1.0) * 65535.0).astype(np.uint16)
    elif a.dtype == bool:
        a = a.astype(np.uint16) * 65535
    else:
        raise TypeError(
            f"a picture array must be uint8, uint16, float (0 to 1) or bool, not {a.dtype}"
        )
    if a.ndim not in (2, 3):
        raise ValueError(f"a picture array must be (H, W) or (H, W, C), not {a.ndim}-D")
    return np.ascontiguousarray(a)


def stipple(
    image: Any,
    output: Optional[PathLike] = None,
    *,
    backend: str = "auto",
    progress: Optional[Progress] = None,
    svg: bool = False,
    job: Optional[PathLike] = None,
    **options: Any,
) -> Any:
    """Draws ``image`` as stipples, as ``pixelpie stipple`` does.

    ``image`` is a file's path, a numpy array -- (H, W) grey or (H, W, 3 or
    4) RGB(A), uint8, uint16 or float in [0, 1], sRGB-encoded as in an image
    file -- or a PIL image. With ``output`` (``.svg``, ``.png``, ``.csv`` or
    ``.json``) the drawing is written there: the same file as the command
    line writes for the same options. Returns the dots as an (N, 3) float32
    array of x, y and drawn radius, in domain pixels and in drawing order;
    with ``pens`` an (N, 4) array whose fourth column is each dot's pen (its
    index in the pens); with ``svg=True`` the SVG's text instead.

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
    as earlier versions), ``relax`` (weighted Lloyd steps; by default 3 for
    corrected sized dots up to 200 000 dots, else none),
    ``order`` (``"tsp"``: a short pen-plotter path), ``scale`` (PNG pixels
    per domain pixel), ``width_mm`` and ``pen_mm`` (SVG in millimetres,
    drawn with a pen), ``paper`` (``"a4"``, ``"letter"``, ``"WxHmm"``, ...:
    the SVG is the sheet, instead of ``width_mm``), ``margin`` (mm) and
    ``landscape``, ``dot_path`` (``"spiral"``, ``"circle"`` or ``"touch"``:
    how the pen draws a dot), ``ink`` (``"#rrggbb"``), ``policy`` (default
    ``"smaller"``), ``seed``, ``subpixel_bits``, ``periodic``, ``exact``,
    ``tones`` (``"display"``: reproduce the grey a viewer sees;
    ``"linear"``: linear light), ``mapping``, ``min_radius``,
    ``max_radius``, ``gamma``, ``black_level``, ``white_level``,
    ``invert``, ``white_cutoff`` and ``hdr_white``; ``pens`` draws in colour
    with several pens sampled together: ``"cmyk"``, a list of ``"#rrggbb"``
    colours, or the path of a ``.toml`` pen file; ``crop`` (``"x,y,w,h"``)
    and ``rotate`` (90, 180 or 270) frame the picture; ``refill_mm`` and
    ``layer_order`` shape the pen layers. An unknown name or a bad value
    raises ``ValueError`` (``TypeError`` for a wrong type).

    ``job`` is a job file (``pixelpie stipple --save-job``, the app's
    presets): its settings, with ``options`` over them, as ``--job`` takes
    it; a file from another version warns (``UserWarning``).
    """
    given, job_file = _job(options, job)
    pixels = _picture(image)
    return _pixelpie.stipple(
        None if pixels is not None else os.fspath(image),
        pixels,
        _path(output),
        given,
        job_file,
        backend,
        bool(svg),
        progress,
    )


def _job(options: Dict[str, Any], job: Optional[PathLike]) -> Tuple[str, Optional[str]]:
    """The keyword options as the native functions take them (JSON), and
    the job file's path; a job file from another version warns. The
    library lays the options over the file, as the command line does."""
    given = {
        k: os.fspath(v) if isinstance(v, os.PathLike) else v
        for k, v in options.items()
        if v is not None
    }
    job_file = None
    if job is not None:
        job_file = os.fspath(job)
        _, warning = _pixelpie.read_job(job_file)
        if warning:
            warnings.warn(f"{job_file}: {warning}", stacklevel=3)
    return json.dumps(_finite(given), default=_option), job_file


def plan(image: Any, *, job: Optional[PathLike] = None, **options: Any) -> Dict[str, Any]:
    """The plan of the drawing :func:`stipple` would make of ``image`` with
    these ``options`` (and ``job`` file), as ``pixelpie stipple --plan``
    prints it: every decision made once (``domain``, ``points``, ``dots``,
    ``dot``, ``relax``, ``corrected`` and ``why``, the correction's
    ``render``, ``order``, an estimated ``seconds``) and its one-line
    summary, ``line``. Nothing is drawn."""
    given, job_file = _job(options, job)
    pixels = _picture(image)
    return json.loads(
        _pixelpie.plan(
            None if pixels is not None else os.fspath(image), pixels, given, job_file
        )
    )


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
