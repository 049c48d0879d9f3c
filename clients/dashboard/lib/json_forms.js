// The JSON the page gets: the proto's shape (snake_case fields, Vec3 as
// {x, y, z}) with three changes that make it easy to use in a browser:
//   - Timestamps become ISO-8601 strings and Durations seconds (numbers);
//   - enum names lose their type prefix ("JOB_STATE_RUNNING" -> "RUNNING");
//   - bulk arrays are flat: a mesh is positions [x0,y0,z0,x1,...], normals
//     likewise and triangles [i0,j0,k0,...]; a trace keeps its columns and
//     phases become "fwd" / "pause" / "rev" (the drag-trace CSV's words).
// Input: messages as @grpc/proto-loader gives them (keepCase, longs: Number,
// enums: String, defaults: true). Missing sub-messages become null.

export function timestampToIso(ts) {
  if (!ts) return null;
  const ms = Number(ts.seconds) * 1000 + Math.round(Number(ts.nanos || 0) / 1e6);
  if (ms === 0) return null;  // unset Timestamp
  return new Date(ms).toISOString();
}

export function durationToSeconds(d) {
  if (!d) return null;
  return Number(d.seconds) + Number(d.nanos || 0) / 1e9;
}

export function stripEnumPrefix(value, prefix) {
  if (typeof value !== 'string') return value;
  return value.startsWith(prefix) ? value.slice(prefix.length) : value;
}

const vec = (v) => (v ? { x: v.x, y: v.y, z: v.z } : null);

export function objectForm(o) {
  return {
    object_id: o.object_id,
    name: o.name,
    format: stripEnumPrefix(o.format, 'MESH_FORMAT_'),
    control_vertex_count: o.control_vertex_count,
    control_face_count: o.control_face_count,
    created: timestampToIso(o.created),
  };
}

function progressForm(p) {
  if (!p) return null;
  return {
    measured: p.measured,
    pending: p.pending,
    issued: p.issued,
    failed: p.failed,
    skipped: p.skipped,
    budget_left: p.budget_left,
    complete: p.complete,
    // Of `issued`, leased to a rig now; null where the server did not count it.
    leased: typeof p.leased === 'number' ? p.leased : null,
    // Every site the plan knows of so far (adaptive plans grow while running).
    total: p.measured + p.pending + p.issued + p.failed + p.skipped,
    levels: (p.levels || []).map((l) => ({
      level: l.level, measured: l.measured, pending: l.pending, issued: l.issued, failed: l.failed,
      leased: typeof l.leased === 'number' ? l.leased : null,
    })),
  };
}

export function jobForm(j) {
  const s = j.spec || {};
  return {
    job_id: j.job_id,
    state: stripEnumPrefix(j.state, 'JOB_STATE_'),
    spec: {
      object_id: s.object_id,
      property: stripEnumPrefix(s.property, 'PROPERTY_'),
      mode: stripEnumPrefix(s.mode, 'SAMPLING_MODE_'),
      coarsest_level: s.coarsest_level,
      finest_level: s.finest_level,
      threshold: s.threshold,
      budget: s.budget,
      probe: s.probe ? { ...s.probe } : null,
      seed: s.seed,
      max_retries: s.max_retries,
      lease_s: durationToSeconds(s.lease),
    },
    progress: progressForm(j.progress),
    created: timestampToIso(j.created),
    updated: timestampToIso(j.updated),
  };
}

export function fitForm(f) {
  if (!f) return null;
  const fr = f.friction || {};
  const ro = f.roughness || {};
  return {
    fit_id: f.fit_id,
    version: f.version,
    estimator: f.estimator,
    estimator_version: f.estimator_version,
    options_json: f.options_json,
    noise_std: f.noise_std,
    friction: {
      mu: fr.mu, mu_std: fr.mu_std, mu_median: fr.mu_median, normal: vec(fr.normal),
      pair_count: fr.pair_count, window_start_mm: fr.window_start_mm, window_end_mm: fr.window_end_mm,
      // Only from GetSample with include_series; empty elsewhere.
      pair_s_mm: fr.pair_s_mm || [], pair_mu: fr.pair_mu || [],
    },
    roughness: {
      ar_coefficients: ro.ar_coefficients || [], ar_stderr: ro.ar_stderr || [], sigma: ro.sigma,
      stationary: ro.stationary, reflection: ro.reflection || [], acf_decay_mm: ro.acf_decay_mm,
      dominant_wavelength_mm: ro.dominant_wavelength_mm, below_noise_floor: ro.below_noise_floor,
      acf: ro.acf || [], grid_step_mm: ro.grid_step_mm,
    },
  };
}

export function sampleForm(s) {
  if (!s) return null;
  return {
    trace_id: s.trace_id,
    command_id: s.command_id,
    job_id: s.job_id,
    site: s.site ? { level: s.site.level, vertex: s.site.vertex } : null,
    position: vec(s.position),
    drag_direction: vec(s.drag_direction),
    segment_length_mm: s.segment_length_mm,
    fit: fitForm(s.fit),
    received: timestampToIso(s.received),
    // The rig that measured it; '' from servers older than the field.
    rig_id: s.rig_id || '',
  };
}

function flattenVec3(list, digits) {
  const out = new Array(list.length * 3);
  const scale = 10 ** digits;
  const r = (v) => Math.round(v * scale) / scale;
  for (let i = 0; i < list.length; ++i) {
    out[3 * i] = r(list[i].x);
    out[3 * i + 1] = r(list[i].y);
    out[3 * i + 2] = r(list[i].z);
  }
  return out;
}

// Positions in mm to 0.1 um and unit normals to 1e-6: far below what a
// screen shows, and it halves the JSON of fine levels.
export function meshForm(m) {
  if (!m) return null;
  return {
    object_id: m.object_id,
    level: m.level,
    vertex_count: m.positions.length,
    triangle_count: m.triangle_indices.length / 3,
    positions: flattenVec3(m.positions, 4),
    normals: flattenVec3(m.normals, 6),
    triangles: m.triangle_indices,
  };
}

export function mapForm(m) {
  if (!m) return null;
  return {
    job_id: m.job_id,
    level: m.level,
    vertex_count: m.vertex_count,
    mu: m.mu,
    mu_uncertainty: m.mu_uncertainty,
    sigma: m.sigma,
    a1: m.a1,
    a2: m.a2,
    samples: (m.samples || []).map(sampleForm),
  };
}

export function mapValueForm(v) {
  return {
    surface_point: vec(v.surface_point),
    normal: vec(v.normal),
    distance_mm: v.distance_mm,
    mu: v.mu,
    mu_uncertainty: v.mu_uncertainty,
    sigma: v.sigma,
    a1: v.a1,
    a2: v.a2,
  };
}

const PHASE_WORDS = Object.freeze({ PHASE_FORWARD: 'fwd', PHASE_PAUSE: 'pause', PHASE_REVERSE: 'rev' });

export function traceForm(t) {
  const s = t.samples || {};
  return {
    trace_id: t.trace_id,
    command_id: t.command_id,
    job_id: t.job_id,
    sample_count: (s.t || []).length,
    t: s.t || [], x: s.x || [], y: s.y || [], z: s.z || [],
    fx: s.fx || [], fy: s.fy || [], fz: s.fz || [],
    phases: (s.phases || []).map((p) => PHASE_WORDS[p] ?? String(p)),
  };
}

export function planForm(p) {
  return {
    job_id: p.job_id,
    progress: progressForm(p.progress),
    sites: (p.sites || []).map((s) => ({
      level: s.site ? s.site.level : null,
      vertex: s.site ? s.site.vertex : null,
      state: stripEnumPrefix(s.state, 'SITE_STATE_'),
      attempts: s.attempts,
      failure_reason: s.failure_reason,
      position: vec(s.position),
    })),
  };
}

/**
 * A job event (ListJobEvents): `detail` is detail_json parsed (the server
 * writes a JSON object: trace_accepted has command_id, level, vertex, mu,
 * rig; probe_failed has command_id, reason, kind, rig, will_retry;
 * job_state has from, to). Detail that is not a JSON object is kept as text
 * in `detail_error` with `detail` null, so one bad record does not hide the
 * others.
 */
export function eventForm(e) {
  const form = {
    event_id: e.event_id,
    job_id: e.job_id,
    time: timestampToIso(e.time),
    kind: e.kind,
    detail: null,
  };
  let parsed;
  try {
    parsed = JSON.parse(e.detail_json || '{}');
  } catch (err) {
    form.detail_error = `event ${e.event_id}: detail_json is not JSON (${err.message}): ${String(e.detail_json).slice(0, 200)}`;
    return form;
  }
  if (parsed === null || typeof parsed !== 'object' || Array.isArray(parsed)) {
    form.detail_error = `event ${e.event_id}: detail_json is not a JSON object: ${String(e.detail_json).slice(0, 200)}`;
    return form;
  }
  form.detail = parsed;
  return form;
}
