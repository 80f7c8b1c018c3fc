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
import os
from typing import Any, Callable, Dict, Optional, Tuple, Union

import numpy as np

from . import _pixelpie

__all__ = ["sample", "stipple", "stipple_options", "analyze", "__version__"]
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


def sample(
    width: int,
    height: int,
    *,
    radius: Optional[float] = None,
    points: Optional[int] = None,
    radius_map: Any = None,
    importance: Any = None,
    policy: str = "smaller",
    seed: int = 0,
    subpixel_bits: int = 3,
    periodic: bool = False,
    exact: bool = False,
    backend: str = "auto",
    max_iterations: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> Tuple[np.ndarray, Dict[str, Any]]:
    """Samples a maximal Poisson-disk set on a ``width`` x ``height`` domain.

    Give one of:

    * ``radius`` -- the disk radius in pixels, or ``points`` -- about that
      many points (within 3%), the radius found for it;
    * ``radius_map`` -- a (height, width) array of radii in pixels (at
      least 1); ``points`` scales it;
    * ``importance`` -- an image path, or a (H, W) array of grey values in
      [0, 1] (0 = black, taken as it is), resized to the domain: dark
      pixels get small disks. ``radius`` is then the black pixels' radius
      (white gets 8 times it), and ``points`` a count target; give at least
      one.

    ``policy`` is how disks of different radii keep apart (paper 3.4):
    ``"prior"`` (the earlier sample's disk), ``"current"`` (the later
    one's), ``"bigger"`` or ``"smaller"``. ``subpixel_bits`` (0 to 7) places
    darts on a finer grid inside each pixel; ``periodic`` wraps the domain
    (tileable sets); ``exact`` gives sets that meet the disk condition with
    no sub-pixel slack and are maximal in the continuous domain (at the
    RSA density). ``backend`` is ``"auto"``, ``"cpu"`` or ``"gpu"`` (this
    package is built without the GPU backend: ``"gpu"`` raises
    ``RuntimeError``). ``max_iterations`` caps the loop (a capped set is not
    maximal: ``stats["maximal"]`` says so). ``progress(iteration, points,
    empty, pixels)`` is called after every iteration; an exception it
    raises stops the run and is raised.

    Returns ``(points, stats)``: an (N, 3) float32 array of x, y and radius
    in acceptance order, and the run's statistics (``points``,
    ``iterations``, ``maximal``, ``exact``, ``seconds``, per-stage seconds,
    ...), as ``pixelpie sample --stats`` writes them.
    """
    path = values = None
    if importance is not None:
        if isinstance(importance, (str, os.PathLike)):
            path = os.fspath(importance)
        else:
            values = _grid(importance, "importance")
    rmap = None if radius_map is None else _grid(radius_map, "radius_map")
    return _pixelpie.sample(
        int(width),
        int(height),
        None if radius is None else float(radius),
        None if points is None else int(points),
        rmap,
        path,
        values,
        policy,
        int(seed),
        int(subpixel_bits),
        bool(periodic),
        bool(exact),
        backend,
        None if max_iterations is None else int(max_iterations),
        progress,
    )


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


def stipple(
    image: PathLike,
    output: Optional[PathLike] = None,
    *,
    backend: str = "auto",
    progress: Optional[Progress] = None,
    **options: Any,
) -> np.ndarray:
    """Draws ``image`` as stipples, as ``pixelpie stipple`` does.

    With ``output`` (``.svg``, ``.png``, ``.csv`` or ``.json``) the drawing
    is written there: the same file as the command line writes for the same
    options. Returns the dots as an (N, 3) float32 array of x, y and drawn
    radius, in domain pixels and in drawing order; with ``pens`` an (N, 4)
    array whose fourth column is each dot's pen (its index in the pens).

    ``options`` are the command line's, with underscores, and the same
    defaults (the library's drawing job, ``pixelpie::job::Job``, holds
    them all): ``points`` (default 10 000 unless ``min_radius`` or
    ``dot_radius`` is given), ``width``, ``height``, ``dot`` (``"sized"``:
    small dots in light areas, the default; ``"fixed"``: all alike;
    ``"proportional"``: a fraction of each disk, a texture that does not
    reproduce tones), ``dot_factor``, ``dot_ratio``, ``dot_radius``,
    ``relax`` (weighted Lloyd steps), ``order`` (``"tsp"``: a short
    pen-plotter path), ``scale`` (PNG pixels per domain pixel),
    ``width_mm`` and ``pen_mm`` (SVG in millimetres, drawn with a pen),
    ``paper`` (``"a4"``, ``"letter"``, ``"WxHmm"``, ...: the SVG is the sheet,
    instead of ``width_mm``), ``margin`` (mm) and ``landscape``, ``dot_path``
    (``"spiral"``, ``"circle"`` or ``"touch"``: how the pen draws a dot),
    ``ink`` (``"#rrggbb"``), ``policy`` (default ``"smaller"``), ``seed``,
    ``subpixel_bits``, ``periodic``, ``exact``, ``tones`` (``"display"``:
    reproduce the grey a viewer sees; ``"linear"``: linear light),
    ``mapping``, ``min_radius``, ``max_radius``, ``gamma``,
    ``black_level``, ``white_level``, ``invert``, ``white_cutoff`` and
    ``hdr_white``; ``pens`` draws in colour with several pens sampled
    together: ``"cmyk"``, a list of ``"#rrggbb"`` colours, or the path of a
    ``.toml`` pen file. An unknown name raises ``ValueError``.
    """
    given = {
        k: os.fspath(v) if isinstance(v, os.PathLike) else v
        for k, v in options.items()
        if v is not None
    }
    return _pixelpie.stipple(
        os.fspath(image),
        _path(output),
        json.dumps(given, default=_option),
        backend,
        progress,
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
