"""The contact force of a drag trace in the drag's own frame.

World components mislead on curved objects: a drag along y puts the friction
in fy, a vertical drag puts it in fz beside the normal force. In the drag
frame the normal force, the friction along the drag and the lateral force
read the same whatever way the drag runs. The definition is the dashboard's
(``clients/dashboard/public/drag_frame.js``), per sample:

- ``s``: position along the forward path, mm: the forward pass's arc length;
  a reverse sample takes the arc length of its nearest point on the forward
  path (the reverse pass retraces it).
- ``m``: the FORWARD direction of motion at s, the unit chord of the forward
  path from s - 1 mm to s + 1 mm (smooths the position noise); within 1 mm of
  an end, extrapolated linearly from the chords 1 and 2 mm from it. Both
  passes use the same m, so friction has opposite signs in the two passes.
- ``n``: the surface normal at s, the differential method's local pair normal
  unit(f/|f| + r/|r|) of the forward and reverse forces at the same s
  (friction cancels in the sum), averaged over s +- 1 mm and made
  perpendicular to m; the fit's mean normal where the passes give no pair.
- ``l = n x m`` (lateral).

Components of the force F (BY the surface ON the probe): ``normal = F.n``
(> 0: pushes the probe out), ``along = F.m`` (forward ~ -mu N, reverse ~
+mu N), ``lateral = F.l`` (~ 0 for Coulomb friction; friction deflected
sideways shows here with opposite signs in the two passes, while a sideways
force the same in both passes cannot be told from a tilted normal).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence, Union

import numpy as np

from .records import Trace
from .trace_analysis import arc_length, project_onto_polyline

MOTION_HALF_WINDOW_MM = 1.0
NORMAL_HALF_WINDOW_MM = 1.0


@dataclass(frozen=True)
class DragFrameForces:
    """Per sample of the trace (NaN for the pause): position and force components."""

    s: np.ndarray             # (N,) mm along the forward path
    normal: np.ndarray        # (N,) N
    along: np.ndarray         # (N,) N, along the forward direction of motion
    lateral: np.ndarray       # (N,) N
    path_length_mm: float
    normal_source: str        # "pairs" or "fit"

    def window_friction(self, trace: Trace, start_mm: float, end_mm: float) -> float:
        """(mean along_rev - mean along_fwd) / (mean normal_fwd + mean normal_rev) over the window:
        mu for Coulomb friction, as the plot shows it. ValueError when a pass has no sample there."""
        inside = (self.s >= start_mm) & (self.s <= end_mm)
        fwd, rev = inside & trace.forward, inside & trace.reverse
        if not fwd.any() or not rev.any():
            raise ValueError(f"trace {trace.trace_id}: no forward or reverse sample in {start_mm}..{end_mm} mm")
        return float((self.along[rev].mean() - self.along[fwd].mean())
                     / (self.normal[fwd].mean() + self.normal[rev].mean()))


def _unit_rows(v: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(length > 0, v / length, np.nan)


def _interp_rows(x_query: np.ndarray, x: np.ndarray, values: np.ndarray) -> np.ndarray:
    return np.column_stack([np.interp(x_query, x, values[:, k]) for k in range(values.shape[1])])


def drag_frame_forces(trace: Trace,
                      fallback_normal: Optional[Union[np.ndarray, Sequence[float]]] = None) -> DragFrameForces:
    """The trace's forces in the drag frame. ``fallback_normal`` (e.g. the fit's
    ``friction.normal``) is used only when the passes give no pair normal.
    ValueError naming the problem for a trace that cannot be framed."""
    fwd, rev = trace.forward, trace.reverse
    if fwd.sum() < 2 or rev.sum() < 2:
        raise ValueError(f"trace {trace.trace_id}: needs a forward and a reverse pass of 2+ samples "
                         f"(has {int(fwd.sum())} and {int(rev.sum())})")
    if not (np.all(np.isfinite(trace.xyz)) and np.all(np.isfinite(trace.f))):
        raise ValueError(f"trace {trace.trace_id}: positions or forces are not all finite")
    points = trace.xyz[fwd]
    path_s = arc_length(points)
    length = float(path_s[-1])
    if not length > 0:
        raise ValueError(f"trace {trace.trace_id}: the forward pass does not move")

    h = MOTION_HALF_WINDOW_MM

    def chord(s: np.ndarray) -> np.ndarray:
        ahead = _interp_rows(np.minimum(length, s + h), path_s, points)
        behind = _interp_rows(np.maximum(0.0, s - h), path_s, points)
        return _unit_rows(ahead - behind)

    def motion(s: np.ndarray) -> np.ndarray:
        if length < 4 * h:
            return np.tile(chord(np.array([length / 2])), (len(s), 1))
        m = chord(s)
        for near_end, inner, nxt in ((s < h, h, 2 * h), (s > length - h, length - h, length - 2 * h)):
            if near_end.any():
                a = chord(np.array([inner]))[0]
                b = chord(np.array([nxt]))[0]
                k = (np.abs(s[near_end] - inner) / h)[:, None]
                m[near_end] = _unit_rows(a + (a - b) * k)
        if not np.all(np.isfinite(m)):
            raise ValueError(f"trace {trace.trace_id}: no direction of motion somewhere (the path turns back)")
        return m

    s_all = np.full(len(trace.t), np.nan)
    s_all[fwd] = path_s
    s_rev, _ = project_onto_polyline(trace.xyz[rev], points)
    s_all[rev] = s_rev

    # Pair normals at the forward samples the reverse pass covers, then s +- 1 mm means.
    order = np.argsort(s_rev, kind="stable")
    rev_s, rev_f = s_rev[order], _unit_rows(trace.f[rev][order])
    covered = (path_s >= rev_s[0]) & (path_s <= rev_s[-1])
    pair_s = path_s[covered]
    pair_n = _unit_rows(_unit_rows(trace.f[fwd][covered]) + _unit_rows(_interp_rows(pair_s, rev_s, rev_f)))
    good = np.all(np.isfinite(pair_n), axis=1)
    pair_s, pair_n = pair_s[good], pair_n[good]
    if len(pair_s) >= 2:
        cumulative = np.vstack([np.zeros(3), np.cumsum(pair_n, axis=0)])
        lo = np.searchsorted(pair_s, pair_s - NORMAL_HALF_WINDOW_MM, side="left")
        hi = np.searchsorted(pair_s, pair_s + NORMAL_HALF_WINDOW_MM, side="right")
        normal_s, normal_v, source = pair_s, _unit_rows(cumulative[hi] - cumulative[lo]), "pairs"
    else:
        if fallback_normal is None or not np.linalg.norm(fallback_normal) > 0:
            raise ValueError(f"trace {trace.trace_id}: the passes give no pair normal and no fit normal was given")
        fallback = _unit_rows(np.asarray(fallback_normal, dtype=float))
        normal_s, normal_v, source = np.array([0.0, 1.0]), np.tile(fallback, (2, 1)), "fit"

    moving = np.isfinite(s_all)
    s = s_all[moving]
    m = motion(s)
    raw = _interp_rows(s, normal_s, normal_v)
    n = _unit_rows(raw - np.sum(raw * m, axis=1, keepdims=True) * m)
    if not np.all(np.isfinite(n)):
        raise ValueError(f"trace {trace.trace_id}: the normal is along the motion somewhere")
    lateral_axis = np.cross(n, m)
    force = trace.f[moving]
    out = {name: np.full(len(trace.t), np.nan) for name in ("normal", "along", "lateral")}
    out["normal"][moving] = np.sum(force * n, axis=1)
    out["along"][moving] = np.sum(force * m, axis=1)
    out["lateral"][moving] = np.sum(force * lateral_axis, axis=1)
    return DragFrameForces(s_all, out["normal"], out["along"], out["lateral"], length, source)
