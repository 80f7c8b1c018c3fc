"""Type stubs of the pixelpie package."""

import os
from typing import Any, Callable, Dict, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, os.PathLike[str]]
Progress = Callable[[int, int, int, int], Any]

def sample(
    width: int,
    height: int,
    *,
    radius: Optional[float] = ...,
    points: Optional[int] = ...,
    radius_map: Optional[npt.ArrayLike] = ...,
    importance: Union[PathLike, npt.ArrayLike, None] = ...,
    policy: str = ...,
    seed: int = ...,
    subpixel_bits: int = ...,
    periodic: bool = ...,
    exact: bool = ...,
    backend: str = ...,
    max_iterations: Optional[int] = ...,
    progress: Optional[Progress] = ...,
) -> Tuple[npt.NDArray[np.float32], Dict[str, Any]]:
    """A maximal Poisson-disk set: (N, 3) float32 x, y, radius, and the stats."""

def stipple_options() -> Dict[str, Any]:
    """The options ``stipple`` takes, with their defaults."""

def stipple(
    image: PathLike,
    output: Optional[PathLike] = ...,
    *,
    backend: str = ...,
    progress: Optional[Progress] = ...,
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
    pen_mm: Optional[float] = ...,
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
) -> npt.NDArray[np.float32]:
    """A stipple drawing of ``image``, written to ``output``; its dots (x, y,
    radius), with ``pens`` also each dot's pen."""

def analyze(
    points: npt.ArrayLike,
    width: float,
    height: float,
    *,
    periodic: bool = ...,
    radius: Optional[float] = ...,
) -> Dict[str, Any]:
    """The measures of ``pixelpie analyze``."""
