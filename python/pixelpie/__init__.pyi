"""Type stubs of the pixelpie package."""

import os
from typing import Any, Callable, Dict, Optional, Tuple, Union

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

def stipple(
    image: PathLike,
    output: Optional[PathLike] = ...,
    *,
    points: Optional[int] = ...,
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    dot: Optional[str] = ...,
    dot_factor: Optional[float] = ...,
    dot_ratio: float = ...,
    dot_radius: Optional[float] = ...,
    relax: int = ...,
    order: str = ...,
    scale: float = ...,
    width_mm: Optional[float] = ...,
    pen_mm: Optional[float] = ...,
    policy: str = ...,
    seed: int = ...,
    subpixel_bits: int = ...,
    periodic: bool = ...,
    exact: bool = ...,
    tones: str = ...,
    mapping: Optional[str] = ...,
    min_radius: Optional[float] = ...,
    max_radius: Optional[float] = ...,
    gamma: float = ...,
    black_level: float = ...,
    white_level: float = ...,
    invert: bool = ...,
    white_cutoff: Optional[float] = ...,
    hdr_white: Optional[float] = ...,
    backend: str = ...,
    progress: Optional[Progress] = ...,
) -> npt.NDArray[np.float32]:
    """A stipple drawing of ``image``, written to ``output``; its dots (x, y, radius)."""

def analyze(
    points: npt.ArrayLike,
    width: float,
    height: float,
    *,
    periodic: bool = ...,
    radius: Optional[float] = ...,
) -> Dict[str, Any]:
    """The measures of ``pixelpie analyze``."""
