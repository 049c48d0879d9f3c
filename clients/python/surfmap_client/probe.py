"""The rig's side of the API, typed: probe commands, leases, submission
results, failure kinds, and the checks and conversions of a measured trace.

A measured trace is the client's ``Trace`` record (records.py): ``t`` (N,) s,
``xyz`` (N, 3) tip position in mm and ``f`` (N, 3) force BY the surface ON
the probe in N, both in the OBJECT frame (the frame of the uploaded mesh),
``phase`` (N,) ``Phase`` values: forward samples, then the pause, then the
reverse pass. ``measured_trace`` builds one for a command; ``check_trace``
says what is wrong with one before anything is sent.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from datetime import datetime, timezone
from typing import Optional, Sequence, Union

import numpy as np

from . import conversion as conv
from . import records as r
from ._stubs import pb
from .errors import invalid_argument

# The paper's drag, used when a command carries zero probe parameters (as the
# C++ rig does).
DEFAULT_SEGMENT_LENGTH_MM = 20.0
DEFAULT_SPEED_MM_S = 10.0
DEFAULT_NORMAL_FORCE_N = 5.0


class FailureKind(str, enum.Enum):
    """Why a rig could not measure a command (the API's FailureKind)."""

    TRANSIENT = "transient"      # try again later: the site is re-queued up to the job's max_retries
    UNREACHABLE = "unreachable"  # this rig can never reach the site: it is given up at once


FAILURE_KIND_TO_PROTO = {FailureKind.TRANSIENT: pb.FAILURE_KIND_TRANSIENT,
                         FailureKind.UNREACHABLE: pb.FAILURE_KIND_UNREACHABLE}

PHASE_NAMES = {r.Phase.FORWARD: "fwd", r.Phase.PAUSE: "pause", r.Phase.REVERSE: "rev"}
PHASE_FROM_NAME = {name: phase for phase, name in PHASE_NAMES.items()}


@dataclass(frozen=True)
class ProbeCommand:
    """One probe to execute: drag over ``probe.segment_length_mm`` centred on
    ``position`` along ``drag_direction`` (forward pass), pause, drag back,
    pressing with ``probe.normal_force_n`` at ``probe.speed_mm_s``.

    Positions in mm and unit vectors, all in the object frame (the uploaded
    mesh's). ``normal`` points out of the surface. A trace answered after
    ``lease_deadline`` may be refused (the command went to another rig).
    """

    command_id: int
    job_id: int
    level: int
    vertex: int
    position: np.ndarray          # (3,) mm
    normal: np.ndarray            # (3,) unit, outward
    drag_direction: np.ndarray    # (3,) unit tangent, forward pass
    probe: r.ProbeParameters      # zero parameters replaced by the paper's 20 mm, 10 mm/s, 5 N
    attempt: int                  # 1 = the site's first command
    lease_deadline: Optional[datetime]
    # The same command in this rig's base frame, when the rig is registered to
    # the object (``SurfmapClient.set_rig_registration``); else None.
    rig_frame: Optional["RigFrameCommand"] = None

    @property
    def lease_deadline_unix_ms(self) -> int:
        """The lease deadline in ms since the Unix epoch (0 when unknown)."""
        if self.lease_deadline is None:
            return 0
        return int(round(self.lease_deadline.timestamp() * 1000))


@dataclass(frozen=True)
class RigFrameCommand:
    """A command in a rig's base frame (docs/trace-format.md, "Frames"):
    contact points in mm, unit vectors; ``tool_centre_path`` (K, 3) is the
    tool centre (contact + ``tip_radius_mm`` x outward normal) along the
    forward pass, ~1 mm apart, start to end."""

    registration_id: int
    registration_version: int
    position: np.ndarray
    normal: np.ndarray
    drag_direction: np.ndarray
    start: np.ndarray
    end: np.ndarray
    tool_centre_path: np.ndarray
    tip_radius_mm: float
    sensor_rotation_wxyz: np.ndarray


@dataclass(frozen=True)
class Lease:
    """LeaseCommand's answer: a command, or when to ask again, or the job's end."""

    command: Optional[ProbeCommand]   # None when nothing is ready or the job finished
    retry_after_s: float              # when command is None and the job goes on: ask again after this
    job_finished: bool                # the job is completed or cancelled: stop


@dataclass(frozen=True)
class SubmitResult:
    """SubmitTrace's answer: the trace is stored (this rig's samples, durably)."""

    sample: r.Sample                  # the fitted sample
    already_accepted: bool            # an identical earlier submission had got through
    progress: r.JobProgress
    next: Optional[Lease]             # the next lease, when asked for with lease_next


def probe_command(m) -> ProbeCommand:
    """pb.ProbeCommand -> ProbeCommand."""
    p = m.probe
    probe = r.ProbeParameters(p.segment_length_mm or DEFAULT_SEGMENT_LENGTH_MM,
                              p.speed_mm_s or DEFAULT_SPEED_MM_S,
                              p.normal_force_n or DEFAULT_NORMAL_FORCE_N)
    deadline = m.lease_deadline.ToDatetime(tzinfo=timezone.utc) if m.HasField("lease_deadline") else None
    vec = lambda v: np.array([v.x, v.y, v.z], dtype=float)  # noqa: E731
    rig_frame = None
    if m.HasField("rig_frame"):
        f = m.rig_frame
        path = np.array([[p.x, p.y, p.z] for p in f.tool_centre_path], dtype=float).reshape(-1, 3)
        q = f.sensor_rotation
        rig_frame = RigFrameCommand(f.registration_id, f.registration_version, vec(f.position), vec(f.normal),
                                    vec(f.drag_direction), vec(f.start), vec(f.end), path, f.tip_radius_mm,
                                    np.array([q.w, q.x, q.y, q.z], dtype=float))
    return ProbeCommand(m.command_id, m.job_id, m.site.level, m.site.vertex, vec(m.position), vec(m.normal),
                        vec(m.drag_direction), probe, m.attempt, deadline, rig_frame)


def lease(m) -> Lease:
    """pb.LeaseCommandResponse -> Lease."""
    command = probe_command(m.command) if m.HasField("command") and m.command.command_id != 0 else None
    retry = m.retry_after.seconds + m.retry_after.nanos * 1e-9 if m.HasField("retry_after") else 0.0
    return Lease(command, retry, m.job_finished)


def submit_result(m) -> SubmitResult:
    """pb.SubmitTraceResponse -> SubmitResult."""
    return SubmitResult(conv.sample(m.sample), m.already_accepted, conv.job_progress(m.progress),
                        lease(m.next) if m.HasField("next") else None)


def measured_trace(command: ProbeCommand, t: Sequence[float], xyz: Union[np.ndarray, Sequence[Sequence[float]]],
                   f: Union[np.ndarray, Sequence[Sequence[float]]],
                   phase: Sequence[Union[int, str, r.Phase]]) -> r.Trace:
    """A measured trace for ``command`` as the client's ``Trace`` record.

    ``t`` (N,) s; ``xyz`` (N, 3) tip position, mm, object frame; ``f`` (N, 3)
    force BY the surface ON the probe, N, object frame; ``phase`` (N,) as
    ``Phase`` values or the CSV names "fwd"/"pause"/"rev". The record is not
    checked here (``check_trace`` and ``submit`` do that).
    """
    def phase_value(p: Union[int, str, r.Phase]) -> int:
        if isinstance(p, str):
            if p not in PHASE_FROM_NAME:
                raise invalid_argument("measured_trace", f"phase {p!r} is not 'fwd', 'pause' or 'rev'")
            return int(PHASE_FROM_NAME[p])
        return int(p)

    phases = np.array([phase_value(p) for p in phase], dtype=np.int8)
    return r.Trace(trace_id=0, command_id=command.command_id, job_id=command.job_id,
                   t=np.asarray(t, dtype=float), xyz=np.asarray(xyz, dtype=float), f=np.asarray(f, dtype=float),
                   phase=phases)


def check_trace(trace: r.Trace, method: str = "SubmitTrace") -> None:
    """Raises SurfmapError(INVALID_ARGUMENT) naming what is wrong with a
    measured trace: shapes, non-finite values, time not strictly increasing,
    an unknown phase, phases out of order (forward, pause, reverse), or no
    forward or no reverse sample. The server would refuse such a trace; the
    spool could not keep it as the CSV it writes."""
    t = np.asarray(trace.t)
    xyz = np.asarray(trace.xyz)
    f = np.asarray(trace.f)
    phase = np.asarray(trace.phase)
    n = t.shape[0] if t.ndim == 1 else -1
    if t.ndim != 1 or n == 0:
        raise invalid_argument(method, f"trace: t must have shape (N,) with N >= 1, got {t.shape}")
    for name, array in (("xyz", xyz), ("f", f)):
        if array.shape != (n, 3):
            raise invalid_argument(method, f"trace: {name} must have shape ({n}, 3) like t, got {array.shape}")
    if phase.shape != (n,):
        raise invalid_argument(method, f"trace: phase must have shape ({n},) like t, got {phase.shape}")
    for name, array in (("t", t), ("xyz", xyz), ("f", f)):
        if not np.issubdtype(array.dtype, np.number):
            raise invalid_argument(method, f"trace: {name} must hold numbers, got dtype {array.dtype}")
        bad = np.argwhere(~np.isfinite(array))
        if bad.size:
            raise invalid_argument(method, f"trace: {name}[{', '.join(str(i) for i in bad[0])}] is not finite")
    steps = np.diff(t)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0)) + 1
        raise invalid_argument(method, f"trace: t[{i}] = {t[i]!r} does not increase (t[{i - 1}] = {t[i - 1]!r})")
    valid = np.isin(phase, [r.Phase.FORWARD, r.Phase.PAUSE, r.Phase.REVERSE])
    if not np.all(valid):
        i = int(np.argmin(valid))
        raise invalid_argument(method, f"trace: phase[{i}] = {phase[i]!r} is not FORWARD, PAUSE or REVERSE")
    back = np.diff(phase.astype(int)) < 0
    if np.any(back):
        i = int(np.argmax(back)) + 1
        raise invalid_argument(method, f"trace: phase[{i}] is {r.Phase(int(phase[i])).name} after "
                                       f"{r.Phase(int(phase[i - 1])).name}: phases must run forward, pause, reverse")
    if not np.any(phase == r.Phase.FORWARD):
        raise invalid_argument(method, "trace: no forward sample")
    if not np.any(phase == r.Phase.REVERSE):
        raise invalid_argument(method, "trace: no reverse sample")


def trace_samples(trace: r.Trace):
    """Trace -> pb.TraceSamples (columns as stored, bit-exact)."""
    xyz = np.asarray(trace.xyz, dtype=float)
    f = np.asarray(trace.f, dtype=float)
    return pb.TraceSamples(t=np.asarray(trace.t, dtype=float).tolist(), x=xyz[:, 0].tolist(), y=xyz[:, 1].tolist(),
                           z=xyz[:, 2].tolist(), fx=f[:, 0].tolist(), fy=f[:, 1].tolist(), fz=f[:, 2].tolist(),
                           phases=[int(p) for p in trace.phase])


def failure_kind(kind: Union[FailureKind, str], method: str = "ReportFailure") -> FailureKind:
    """``kind`` as a FailureKind; INVALID_ARGUMENT naming the accepted values otherwise."""
    try:
        return FailureKind(kind)
    except ValueError:
        raise invalid_argument(method, f"kind must be 'transient' or 'unreachable', got {kind!r}") from None


def finite_positive(value: float, name: str, method: str) -> float:
    if value is None or not math.isfinite(value) or value <= 0:
        raise invalid_argument(method, f"{name} must be a positive number, got {value!r}")
    return float(value)
