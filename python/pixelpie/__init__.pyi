"""Type stubs of the pixelpie package."""

import os
from typing import Any, Callable, Dict, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, os.PathLike[str]]
Progress = Callable[[int, int, int, int], Any]

def sample_options() -> Dict[str, Any]:
    """The options ``sample`` takes, with their defaults."""

def sample(
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    *,
    radius_map: Union[PathLike, npt.ArrayLike, None] = ...,
    importance: Union[PathLike, npt.ArrayLike, None] = ...,
    backend: str = ...,
    progress: Optional[Progress] = ...,
    radius: Optional[float] = ...,
    points: Optional[int] = ...,
    policy: Optional[str] = ...,
    seed: Optional[int] = ...,
    subpixel_bits: Optional[int] = ...,
    periodic: Optional[bool] = ...,
    exact: Optional[bool] = ...,
    batch: Optional[int] = ...,
    max_iterations: Optional[int] = ...,
    tones: Optional[str] = ...,
    mapping: Optional[str] = ...,
    min_radius: Optional[float] = ...,
    max_radius: Optional[float] = ...,
    gamma: Optional[float] = ...,
    black_level: Optional[float] = ...,
    white_level: Optional[float] = ...,
    invert: Optional[bool] = ...,
    white_cutoff: Optional[float] = ...,
    hdr_white: Optional[float] = ...,
) -> Tuple[npt.NDArray[np.float32], Dict[str, Any]]:
    """A maximal Poisson-disk set: (N, 3) float32 x, y, radius, and the stats."""

def stipple_options() -> Dict[str, Any]:
    """The options ``stipple`` takes, with their defaults."""

def stipple(
    image: Union[PathLike, npt.ArrayLike, Any],
    output: Optional[PathLike] = ...,
    *,
    backend: str = ...,
    progress: Optional[Progress] = ...,
    svg: bool = ...,
    job: Optional[PathLike] = ...,
    points: Optional[int] = ...,
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    dot: Optional[str] = ...,
    dot_factor: Optional[float] = ...,
    dot_ratio: Optional[float] = ...,
    dot_radius: Optional[float] = ...,
    relax: Optional[int] = ...,
    order: Optional[str] = ...,
    scale: Optional[float] = ...,
    width_mm: Optional[float] = ...,
    paper: Optional[str] = ...,
    margin: Optional[float] = ...,
    landscape: Optional[bool] = ...,
    pen_mm: Optional[float] = ...,
    dot_path: Optional[str] = ...,
    ink: Optional[str] = ...,
    policy: Optional[str] = ...,
    seed: Optional[int] = ...,
    subpixel_bits: Optional[int] = ...,
    periodic: Optional[bool] = ...,
    exact: Optional[bool] = ...,
    tones: Optional[str] = ...,
    mapping: Optional[str] = ...,
    min_radius: Optional[float] = ...,
    max_radius: Optional[float] = ...,
    gamma: Optional[float] = ...,
    black_level: Optional[float] = ...,
    white_level: Optional[float] = ...,
    invert: Optional[bool] = ...,
    white_cutoff: Optional[float] = ...,
    hdr_white: Optional[float] = ...,
    pens: Optional[Union[str, Sequence[str], os.PathLike[str]]] = ...,
    crop: Optional[str] = ...,
    dot_mm: Optional[float] = ...,
    rotate: Optional[int] = ...,
    refill_mm: Optional[float] = ...,
    layer_order: Optional[str] = ...,
    spacing: Optional[str] = ...,
    correction: Optional[str] = ...,
) -> Any:
    """A stipple drawing of ``image`` (a path, an array or a PIL image),
    written to ``output``; its dots (x, y, radius), with ``pens`` also each
    dot's pen; with ``svg=True`` the SVG's text."""

def plan(
    image: Union[PathLike, npt.ArrayLike, Any],
    *,
    job: Optional[PathLike] = ...,
    points: Optional[int] = ...,
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    dot: Optional[str] = ...,
    dot_factor: Optional[float] = ...,
    dot_ratio: Optional[float] = ...,
    dot_radius: Optional[float] = ...,
    relax: Optional[int] = ...,
    order: Optional[str] = ...,
    scale: Optional[float] = ...,
    width_mm: Optional[float] = ...,
    paper: Optional[str] = ...,
    margin: Optional[float] = ...,
    landscape: Optional[bool] = ...,
    pen_mm: Optional[float] = ...,
    dot_path: Optional[str] = ...,
    ink: Optional[str] = ...,
    policy: Optional[str] = ...,
    seed: Optional[int] = ...,
    subpixel_bits: Optional[int] = ...,
    periodic: Optional[bool] = ...,
    exact: Optional[bool] = ...,
    tones: Optional[str] = ...,
    mapping: Optional[str] = ...,
    min_radius: Optional[float] = ...,
    max_radius: Optional[float] = ...,
    gamma: Optional[float] = ...,
    black_level: Optional[float] = ...,
    white_level: Optional[float] = ...,
    invert: Optional[bool] = ...,
    white_cutoff: Optional[float] = ...,
    hdr_white: Optional[float] = ...,
    pens: Optional[Union[str, Sequence[str], os.PathLike[str]]] = ...,
    crop: Optional[str] = ...,
    dot_mm: Optional[float] = ...,
    rotate: Optional[int] = ...,
    refill_mm: Optional[float] = ...,
    layer_order: Optional[str] = ...,
    spacing: Optional[str] = ...,
    correction: Optional[str] = ...,
) -> Dict[str, Any]:
    """The plan of the drawing ``stipple`` would make (``pixelpie stipple
    --plan``): every decision, an estimated time and its one-line summary."""

def analyze(
    points: npt.ArrayLike,
    width: float,
    height: float,
    *,
    periodic: bool = ...,
    radius: Optional[float] = ...,
) -> Dict[str, Any]:
    """The measures of ``pixelpie analyze``."""
