"""Type stubs of the pixelpie package."""

import os
import sys
from typing import (
    Any,
    Callable,
    Dict,
    Iterator,
    List,
    Literal,
    Mapping,
    NamedTuple,
    Optional,
    Sequence,
    Tuple,
    TypedDict,
    Union,
    overload,
)

import numpy as np
import numpy.typing as npt

if sys.version_info >= (3, 11):
    from typing import NotRequired
else:
    from typing_extensions import NotRequired

__version__: str

PathLike = Union[str, bytes, os.PathLike[str], os.PathLike[bytes]]
Progress = Callable[[int, int, int, int], object]
#: An option's value, as ``sample_options`` and ``stipple_options`` give it.
OptionValue = Union[None, bool, int, float, str, List[str]]
#: A picture: a path, an array or a PIL image (``PIL.Image.Image``).
Picture = Union[PathLike, npt.ArrayLike, object]
Pens = Union[str, os.PathLike[str], Sequence[str]]

class PixelpieWarning(UserWarning):
    """What the command line prints as ``warning: ...``."""

class SampleStats(TypedDict):
    """The run's statistics, as ``pixelpie sample --stats`` writes them."""

    points: int
    target: Optional[int]
    iterations: int
    maximal: bool
    exact: bool
    empty_left: int
    repaired: int
    backend: str
    device: str
    seconds: float
    throw_seconds: float
    cull_seconds: float
    compact_seconds: float
    bytes_per_pixel: float
    gpu_timestamps: bool
    refine_seconds: NotRequired[float]
    repair_seconds: NotRequired[float]

class Gap(TypedDict):
    """The largest empty circle."""

    radius: float
    at: List[float]

class Analysis(TypedDict):
    """The measures of ``pixelpie analyze``."""

    count: int
    min_distance: float
    rho: float
    uncovered_pixels: NotRequired[int]
    density: float
    largest_gap: Gap
    continuous_maximal: bool
    angle_std: float
    angle_edges: int

class LinePlan(TypedDict):
    """A line drawing's plan: its width and why its count is what it is."""

    width_px: float
    width_mm: Optional[float]
    needed: int
    why: str
    pens: List[int]

class Plan(TypedDict):
    """A drawing's plan (``pixelpie stipple --plan``)."""

    line: str
    picture: List[int]
    domain: List[int]
    points: Optional[int]
    dots: int
    pens: int
    radius: List[float]
    dot: str
    relax: int
    corrected: bool
    why: str
    render: Optional[List[int]]
    order: str
    layer_order: Optional[str]
    seconds: float
    memory_mb: int
    style: str
    line_plan: NotRequired[LinePlan]

class Pen(NamedTuple):
    """A pen of a colour drawing."""

    name: str
    colour: str
    width_mm: Optional[float]

class PenPaths(NamedTuple):
    """One layer's pen paths, as the plotter draws them."""

    name: str
    colour: str
    pen_mm: float
    paths: List[npt.NDArray[np.float64]]

class Stroke(NamedTuple):
    """One pen's line in a line drawing."""

    points: npt.NDArray[np.float32]
    width: float
    smooth: bool

class PlotStats(TypedDict):
    """One pen's plot, as ``--plot-stats`` prints it."""

    pen: str
    dots: int
    lifts: int
    pen_down_mm: float
    pen_up_mm: float
    pen_down_s: float
    pen_up_s: float
    seconds: float

class Drawing:
    """A stipple drawing: its dots and what comes with them."""

    SVG_REPR_DOTS: int
    @property
    def dots(self) -> npt.NDArray[np.float32]:
        """The dots, read-only (what ``svg()`` and ``png()`` draw)."""
    @property
    def line(self) -> npt.NDArray[np.float32]:
        """A line drawing's points, read-only."""
    @property
    def strokes(self) -> List[Stroke]:
        """A line drawing's lines, one per pen."""
    style: str
    domain: Tuple[int, int]
    asked: Optional[int]
    reached: int
    plan: Plan
    pens: Optional[List[Pen]]
    warnings: List[str]
    stages: Dict[str, float]
    sheets: List["Drawing"]
    poster: Optional[Dict[str, Any]]
    @property
    def page(self) -> Optional[Tuple[float, float]]: ...
    @property
    def shape(self) -> Tuple[int, ...]: ...
    def to_mm(self, xy: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def svg(self) -> bytes: ...
    def png(self) -> bytes: ...
    def save(self, path: PathLike) -> None: ...
    def paths(self) -> List[PenPaths]: ...
    def plot_stats(
        self, plotter: Union[PathLike, Mapping[str, Union[float, bool]], None] = ...
    ) -> List[PlotStats]: ...
    def to_vpype(self) -> object:
        """A ``vpype.Document`` of the pen paths."""
    def __copy__(self) -> Drawing: ...
    def __deepcopy__(self, memo: Dict[int, object]) -> Drawing: ...
    def _repr_svg_(self) -> Optional[str]: ...
    def _repr_png_(self) -> Optional[bytes]: ...
    def __array__(
        self, dtype: Optional[npt.DTypeLike] = ..., copy: Optional[bool] = ...
    ) -> npt.NDArray[np.float32]: ...
    def __len__(self) -> int: ...
    def __getitem__(self, key: object) -> npt.NDArray[np.float32]: ...
    def __iter__(self) -> Iterator[npt.NDArray[np.float32]]: ...
    def max(self) -> np.float32: ...
    def min(self) -> np.float32: ...

def sample_options() -> Dict[str, OptionValue]:
    """The options ``sample`` takes, with their defaults."""

def sample(
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    *,
    radius_map: Union[PathLike, npt.ArrayLike, None] = ...,
    importance: Optional[Picture] = ...,
    backend: str = ...,
    progress: Optional[Progress] = ...,
    max_memory: Union[int, str, None] = ...,
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
) -> Tuple[npt.NDArray[np.float32], SampleStats]:
    """A maximal Poisson-disk set: (N, 3) float32 x, y, radius, and the stats."""

def stipple_options() -> Dict[str, OptionValue]:
    """The options ``stipple`` takes, with their defaults."""

@overload
def stipple(
    image: Picture,
    output: Optional[PathLike] = ...,
    *,
    backend: str = ...,
    progress: Optional[Progress] = ...,
    svg: Literal[False] = ...,
    job: Optional[PathLike] = ...,
    max_memory: Union[int, str, None] = ...,
    points: Optional[int] = ...,
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    dot: Optional[str] = ...,
    dot_factor: Optional[float] = ...,
    dot_ratio: Optional[float] = ...,
    dot_radius: Optional[float] = ...,
    relax: Optional[int] = ...,
    order: Optional[str] = ...,
    style: Optional[str] = ...,
    line_smooth: Optional[bool] = ...,
    scale: Optional[float] = ...,
    width_mm: Optional[float] = ...,
    paper: Optional[str] = ...,
    margin: Optional[float] = ...,
    landscape: Optional[bool] = ...,
    poster: Union[Tuple[float, float], str, None] = ...,
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
    pens: Optional[Pens] = ...,
    choose: Optional[int] = ...,
    paper_colour: Optional[str] = ...,
    size_px: bool = ...,
    crop: Optional[str] = ...,
    dot_mm: Optional[float] = ...,
    rotate: Optional[int] = ...,
    refill_mm: Optional[float] = ...,
    layer_order: Optional[str] = ...,
    spacing: Optional[str] = ...,
    correction: Optional[str] = ...,
) -> Drawing:
    """A stipple drawing of ``image`` (a path, an array or a PIL image),
    written to ``output`` when given: its dots, domain, plan, counts, pens,
    files and pen paths."""

@overload
def stipple(
    image: Picture,
    output: Optional[PathLike] = ...,
    *,
    backend: str = ...,
    progress: Optional[Progress] = ...,
    svg: Literal[True],
    job: Optional[PathLike] = ...,
    max_memory: Union[int, str, None] = ...,
    points: Optional[int] = ...,
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    dot: Optional[str] = ...,
    dot_factor: Optional[float] = ...,
    dot_ratio: Optional[float] = ...,
    dot_radius: Optional[float] = ...,
    relax: Optional[int] = ...,
    order: Optional[str] = ...,
    style: Optional[str] = ...,
    line_smooth: Optional[bool] = ...,
    scale: Optional[float] = ...,
    width_mm: Optional[float] = ...,
    paper: Optional[str] = ...,
    margin: Optional[float] = ...,
    landscape: Optional[bool] = ...,
    poster: Union[Tuple[float, float], str, None] = ...,
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
    pens: Optional[Pens] = ...,
    choose: Optional[int] = ...,
    paper_colour: Optional[str] = ...,
    size_px: bool = ...,
    crop: Optional[str] = ...,
    dot_mm: Optional[float] = ...,
    rotate: Optional[int] = ...,
    refill_mm: Optional[float] = ...,
    layer_order: Optional[str] = ...,
    spacing: Optional[str] = ...,
    correction: Optional[str] = ...,
) -> str:
    """The SVG text of the drawing of ``image``."""

def plan(
    image: Picture,
    *,
    job: Optional[PathLike] = ...,
    max_memory: Union[int, str, None] = ...,
    points: Optional[int] = ...,
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    dot: Optional[str] = ...,
    dot_factor: Optional[float] = ...,
    dot_ratio: Optional[float] = ...,
    dot_radius: Optional[float] = ...,
    relax: Optional[int] = ...,
    order: Optional[str] = ...,
    style: Optional[str] = ...,
    line_smooth: Optional[bool] = ...,
    scale: Optional[float] = ...,
    width_mm: Optional[float] = ...,
    paper: Optional[str] = ...,
    margin: Optional[float] = ...,
    landscape: Optional[bool] = ...,
    poster: Union[Tuple[float, float], str, None] = ...,
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
    pens: Optional[Pens] = ...,
    choose: Optional[int] = ...,
    paper_colour: Optional[str] = ...,
    size_px: bool = ...,
    crop: Optional[str] = ...,
    dot_mm: Optional[float] = ...,
    rotate: Optional[int] = ...,
    refill_mm: Optional[float] = ...,
    layer_order: Optional[str] = ...,
    spacing: Optional[str] = ...,
    correction: Optional[str] = ...,
) -> Plan:
    """The plan of the drawing ``stipple`` would make (``pixelpie stipple
    --plan``): every decision, an estimated time and its one-line summary."""

def analyze(
    points: npt.ArrayLike,
    width: float,
    height: float,
    *,
    periodic: bool = ...,
    radius: Optional[float] = ...,
) -> Analysis:
    """The measures of ``pixelpie analyze``."""
