"""Typed records returned by the client: plain dataclasses and numpy arrays.

Units follow the API: lengths in mm, forces in N, speeds in mm/s, times in s
(timestamps as timezone-aware ``datetime``). Per-vertex and per-sample values
are numpy arrays; an unknown map value is NaN. The records are frozen: they
are snapshots of what the server answered.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from datetime import datetime
from typing import Any, Dict, Optional, Tuple

import numpy as np


class Property(str, enum.Enum):
    """What a job maps."""

    FRICTION = "friction"
    ROUGHNESS = "roughness"
    BOTH = "both"


class SamplingMode(str, enum.Enum):
    """How a job chooses its sites."""

    BOUNDARY = "boundary"        # the default: goes looking for boundaries (drags across them)
    ADAPTIVE = "adaptive"        # the paper's threshold rule (the only mode that reads threshold)
    UNIFORM = "uniform"          # every vertex of coarsest_level, nothing more
    UNCERTAINTY = "uncertainty"  # next site where the harmonic map is most uncertain (needs a budget)


class ArMethod(str, enum.Enum):
    """AR estimator of a refit."""

    BURG = "burg"
    LEAST_SQUARES = "ls"


class JobState(enum.IntEnum):
    """Values equal the proto's JobState numbers."""

    UNSPECIFIED = 0
    RUNNING = 1
    PAUSED = 2
    COMPLETED = 3
    CANCELLED = 4

    @property
    def finished(self) -> bool:
        return self in (JobState.COMPLETED, JobState.CANCELLED)


class SiteState(enum.IntEnum):
    """Values equal the proto's SiteState numbers."""

    UNSPECIFIED = 0
    PENDING = 1
    ISSUED = 2
    MEASURED = 3
    FAILED = 4
    SKIPPED = 5


class Phase(enum.IntEnum):
    """Phase of a trace sample; values equal the proto's Phase numbers."""

    UNSPECIFIED = 0
    FORWARD = 1
    PAUSE = 2
    REVERSE = 3


@dataclass(frozen=True)
class Provenance:
    """What a lab keeps with its data (objects, jobs, traces), given at creation.

    Bounded by the server: each named field and extra value at most 200
    characters on one line, notes at most 4000, at most 32 extra keys of
    letters, digits, '_', '.' and '-'."""

    operator: str = ""
    specimen: str = ""
    probe_tip: str = ""
    sensor: str = ""
    notes: str = ""
    extra: Dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class ImportInfo:
    """Where an imported trace came from (``import_trace``)."""

    source: str
    file_name: str
    file_sha256: str
    recorded: Optional[datetime]
    imported: Optional[datetime]


@dataclass(frozen=True)
class RejectedTrace:
    """A trace refused as implausible (a rig's, or an import: ``rig_id`` is then its source)."""

    rejected_trace_id: int
    command_id: int
    job_id: int
    rig_id: str
    check: str                    # offset, surface, length, direction, normal, force, friction, ...
    message: str
    sample_count: int
    received: Optional[datetime]


@dataclass(frozen=True)
class ObjectInfo:
    object_id: int
    name: str
    format: str                   # "obj" or "ply"
    control_vertex_count: int
    control_face_count: int
    created: Optional[datetime]
    provenance: Provenance = field(default_factory=Provenance)
    surface: str = "control_mesh"  # or "facets": the flat triangles are the surface


@dataclass(frozen=True)
class Mesh:
    """One subdivision level of an object: limit positions and normals."""

    object_id: int
    level: int
    positions: np.ndarray         # (N, 3) mm
    normals: np.ndarray           # (N, 3) unit, outward
    triangles: np.ndarray         # (M, 3) int vertex indices


@dataclass(frozen=True)
class ProbeParameters:
    segment_length_mm: float
    speed_mm_s: float
    normal_force_n: float


@dataclass(frozen=True)
class JobSpec:
    """A job's settings as the server applied them (its defaults filled in)."""

    object_id: int
    property: Property
    mode: SamplingMode
    coarsest_level: int
    finest_level: int             # the plan's finest level
    threshold: float
    budget: int                   # 0 = unlimited
    probe: ProbeParameters
    seed: int
    max_retries: int
    lease_s: float
    map_level: int = -1           # the level the map is evaluated on (>= finest_level)


@dataclass(frozen=True)
class LevelProgress:
    level: int
    measured: int
    pending: int
    issued: int
    failed: int
    leased: Optional[int] = None  # of `issued`, held by a rig; None where not counted


@dataclass(frozen=True)
class JobProgress:
    measured: int
    pending: int
    issued: int
    failed: int
    skipped: int
    budget_left: int              # -1 = unlimited
    complete: bool
    levels: Tuple[LevelProgress, ...]
    # Of `issued` (queued for a rig or leased), the commands a rig holds with
    # an unexpired lease; None where the server does not count it (the reply
    # to a submitted trace).
    leased: Optional[int] = None


@dataclass(frozen=True)
class JobInfo:
    job_id: int
    spec: JobSpec
    state: JobState
    progress: JobProgress
    created: Optional[datetime]
    updated: Optional[datetime]
    provenance: Provenance = field(default_factory=Provenance)


@dataclass(frozen=True)
class PlanSite:
    level: int
    vertex: int
    state: SiteState
    attempts: int
    failure_reason: str
    position: np.ndarray          # (3,) mm


@dataclass(frozen=True)
class Plan:
    job_id: int
    progress: JobProgress
    sites: Tuple[PlanSite, ...]


@dataclass(frozen=True)
class FrictionEstimate:
    mu: float
    mu_std: float
    mu_median: float
    normal: np.ndarray            # (3,) mean normal over the window
    pair_count: int
    window_start_mm: float        # the data window, along the forward path from its first sample
    window_end_mm: float
    # get_sample(..., include_series=True) only, else empty: each pair's arc
    # length (mm) and mu = tan(theta/2), as the server's estimator computed them.
    pair_s_mm: np.ndarray = field(default_factory=lambda: np.zeros(0))
    pair_mu: np.ndarray = field(default_factory=lambda: np.zeros(0))


@dataclass(frozen=True)
class RoughnessEstimate:
    ar_coefficients: Tuple[float, ...]   # a1..ap
    ar_stderr: Tuple[float, ...]
    sigma: float                         # innovation std, N
    stationary: bool
    reflection: Tuple[float, ...]
    acf_decay_mm: float
    dominant_wavelength_mm: float        # 0 when there is no oscillation
    below_noise_floor: bool
    # get_sample(..., include_series=True) only, else empty: the measured ACF
    # at lags 0, 1, ... grid steps of grid_step_mm.
    acf: np.ndarray = field(default_factory=lambda: np.zeros(0))
    grid_step_mm: float = 0.0

    @property
    def a1(self) -> float:
        return self.ar_coefficients[0] if len(self.ar_coefficients) > 0 else float("nan")

    @property
    def a2(self) -> float:
        return self.ar_coefficients[1] if len(self.ar_coefficients) > 1 else float("nan")


@dataclass(frozen=True)
class DragPiece:
    """A stretch of one drag over one material (between detected changes)."""

    start_mm: float                # along the forward path (the frame of window_start_mm)
    end_mm: float
    starts_at_change: bool
    ends_at_change: bool
    mu: float
    mu_std: float                  # spread of the per-pair mu
    mu_se: float                   # standard error of mu
    pair_count: int
    roughness_state: str           # "fitted", "too_short", "fit_failed"
    roughness_note: str
    roughness: Optional["RoughnessEstimate"]  # when fitted


@dataclass(frozen=True)
class Fit:
    fit_id: int
    version: int                  # 1 = on arrival, 2.. = refits
    estimator: str
    estimator_version: str
    options_json: str
    friction: FrictionEstimate
    roughness: RoughnessEstimate
    noise_std: float              # sensor noise seen in the pause, N
    change_s_mm: Tuple[float, ...] = ()     # material changes found inside the drag
    pieces: Tuple[DragPiece, ...] = ()      # the drag's pieces, in path order


@dataclass(frozen=True)
class Sample:
    """One measured site: its drag and the fit of its trace."""

    trace_id: int
    command_id: int
    job_id: int
    level: int
    vertex: int
    position: np.ndarray          # (3,) the site on the surface, mm
    drag_direction: np.ndarray    # (3,) unit, forward pass
    segment_length_mm: float
    fit: Optional[Fit]
    received: Optional[datetime]
    rig_id: str = ""              # the rig that measured it ("" from servers before the field)
    provenance: Provenance = field(default_factory=Provenance)
    import_info: Optional[ImportInfo] = None  # set for a trace imported from a file


@dataclass(frozen=True)
class JobEvent:
    """One entry of a job's event log (``list_job_events``), oldest first.

    ``kind``: ``job_created``, ``job_state`` (``from``, ``to``),
    ``trace_accepted`` (``command_id``, ``level``, ``vertex``, ``mu``,
    ``rig``) or ``probe_failed`` (``command_id``, ``reason``, ``kind``
    transient/unreachable, ``rig``, ``will_retry``); ``detail`` holds those
    fields, parsed from ``detail_json``. A detail that is not a JSON object
    leaves ``detail`` None and says why in ``detail_error``.
    """

    event_id: int                 # increases with every event: the cursor for the next call
    job_id: int
    time: Optional[datetime]
    kind: str
    detail: Optional[Dict[str, Any]]
    detail_json: str
    detail_error: str = ""


@dataclass(frozen=True)
class MapRegionPiece:
    """One drag piece behind a region (GetMap's ``MapRegion.pieces``):
    ``trace_id`` and ``fit_piece`` name the sample and which of its fit's
    pieces; ``start_mm``..``end_mm`` its stretch along the drag (a part of
    the fit piece when ``split_by_map``); ``mu_se`` as the map weighs it;
    ``mu_weight`` its share of the material's mu (0 unless ``in_mu``)."""

    trace_id: int
    fit_piece: int
    start_mm: float
    end_mm: float
    split_by_map: bool
    mu: float
    mu_se: float
    effective_pairs: float
    in_mu: bool
    mu_weight: float


@dataclass(frozen=True)
class MapRegion:
    """A region of the map: drag pieces that touch and are alike. Regions
    with the same ``material`` are alike wherever they lie and report the
    material's estimates (``mu``, ``mu_se``, roughness); ``own_mu`` and
    ``own_mu_se`` are the region's own pieces'."""

    region: int
    mu: float
    mu_se: float
    mu_spread: float
    piece_count: int
    roughness_piece_count: int
    reflection: Tuple[float, ...]        # empty without roughness
    ar_coefficients: Tuple[float, ...]   # a1..ap, empty without roughness
    sigma: float                         # N; 0 without roughness
    area_mm2: float
    material: int = 0
    own_mu: float = 0.0
    own_mu_se: float = 0.0
    pieces: Tuple[MapRegionPiece, ...] = ()


@dataclass(frozen=True)
class SurfaceMap:
    """The map at one subdivision level, as arrays.

    Per vertex (N = vertex_count): ``mu``, ``mu_uncertainty`` (standard
    deviation), ``sigma`` (roughness innovation std, N), ``a1``, ``a2`` (0
    where the region has no roughness), ``region`` (index into ``regions``,
    -1 without data) and ``boundary_probability``. ``positions``/``normals``/``triangles`` are present when
    the map was fetched with its mesh, else None. Per measured sample (S):
    ``sample_positions`` (S, 3), ``sample_drag_directions`` (S, 3),
    ``sample_sites`` (S, 2) as (level, vertex), ``sample_mu`` (S,), and the
    full records in ``samples``.
    """

    job_id: int
    level: int
    vertex_count: int
    mu: np.ndarray
    mu_uncertainty: np.ndarray
    sigma: np.ndarray
    a1: np.ndarray
    a2: np.ndarray
    samples: Tuple[Sample, ...]
    region: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    boundary_probability: np.ndarray = field(default_factory=lambda: np.zeros(0))
    regions: Tuple[MapRegion, ...] = ()
    positions: Optional[np.ndarray] = None
    normals: Optional[np.ndarray] = None
    triangles: Optional[np.ndarray] = None
    sample_positions: np.ndarray = field(init=False, repr=False)
    sample_drag_directions: np.ndarray = field(init=False, repr=False)
    sample_sites: np.ndarray = field(init=False, repr=False)
    sample_mu: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        s = self.samples
        set_ = object.__setattr__  # frozen: derived arrays are set once, here
        set_(self, "sample_positions", np.array([x.position for x in s], dtype=float).reshape(len(s), 3))
        set_(self, "sample_drag_directions",
             np.array([x.drag_direction for x in s], dtype=float).reshape(len(s), 3))
        set_(self, "sample_sites", np.array([(x.level, x.vertex) for x in s], dtype=np.int64).reshape(len(s), 2))
        set_(self, "sample_mu",
             np.array([x.fit.friction.mu if x.fit is not None else np.nan for x in s], dtype=float))


@dataclass(frozen=True)
class MapQuery:
    """QueryMap's answer: one row per query point, in order."""

    surface_points: np.ndarray    # (N, 3) the query points projected to the surface
    normals: np.ndarray           # (N, 3)
    distance_mm: np.ndarray       # (N,) from each query point to the surface
    mu: np.ndarray
    mu_uncertainty: np.ndarray
    sigma: np.ndarray
    a1: np.ndarray
    a2: np.ndarray
    region: Optional[np.ndarray] = None  # (N,) MapRegion index, -1 without data


@dataclass(frozen=True)
class Trace:
    """A raw drag trace, bit-exact as stored.

    ``t`` (N,) s; ``xyz`` (N, 3) tip position, mm; ``f`` (N, 3) force BY the
    surface ON the probe, N; ``phase`` (N,) int8 with ``Phase`` values.
    """

    trace_id: int
    command_id: int
    job_id: int
    t: np.ndarray
    xyz: np.ndarray
    f: np.ndarray
    phase: np.ndarray

    @property
    def forward(self) -> np.ndarray:
        """Boolean mask of the forward pass."""
        return self.phase == Phase.FORWARD

    @property
    def pause(self) -> np.ndarray:
        return self.phase == Phase.PAUSE

    @property
    def reverse(self) -> np.ndarray:
        return self.phase == Phase.REVERSE

    def to_csv(self, path: str) -> None:
        """Writes the project's drag-trace CSV (``surfmap fit`` reads it)."""
        names = {Phase.FORWARD: "fwd", Phase.PAUSE: "pause", Phase.REVERSE: "rev"}
        with open(path, "w", encoding="ascii") as out:
            out.write(f"# trace {self.trace_id} of job {self.job_id}, command {self.command_id}\n")
            out.write("t,x,y,z,fx,fy,fz,phase\n")
            for i in range(len(self.t)):
                # repr() round-trips a double exactly.
                values = [self.t[i], *self.xyz[i], *self.f[i]]
                out.write(",".join(repr(float(v)) for v in values))
                out.write("," + names.get(Phase(int(self.phase[i])), "unspecified") + "\n")


@dataclass(frozen=True)
class JobUpdate:
    """One message of the WatchJob stream."""

    job: JobInfo
    # The newest accepted sample as of this update (updates are coalesced: list_samples has them all).
    latest_sample: Optional[Sample]
    map: Optional[SurfaceMap]         # finest level, when watched with include_map


@dataclass(frozen=True)
class RefitResult:
    fit_version: int              # the new version every refitted trace now has
    refitted: int
    failed: int
