"""Type stubs of the native module `guiding._guiding` (see the package's
docstring). Array arguments take any array-like of floats or integers of
the shape given in the comments; light indices any integer dtype."""

from typing import Optional, Tuple, TypedDict

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
F32 = npt.NDArray[np.float32]
I64 = npt.NDArray[np.int64]

PARALLEL_FROM: int
"""Batches of at least this many points run on a thread pool."""

class RefineOutcome(TypedDict):
    splits: int
    refused_by_budget: int
    refused_by_precision: int

class DroppedRecords(TypedDict):
    position: int
    direction: int
    radiance: int
    pdf: int
    overflow: int
    light: int
    total: int

class Emitters:
    """A scene's emitters in the order their light indices count; each
    `add_*` appends a batch (one row per emitter) and returns the first's
    index. Powers are flux, finite and >= 0."""

    def __init__(self) -> None: ...
    def __len__(self) -> int: ...
    def add_points(self, positions: ArrayLike, powers: ArrayLike) -> int:
        """positions (n, 3), powers (n,)."""
    def add_spheres(self, centers: ArrayLike, radii: ArrayLike, powers: ArrayLike) -> int:
        """centers (n, 3), radii (n,), powers (n,)."""
    def add_spots(
        self,
        positions: ArrayLike,
        directions: ArrayLike,
        cos_falloff_start: ArrayLike,
        cos_falloff_end: ArrayLike,
        powers: ArrayLike,
    ) -> int:
        """pbrt's spot lights: positions, directions (n, 3); cosines (n,) in [-1, 1]; powers (n,)."""
    def add_triangles(self, vertices: ArrayLike, powers: ArrayLike, two_sided: bool = False) -> int:
        """vertices (n, 3, 3) or (n, 9); emitting on the side of (p1 - p0) x (p2 - p0)."""
    def add_quads(
        self,
        corners: ArrayLike,
        edges_u: ArrayLike,
        edges_v: ArrayLike,
        powers: ArrayLike,
        two_sided: bool = False,
    ) -> int:
        """corner + s edge_u + t edge_v, each (n, 3); emitting on the side of edge_u x edge_v."""
    def add_disks(
        self,
        centers: ArrayLike,
        normals: ArrayLike,
        radii: ArrayLike,
        powers: ArrayLike,
        two_sided: bool = False,
    ) -> int:
        """centers, normals (n, 3); radii (n,); powers (n,)."""

class LightTree:
    """The global light tree over a scene's emitters; immutable, shared."""

    def __init__(self, emitters: Emitters, heuristic: str = "sarh") -> None:
        """heuristic: 'sarh', 'sah', 'saoh' or 'balanced'."""
    @property
    def emitter_count(self) -> int: ...
    @property
    def depth(self) -> int: ...
    @property
    def total_power(self) -> float: ...
    @property
    def bounds(self) -> Tuple[Tuple[float, float, float], Tuple[float, float, float]]: ...
    @property
    def nbytes(self) -> int: ...
    def to_bytes(self) -> bytes:
        """What a farm sends its workers once (pickling goes through it)."""
    @staticmethod
    def from_bytes(data: bytes) -> "LightTree": ...

class _Guide:
    """What every guide has (not a class of the module)."""

    def refine(self) -> RefineOutcome:
        """Ends a training iteration."""
    def clear_records(self) -> None: ...
    def merge(self, other: "_Guide") -> None:
        """Adds a copy's records; ValueError unless it is a copy of one guide."""
    def to_bytes(self) -> bytes: ...
    @property
    def iteration(self) -> int: ...
    @property
    def dropped_records(self) -> DroppedRecords: ...
    @property
    def nbytes(self) -> int: ...
    def lookup(self, positions: ArrayLike) -> I64:
        """The cell of each position (n, 3)."""

class _LightGuide(_Guide):
    @property
    def light_count(self) -> int:
        """Emitters, then unbounded lights."""
    def sample(
        self, positions: ArrayLike, u: ArrayLike, normals: Optional[ArrayLike] = None
    ) -> Tuple[I64, F32]:
        """(lights, pmfs) from u (n,) in [0, 1); -1 and 0 where nothing can be chosen."""
    def pmf(self, positions: ArrayLike, lights: ArrayLike, normals: Optional[ArrayLike] = None) -> F32:
        """Exactly the pmf `sample` returns for each light."""
    def record_light(
        self,
        positions: ArrayLike,
        lights: ArrayLike,
        values: ArrayLike,
        normals: Optional[ArrayLike] = None,
    ) -> int:
        """NEE records (contribution / pmf, >= 0); returns how many were taken."""

class _DirectionGuide(_Guide):
    def sample_direction(self, positions: ArrayLike, u: ArrayLike) -> Tuple[F32, F32]:
        """(directions (n, 3), solid-angle pdfs (n,)) from u (n, 2) in [0, 1)."""
    def direction_pdf(self, positions: ArrayLike, directions: ArrayLike) -> F32: ...
    def bsdf_fraction(self, positions: ArrayLike) -> F32: ...
    def record_radiance(
        self, positions: ArrayLike, directions: ArrayLike, radiance: ArrayLike, pdfs: ArrayLike
    ) -> int:
        """PPG's records; returns how many were taken."""

class Glt(_LightGuide):
    """The Guiding Light Tree."""

    def __init__(
        self,
        tree: LightTree,
        bounds: ArrayLike,
        *,
        sigma: Optional[float] = None,
        alpha: Optional[float] = None,
        min_records: Optional[int] = None,
        visibility: Optional[bool] = None,
        unbounded_lights: Optional[int] = None,
        unbounded_probability: Optional[float] = None,
        deterministic: Optional[bool] = None,
        spatial_threshold: Optional[float] = None,
        max_bytes: Optional[int] = None,
        light_filter: Optional[str] = None,
    ) -> None:
        """bounds: (lower, upper); a keyword left out (or None) is the crate's default."""
    @staticmethod
    def from_bytes(data: bytes, tree: LightTree) -> "Glt": ...
    def __copy__(self) -> "Glt": ...
    def __deepcopy__(self, memo: object) -> "Glt": ...

class SdTree(_DirectionGuide):
    """Practical Path Guiding's SD-tree."""

    def __init__(
        self,
        bounds: ArrayLike,
        *,
        improved: Optional[bool] = None,
        spatial_threshold: Optional[float] = None,
        max_bytes: Optional[int] = None,
        rho: Optional[float] = None,
        max_depth: Optional[int] = None,
        spatial_filter: Optional[str] = None,
        directional_filter: Optional[str] = None,
        bsdf_fraction: Optional[float] = None,
        learn_bsdf_fraction: Optional[bool] = None,
        fraction_steps: Optional[int] = None,
        deterministic: Optional[bool] = None,
    ) -> None: ...
    @staticmethod
    def from_bytes(data: bytes) -> "SdTree": ...
    def __copy__(self) -> "SdTree": ...
    def __deepcopy__(self, memo: object) -> "SdTree": ...

class GuidingField(_LightGuide, _DirectionGuide):
    """The SD-tree and the GLT in one spatial tree."""

    def __init__(
        self,
        tree: LightTree,
        bounds: ArrayLike,
        *,
        improved: Optional[bool] = None,
        spatial_threshold: Optional[float] = None,
        max_bytes: Optional[int] = None,
        rho: Optional[float] = None,
        max_depth: Optional[int] = None,
        spatial_filter: Optional[str] = None,
        directional_filter: Optional[str] = None,
        bsdf_fraction: Optional[float] = None,
        learn_bsdf_fraction: Optional[bool] = None,
        fraction_steps: Optional[int] = None,
        sigma: Optional[float] = None,
        alpha: Optional[float] = None,
        min_records: Optional[int] = None,
        visibility: Optional[bool] = None,
        unbounded_lights: Optional[int] = None,
        unbounded_probability: Optional[float] = None,
        light_filter: Optional[str] = None,
        deterministic: Optional[bool] = None,
    ) -> None: ...
    @staticmethod
    def from_bytes(data: bytes, tree: LightTree) -> "GuidingField": ...
    def __copy__(self) -> "GuidingField": ...
    def __deepcopy__(self, memo: object) -> "GuidingField": ...
