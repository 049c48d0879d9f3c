// The contact force of a drag trace in the drag's own frame, so a plot shows
// the normal force and the friction whatever way the drag runs (along x, y,
// z or around a curved object). World components do not: a drag along y puts
// the friction in fy, a vertical drag puts it in fz beside the normal force.
//
// The frame, per sample (docs: clients/dashboard/README.md, "The trace plot"):
//   s   position along the forward path, mm: the forward pass's arc length;
//       a reverse sample takes the arc length of its nearest point on the
//       forward path (the reverse pass retraces it).
//   m   the drag direction at s: the FORWARD direction of motion, the unit
//       chord of the forward path from s - 1 mm to s + 1 mm (clamped to the
//       path's ends), which smooths the sensor's position noise; within
//       1 mm of an end, extrapolated from the chords 1 and 2 mm from it. Both passes
//       use the same m, so friction has opposite signs in the two passes.
//   n   the surface normal at s: the differential method's local pair normal,
//       unit(f/|f| + r/|r|) of the forward force f and the reverse force r at
//       the same s (friction cancels in the sum), averaged over s +- 1 mm and
//       made perpendicular to m. Where the passes have no pair (a trace that
//       cannot be paired) the fit's mean normal is used instead.
//   l   lateral = n x m (right-handed: m, l, n).
// Components of the force F (BY the surface ON the probe):
//   normal     F . n  (> 0: the surface pushes the probe out)
//   along      F . m  (forward pass ~ -mu * normal, reverse ~ +mu * normal:
//                      friction opposes each pass's motion)
//   lateral    F . l  (~ 0 for Coulomb friction: friction deflected sideways
//                      shows here with opposite signs in the two passes; a
//                      sideways force the same in both passes cannot be told
//                      from a tilted normal, by the method, and reads as normal)
// Pure functions, no DOM: the unit tests and the page share them.

export const MOTION_HALF_WINDOW_MM = 1.0;
export const NORMAL_HALF_WINDOW_MM = 1.0;

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const norm = (a) => Math.hypot(a[0], a[1], a[2]);
const scale = (a, k) => [a[0] * k, a[1] * k, a[2] * k];
const lerp = (a, b, t) => [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t];

function unit(a) {
  const len = norm(a);
  return len > 0 ? scale(a, 1 / len) : null;
}

/** Index k with xs[k] <= x < xs[k+1] in a non-decreasing array (clamped). */
function bracket(xs, x) {
  let lo = 0;
  let hi = xs.length - 1;
  if (x <= xs[0]) return 0;
  if (x >= xs[hi]) return Math.max(0, hi - 1);
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (xs[mid] <= x) lo = mid;
    else hi = mid;
  }
  return lo;
}

/** The value of a piecewise-linear vector function (xs, values) at x, clamped at the ends. */
function interpolate(xs, values, x) {
  if (xs.length === 1) return values[0];
  const k = bracket(xs, x);
  const span = xs[k + 1] - xs[k];
  const t = span > 0 ? Math.min(1, Math.max(0, (x - xs[k]) / span)) : 0;
  return lerp(values[k], values[k + 1], t);
}

function checkTrace(trace) {
  const columns = ['t', 'x', 'y', 'z', 'fx', 'fy', 'fz', 'phases'];
  for (const c of columns) {
    if (!Array.isArray(trace[c])) throw new Error(`trace ${trace.trace_id}: column ${c} is missing`);
  }
  const n = trace.t.length;
  for (const c of columns) {
    if (trace[c].length !== n) throw new Error(`trace ${trace.trace_id}: column ${c} has ${trace[c].length} values, t has ${n}`);
  }
  for (const c of ['x', 'y', 'z', 'fx', 'fy', 'fz']) {
    const bad = trace[c].findIndex((v) => !Number.isFinite(v));
    if (bad >= 0) throw new Error(`trace ${trace.trace_id}: ${c}[${bad}] is not a finite number`);
  }
}

const positionOf = (trace, i) => [trace.x[i], trace.y[i], trace.z[i]];
const forceOf = (trace, i) => [trace.fx[i], trace.fy[i], trace.fz[i]];

/** Arc length along the polyline (points, cumulative s) of the point nearest p. */
function projectOntoPath(points, s, p) {
  let best = Infinity;
  let bestS = 0;
  for (let k = 0; k + 1 < points.length; ++k) {
    const d = sub(points[k + 1], points[k]);
    const len2 = dot(d, d);
    const u = len2 > 0 ? Math.min(1, Math.max(0, dot(sub(p, points[k]), d) / len2)) : 0;
    const foot = lerp(points[k], points[k + 1], u);
    const dist = norm(sub(p, foot));
    if (dist < best) {
      best = dist;
      bestS = s[k] + u * (s[k + 1] - s[k]);
    }
  }
  return bestS;
}

/**
 * The trace's forces in the drag frame. `fallbackNormal` ({x, y, z}, e.g. the
 * fit's mean normal) is used only when the passes give no pair normal.
 * Returns { s, normal, along, lateral } (one entry per sample; null for the
 * pause), `pathLength` (mm), `normalSource` ('pairs' or 'fit') and, per
 * sample, the frame itself (`frames[i] = { m, n, l }` or null).
 * Throws an Error naming the problem for a trace that cannot be framed.
 */
export function dragFrameForces(trace, fallbackNormal = null) {
  checkTrace(trace);
  const n = trace.t.length;
  const forward = [];
  const reverse = [];
  for (let i = 0; i < n; ++i) {
    if (trace.phases[i] === 'fwd') forward.push(i);
    else if (trace.phases[i] === 'rev') reverse.push(i);
    else if (trace.phases[i] !== 'pause') throw new Error(`trace ${trace.trace_id}: phase '${trace.phases[i]}' at sample ${i} is not fwd, pause or rev`);
  }
  if (forward.length < 2 || reverse.length < 2) {
    throw new Error(`trace ${trace.trace_id}: needs a forward and a reverse pass of 2+ samples (has ${forward.length} and ${reverse.length})`);
  }

  // The forward path and its arc length.
  const points = forward.map((i) => positionOf(trace, i));
  const pathS = [0];
  for (let k = 1; k < points.length; ++k) pathS.push(pathS[k - 1] + norm(sub(points[k], points[k - 1])));
  const pathLength = pathS.at(-1);
  if (!(pathLength > 0)) throw new Error(`trace ${trace.trace_id}: the forward pass does not move`);

  // The unit chord from s - h to s + h; within h of an end, the direction is
  // extrapolated linearly from the chords centred at h and 2h from that end
  // (a one-sided chord there would lag the turning path by h/2 of arc).
  const h = MOTION_HALF_WINDOW_MM;
  const chordAt = (s) => unit(sub(interpolate(pathS, points, Math.min(pathLength, s + h)), interpolate(pathS, points, Math.max(0, s - h))));
  const motionAt = (s) => {
    let m;
    if (pathLength < 4 * h) {
      m = chordAt(pathLength / 2);
    } else if (s < h || s > pathLength - h) {
      const inner = s < h ? h : pathLength - h;
      const next = s < h ? 2 * h : pathLength - 2 * h;
      const a = chordAt(inner);
      const b = chordAt(next);
      const k = Math.abs(s - inner) / h;
      m = a && b && unit([a[0] + (a[0] - b[0]) * k, a[1] + (a[1] - b[1]) * k, a[2] + (a[2] - b[2]) * k]);
    } else {
      m = chordAt(s);
    }
    if (!m) throw new Error(`trace ${trace.trace_id}: no direction of motion at ${s.toFixed(2)} mm (the path turns back on itself)`);
    return m;
  };

  // Every moving sample's position along the forward path.
  const sOf = new Array(n).fill(null);
  forward.forEach((i, k) => { sOf[i] = pathS[k]; });
  for (const i of reverse) sOf[i] = projectOntoPath(points, pathS, positionOf(trace, i));

  // Reverse force as a function of s (sorted: the reverse pass runs backwards).
  const revOrder = [...reverse].sort((a, b) => sOf[a] - sOf[b]);
  const revS = revOrder.map((i) => sOf[i]);
  const revF = revOrder.map((i) => unit(forceOf(trace, i)));

  // Pair normals at the forward samples the reverse pass covers.
  const pairS = [];
  const pairN = [];
  for (const i of forward) {
    const s = sOf[i];
    if (s < revS[0] || s > revS.at(-1)) continue;
    const f = unit(forceOf(trace, i));
    const k = bracket(revS, s);
    if (!f || !revF[k] || !revF[k + 1]) continue;  // no contact force: no direction
    const span = revS[k + 1] - revS[k];
    const r = unit(lerp(revF[k], revF[k + 1], span > 0 ? (s - revS[k]) / span : 0));
    const sum = r && unit([f[0] + r[0], f[1] + r[1], f[2] + r[2]]);
    if (!sum) continue;
    pairS.push(s);
    pairN.push(sum);
  }

  let normalSource = 'pairs';
  let normalS = [];
  let normalV = [];
  if (pairS.length >= 2) {
    // Moving average over s +- NORMAL_HALF_WINDOW_MM (pairS is non-decreasing).
    let lo = 0;
    let hi = 0;
    const acc = [0, 0, 0];
    for (let k = 0; k < pairS.length; ++k) {
      while (hi < pairS.length && pairS[hi] <= pairS[k] + NORMAL_HALF_WINDOW_MM) {
        for (let c = 0; c < 3; ++c) acc[c] += pairN[hi][c];
        hi += 1;
      }
      while (pairS[lo] < pairS[k] - NORMAL_HALF_WINDOW_MM) {
        for (let c = 0; c < 3; ++c) acc[c] -= pairN[lo][c];
        lo += 1;
      }
      const mean = unit(acc);
      if (mean) {
        normalS.push(pairS[k]);
        normalV.push(mean);
      }
    }
  }
  if (normalS.length < 2) {
    const fb = fallbackNormal && unit([fallbackNormal.x, fallbackNormal.y, fallbackNormal.z]);
    if (!fb) {
      throw new Error(`trace ${trace.trace_id}: the passes give no pair normal and no fit normal was given`);
    }
    normalSource = 'fit';
    normalS = [0];
    normalV = [fb];
  }

  const frameAt = (s) => {
    const m = motionAt(s);
    const raw = interpolate(normalS, normalV, s);
    const nn = unit(sub(raw, scale(m, dot(raw, m))));
    if (!nn) throw new Error(`trace ${trace.trace_id}: the normal at ${s.toFixed(2)} mm is along the motion`);
    return { m, n: nn, l: cross(nn, m) };
  };

  const out = {
    s: sOf,
    normal: new Array(n).fill(null),
    along: new Array(n).fill(null),
    lateral: new Array(n).fill(null),
    frames: new Array(n).fill(null),
    pathLength,
    normalSource,
  };
  for (let i = 0; i < n; ++i) {
    if (sOf[i] === null) continue;
    const frame = frameAt(sOf[i]);
    const f = forceOf(trace, i);
    out.frames[i] = frame;
    out.normal[i] = dot(f, frame.n);
    out.along[i] = dot(f, frame.m);
    out.lateral[i] = dot(f, frame.l);
  }
  return out;
}

/**
 * What the plot shows about friction, over [startMm, endMm] of the path:
 * the mean force along the drag in each pass, the mean normal force, and
 * their ratio mu_plot = (along_rev - along_fwd) / (normal_fwd + normal_rev),
 * which is mu for Coulomb friction (a check that the plot shows the
 * friction, not an estimator). Null when a pass has no sample there.
 */
export function frictionInWindow(trace, framed, startMm, endMm) {
  const sums = { fwd: { along: 0, normal: 0, lateral: 0, count: 0 }, rev: { along: 0, normal: 0, lateral: 0, count: 0 } };
  for (let i = 0; i < trace.t.length; ++i) {
    const s = framed.s[i];
    const pass = sums[trace.phases[i]];
    if (!pass || s === null || s < startMm || s > endMm) continue;
    pass.along += framed.along[i];
    pass.normal += framed.normal[i];
    pass.lateral += framed.lateral[i];
    pass.count += 1;
  }
  if (sums.fwd.count === 0 || sums.rev.count === 0) return null;
  const mean = (p) => ({ along: p.along / p.count, normal: p.normal / p.count, lateral: p.lateral / p.count, count: p.count });
  const fwd = mean(sums.fwd);
  const rev = mean(sums.rev);
  return { fwd, rev, mu: (rev.along - fwd.along) / (fwd.normal + rev.normal) };
}
