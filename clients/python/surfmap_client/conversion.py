"""Proto messages -> the records of records.py (one direction: the client only reads them)."""

from __future__ import annotations

import json
from datetime import datetime, timezone
from typing import Any, Dict, Optional

import numpy as np

from . import records as r
from ._stubs import pb

_PROPERTY = {
    pb.PROPERTY_FRICTION: r.Property.FRICTION,
    pb.PROPERTY_ROUGHNESS: r.Property.ROUGHNESS,
    pb.PROPERTY_BOTH: r.Property.BOTH,
}
_MODE = {
    pb.SAMPLING_MODE_BOUNDARY: r.SamplingMode.BOUNDARY,
    pb.SAMPLING_MODE_ADAPTIVE: r.SamplingMode.ADAPTIVE,
    pb.SAMPLING_MODE_UNIFORM: r.SamplingMode.UNIFORM,
    pb.SAMPLING_MODE_UNCERTAINTY: r.SamplingMode.UNCERTAINTY,
}
PROPERTY_TO_PROTO = {v: k for k, v in _PROPERTY.items()}
MODE_TO_PROTO = {v: k for k, v in _MODE.items()}
AR_METHOD_TO_PROTO = {r.ArMethod.BURG: pb.AR_METHOD_BURG, r.ArMethod.LEAST_SQUARES: pb.AR_METHOD_LEAST_SQUARES}


def _time(message, name: str) -> Optional[datetime]:
    if not message.HasField(name):
        return None
    return getattr(message, name).ToDatetime(tzinfo=timezone.utc)


def _vec(v) -> np.ndarray:
    return np.array([v.x, v.y, v.z], dtype=float)


def vec_array(vectors) -> np.ndarray:
    """repeated Vec3 -> (N, 3) float array."""
    out = np.empty((len(vectors), 3), dtype=float)
    for i, v in enumerate(vectors):
        out[i, 0], out[i, 1], out[i, 2] = v.x, v.y, v.z
    return out


def provenance(m) -> r.Provenance:
    return r.Provenance(m.operator_name, m.specimen, m.probe_tip, m.sensor, m.notes, dict(m.extra))


def provenance_to_proto(p) -> Any:
    """A ``records.Provenance``, a dict of its fields, or None (empty)."""
    if p is None:
        return pb.Provenance()
    if isinstance(p, dict):
        p = r.Provenance(**p)
    return pb.Provenance(operator_name=p.operator, specimen=p.specimen, probe_tip=p.probe_tip, sensor=p.sensor,
                         notes=p.notes, extra=dict(p.extra))


def import_info(m) -> r.ImportInfo:
    return r.ImportInfo(m.source, m.file_name, m.file_sha256, _time(m, "recorded"), _time(m, "imported"))


def rejected_trace(m) -> r.RejectedTrace:
    return r.RejectedTrace(m.rejected_trace_id, m.command_id, m.job_id, m.rig_id, m.check, m.message,
                           m.sample_count, _time(m, "received"))


def object_info(m) -> r.ObjectInfo:
    fmt = {pb.MESH_FORMAT_OBJ: "obj", pb.MESH_FORMAT_PLY: "ply"}.get(m.format, "unspecified")
    surface = "facets" if m.surface == pb.OBJECT_SURFACE_FACETS else "control_mesh"
    return r.ObjectInfo(m.object_id, m.name, fmt, m.control_vertex_count, m.control_face_count, _time(m, "created"),
                        provenance(m.provenance), surface)


def mesh(m) -> r.Mesh:
    tri = np.array(m.triangle_indices, dtype=np.int64).reshape(-1, 3)
    return r.Mesh(m.object_id, m.level, vec_array(m.positions), vec_array(m.normals), tri)


def job_spec(m) -> r.JobSpec:
    probe = r.ProbeParameters(m.probe.segment_length_mm, m.probe.speed_mm_s, m.probe.normal_force_n)
    lease_s = m.lease.seconds + m.lease.nanos * 1e-9
    return r.JobSpec(m.object_id, _PROPERTY.get(m.property, r.Property.FRICTION),
                     _MODE.get(m.mode, r.SamplingMode.BOUNDARY), m.coarsest_level, m.finest_level, m.threshold,
                     m.budget, probe, m.seed, m.max_retries, lease_s,
                     m.map_level if m.HasField("map_level") else m.finest_level)


def job_progress(m) -> r.JobProgress:
    levels = tuple(r.LevelProgress(lv.level, lv.measured, lv.pending, lv.issued, lv.failed,
                                   lv.leased if lv.HasField("leased") else None) for lv in m.levels)
    leased = m.leased if m.HasField("leased") else None
    return r.JobProgress(m.measured, m.pending, m.issued, m.failed, m.skipped, m.budget_left, m.complete, levels,
                         leased)


def job_info(m) -> r.JobInfo:
    return r.JobInfo(m.job_id, job_spec(m.spec), r.JobState(m.state), job_progress(m.progress),
                     _time(m, "created"), _time(m, "updated"), provenance(m.provenance))


def plan(m) -> r.Plan:
    sites = tuple(
        r.PlanSite(s.site.level, s.site.vertex, r.SiteState(s.state), s.attempts, s.failure_reason, _vec(s.position))
        for s in m.sites)
    return r.Plan(m.job_id, job_progress(m.progress), sites)


def fit(m) -> r.Fit:
    f = m.friction
    friction = r.FrictionEstimate(f.mu, f.mu_std, f.mu_median, _vec(f.normal), f.pair_count,
                                  f.window_start_mm, f.window_end_mm,
                                  np.asarray(f.pair_s_mm, dtype=float), np.asarray(f.pair_mu, dtype=float))
    pieces = tuple(r.DragPiece(p.start_mm, p.end_mm, p.starts_at_change, p.ends_at_change, p.mu, p.mu_std, p.mu_se,
                               p.pair_count, _ROUGHNESS_STATE.get(p.roughness_state, "unspecified"),
                               p.roughness_note,
                               _roughness(p.roughness) if p.roughness_state == _FITTED else None)
                   for p in m.pieces)
    return r.Fit(m.fit_id, m.version, m.estimator, m.estimator_version, m.options_json, friction,
                 _roughness(m.roughness), m.noise_std, tuple(m.change_s_mm), pieces)


_FITTED = pb.DragPiece.ROUGHNESS_STATE_FITTED
_ROUGHNESS_STATE = {
    pb.DragPiece.ROUGHNESS_STATE_FITTED: "fitted",
    pb.DragPiece.ROUGHNESS_STATE_TOO_SHORT: "too_short",
    pb.DragPiece.ROUGHNESS_STATE_FIT_FAILED: "fit_failed",
}


def _roughness(g) -> r.RoughnessEstimate:
    return r.RoughnessEstimate(tuple(g.ar_coefficients), tuple(g.ar_stderr), g.sigma, g.stationary,
                               tuple(g.reflection), g.acf_decay_mm, g.dominant_wavelength_mm,
                               g.below_noise_floor, np.asarray(g.acf, dtype=float), g.grid_step_mm)


def sample(m) -> r.Sample:
    return r.Sample(m.trace_id, m.command_id, m.job_id, m.site.level, m.site.vertex, _vec(m.position),
                    _vec(m.drag_direction), m.segment_length_mm, fit(m.fit) if m.HasField("fit") else None,
                    _time(m, "received"), m.rig_id, provenance(m.provenance),
                    import_info(getattr(m, "import")) if m.HasField("import") else None)


def job_event(m) -> r.JobEvent:
    detail: Optional[Dict[str, Any]] = None
    problem = ""
    try:
        parsed = json.loads(m.detail_json or "{}")
    except ValueError as error:
        problem = f"event {m.event_id}: detail_json is not JSON ({error}): {m.detail_json[:200]}"
    else:
        if isinstance(parsed, dict):
            detail = parsed
        else:
            problem = f"event {m.event_id}: detail_json is not a JSON object: {m.detail_json[:200]}"
    return r.JobEvent(m.event_id, m.job_id, _time(m, "time"), m.kind, detail, m.detail_json, problem)


def surface_map(level_message, mesh_message=None) -> r.SurfaceMap:
    m = level_message
    arrays = {name: np.array(getattr(m, name), dtype=float) for name in ("mu", "mu_uncertainty", "sigma", "a1", "a2")}
    positions = normals = triangles = None
    if mesh_message is not None and len(mesh_message.positions) > 0:
        mm = mesh(mesh_message)
        positions, normals, triangles = mm.positions, mm.normals, mm.triangles
    regions = tuple(r.MapRegion(g.region, g.mu, g.mu_se, g.mu_spread, g.piece_count, g.roughness_piece_count,
                                tuple(g.reflection), tuple(g.ar_coefficients), g.sigma, g.area_mm2,
                                g.material, g.own_mu, g.own_mu_se,
                                tuple(r.MapRegionPiece(p.trace_id, p.fit_piece, p.start_mm, p.end_mm, p.split_by_map,
                                                       p.mu, p.mu_se, p.effective_pairs, p.in_mu, p.mu_weight)
                                      for p in g.pieces))
                    for g in m.regions)
    return r.SurfaceMap(job_id=m.job_id, level=m.level, vertex_count=m.vertex_count,
                        samples=tuple(sample(s) for s in m.samples), positions=positions, normals=normals,
                        triangles=triangles, region=np.array(m.region, dtype=np.int64),
                        boundary_probability=np.array(m.boundary_probability, dtype=float), regions=regions,
                        **arrays)


def map_query(m) -> r.MapQuery:
    v = m.values
    column = lambda name: np.array([getattr(x, name) for x in v], dtype=float)  # noqa: E731
    return r.MapQuery(vec_array([x.surface_point for x in v]), vec_array([x.normal for x in v]),
                      column("distance_mm"), column("mu"), column("mu_uncertainty"), column("sigma"),
                      column("a1"), column("a2"), np.array([x.region for x in v], dtype=np.int64))


def trace(m) -> r.Trace:
    s = m.samples
    xyz = np.column_stack([np.array(s.x, dtype=float), np.array(s.y, dtype=float), np.array(s.z, dtype=float)])
    f = np.column_stack([np.array(s.fx, dtype=float), np.array(s.fy, dtype=float), np.array(s.fz, dtype=float)])
    return r.Trace(m.trace_id, m.command_id, m.job_id, np.array(s.t, dtype=float), xyz.reshape(-1, 3),
                   f.reshape(-1, 3), np.array(s.phases, dtype=np.int8))


def job_update(m) -> r.JobUpdate:
    latest = sample(m.latest_sample) if m.HasField("latest_sample") and m.latest_sample.trace_id != 0 else None
    level_map = surface_map(m.map) if m.HasField("map") else None
    return r.JobUpdate(job_info(m.job), latest, level_map)
