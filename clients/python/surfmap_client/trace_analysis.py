"""Quantities of a drag trace that the API does not return, computed in Python.

The server's fit (``Sample.fit``) gives mu, its spread, the mean normal, the
data window, the AR coefficients, sigma and the ACF decay length, but not the
per-point mu along the window nor the autocorrelation function itself. This
module recomputes those from the raw trace (``SurfmapClient.get_trace``) for
plots. It is a SIMPLIFIED re-implementation of the method in
docs/method.md (the server's estimator in server/estimate/ is the reference):

- pairing: each forward sample's arc length along the forward polyline; each
  reverse sample projected onto the nearest forward segment (brute force, no
  smoothing), the reverse force linearly interpolated at forward arc lengths;
- per-point mu = |fh x rh| / (1 + fh . rh) with unit forces, normal =
  normalised fh + rh (the paper's differential method), over a given window
  (pass the server's ``window_start_mm`` / ``window_end_mm``);
- force variation |f_t| - mu f_n with the local paired normal, nearest sample
  on a uniform arc-length grid, least-squares line removed, per pass;
- the ACF pooled over the passes (biased estimator), the model ACF of AR
  coefficients, and a seeded AR resynthesis.

Its numbers are close to the server's but are not the server's fit.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import List, Sequence, Tuple

import numpy as np

from .records import Trace


def arc_length(points: np.ndarray) -> np.ndarray:
    """Cumulative distance along a polyline (N, 3), first = 0."""
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(steps)])


def project_onto_polyline(points: np.ndarray, polyline: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Arc length of each point's foot on the polyline and its distance to it.

    Brute force over segments (O(N M)): traces have a few hundred samples per pass."""
    s_poly = arc_length(polyline)
    a = polyline[:-1]                          # (M, 3) segment starts
    d = polyline[1:] - a                       # (M, 3)
    length2 = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
    rel = points[:, None, :] - a[None, :, :]   # (N, M, 3)
    u = np.clip(np.einsum("nmk,mk->nm", rel, d) / length2, 0.0, 1.0)
    foot = a[None, :, :] + u[:, :, None] * d[None, :, :]
    dist = np.linalg.norm(points[:, None, :] - foot, axis=2)
    best = np.argmin(dist, axis=1)
    rows = np.arange(len(points))
    s = s_poly[best] + u[rows, best] * np.sqrt(length2[best])
    return s, dist[rows, best]


@dataclass(frozen=True)
class PassGeometry:
    """Both passes placed along the forward path."""

    s_forward: np.ndarray     # arc length of each forward sample, mm
    s_reverse: np.ndarray     # arc length of each reverse sample's foot on the forward path, mm
    f_forward: np.ndarray     # (Nf, 3) force
    f_reverse: np.ndarray     # (Nr, 3)
    path_length_mm: float


def pass_geometry(trace: Trace) -> PassGeometry:
    """ValueError when a pass has fewer than 2 samples."""
    fwd, rev = trace.forward, trace.reverse
    if fwd.sum() < 2 or rev.sum() < 2:
        raise ValueError(f"trace {trace.trace_id}: needs a forward and a reverse pass of 2+ samples "
                         f"(has {int(fwd.sum())} and {int(rev.sum())})")
    xyz_f = trace.xyz[fwd]
    s_f = arc_length(xyz_f)
    s_r, _ = project_onto_polyline(trace.xyz[rev], xyz_f)
    return PassGeometry(s_f, s_r, trace.f[fwd], trace.f[rev], float(s_f[-1]))


def _interp_rows(s_query: np.ndarray, s: np.ndarray, values: np.ndarray) -> np.ndarray:
    order = np.argsort(s, kind="stable")
    return np.column_stack([np.interp(s_query, s[order], values[order, k]) for k in range(values.shape[1])])


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=1, keepdims=True)


@dataclass(frozen=True)
class PointFriction:
    s: np.ndarray             # arc length of each forward sample in the window, mm
    mu: np.ndarray            # per-point tan(theta / 2)
    normal: np.ndarray        # (N, 3) per-point normal estimate


def per_point_friction(trace: Trace, window_mm: Tuple[float, float]) -> PointFriction:
    """Per forward sample inside ``window_mm``: mu and the normal by the differential method."""
    g = pass_geometry(trace)
    inside = (g.s_forward >= window_mm[0]) & (g.s_forward <= window_mm[1])
    s = g.s_forward[inside]
    fh = _unit(g.f_forward[inside])
    rh = _unit(_interp_rows(s, g.s_reverse, g.f_reverse))
    mu = np.linalg.norm(np.cross(fh, rh), axis=1) / (1.0 + np.einsum("ij,ij->i", fh, rh))
    return PointFriction(s, mu, _unit(fh + rh))


def force_variation(trace: Trace, mu: float, window_mm: Tuple[float, float],
                    step_mm: float = 0.1) -> List[Tuple[np.ndarray, np.ndarray]]:
    """Per pass (forward, reverse): (grid arc lengths, detrended |f_t| - mu f_n) on the grid."""
    g = pass_geometry(trace)
    points = per_point_friction(trace, window_mm)
    if len(points.s) < 2:
        raise ValueError(f"trace {trace.trace_id}: window {window_mm} holds fewer than 2 forward samples")
    grid = np.arange(window_mm[0], window_mm[1] + 1e-9, step_mm)
    out = []
    for s_pass, f_pass in ((g.s_forward, g.f_forward), (g.s_reverse, g.f_reverse)):
        n = _unit(_interp_rows(s_pass, points.s, points.normal))
        f_n = np.einsum("ij,ij->i", f_pass, n)
        f_t = f_pass - f_n[:, None] * n
        variation = np.linalg.norm(f_t, axis=1) - mu * f_n
        order = np.argsort(s_pass, kind="stable")
        s_sorted, v_sorted = s_pass[order], variation[order]
        # Nearest sample, not interpolation: interpolating would low-pass the texture.
        idx = np.clip(np.searchsorted(s_sorted, grid), 1, len(s_sorted) - 1)
        left_closer = (grid - s_sorted[idx - 1]) <= (s_sorted[idx] - grid)
        values = v_sorted[np.where(left_closer, idx - 1, idx)]
        line = np.polyfit(grid, values, 1)
        out.append((grid, values - np.polyval(line, grid)))
    return out


def autocorrelation(segments: Sequence[np.ndarray], max_lag: int) -> np.ndarray:
    """ACF at lags 0..max_lag pooled over segments (each mean-removed; biased: divided by the total length)."""
    cov = np.zeros(max_lag + 1)
    total = 0
    for x in segments:
        x = np.asarray(x, dtype=float) - np.mean(x)
        total += len(x)
        for k in range(min(max_lag, len(x) - 1) + 1):
            cov[k] += np.dot(x[: len(x) - k], x[k:])
    if total == 0 or cov[0] <= 0:
        raise ValueError("autocorrelation of an empty or constant series")
    return cov / cov[0]


def ar_model_autocorrelation(coefficients: Sequence[float], max_lag: int) -> np.ndarray:
    """The ACF of a stationary AR(p) process f(k) = sum a_i f(k-i) + e (Yule-Walker equations)."""
    a = np.asarray(coefficients, dtype=float)
    p = len(a)
    rho = np.zeros(max(max_lag, p) + 1)
    rho[0] = 1.0
    if p > 0:
        # rho_k = sum_i a_i rho_|k-i| for k = 1..p: a linear system in rho_1..rho_p.
        m = np.eye(p)
        rhs = np.zeros(p)
        for k in range(1, p + 1):
            for i in range(1, p + 1):
                lag = abs(k - i)
                if lag == 0:
                    rhs[k - 1] += a[i - 1]
                else:
                    m[k - 1, lag - 1] -= a[i - 1]
        rho[1: p + 1] = np.linalg.solve(m, rhs)
        for k in range(p + 1, len(rho)):
            rho[k] = np.dot(a, rho[k - p: k][::-1])
    return rho[: max_lag + 1]


def synthesize_ar(coefficients: Sequence[float], sigma: float, n: int, seed: int, burn_in: int = 500) -> np.ndarray:
    """n values of the AR process with Gaussian innovations of std sigma (numpy PCG64, seeded)."""
    a = np.asarray(coefficients, dtype=float)
    rng = np.random.default_rng(seed)
    e = rng.standard_normal(n + burn_in) * sigma
    x = np.zeros(n + burn_in)
    for k in range(len(x)):
        past = x[max(0, k - len(a)): k][::-1]
        x[k] = np.dot(a[: len(past)], past) + e[k]
    return x[burn_in:]
