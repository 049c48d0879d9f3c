// The drag frame (public/drag_frame.js) on traces made here with known
// physics: Coulomb friction mu on a surface with normal n, dragged along x,
// along y, straight down, and around a cylinder (the normal turning by 30
// degrees over the drag). In every case the normal force, the friction along
// the drag and the lateral force come out as made, where world fx/fz do not.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { dragFrameForces, frictionInWindow } from '../public/drag_frame.js';

const NORMAL_N = 5;

// A drag over `path(u)` (u in [0, 1]) with outward normal `normalAt(u)`:
// `count` samples forward, a short pause, `count` back. The force is BY the
// surface ON the probe: N n minus mu N along the motion.
// `lateral` deflects the friction sideways (anisotropic friction): a force
// lateral * N along n x (direction of motion), flipping with the pass.
function makeTrace({ path, normalAt, mu, count = 200, lateral = 0 }) {
  const t = []; const x = []; const y = []; const z = []; const fx = []; const fy = []; const fz = []; const phases = [];
  const push = (u, dir, phase, time) => {
    const p = path(u);
    const h = 1e-4;
    const a = path(Math.max(0, u - h)); const b = path(Math.min(1, u + h));
    const d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    const len = Math.hypot(...d);
    const m = d.map((v) => (dir * v) / len);
    const n = normalAt(u);
    const l = [n[1] * m[2] - n[2] * m[1], n[2] * m[0] - n[0] * m[2], n[0] * m[1] - n[1] * m[0]];
    const f = [0, 1, 2].map((k) => NORMAL_N * n[k] - mu * NORMAL_N * m[k] + lateral * NORMAL_N * l[k]);
    t.push(time); x.push(p[0]); y.push(p[1]); z.push(p[2]); fx.push(f[0]); fy.push(f[1]); fz.push(f[2]); phases.push(phase);
  };
  let time = 0;
  for (let k = 0; k < count; ++k) push(k / (count - 1), 1, 'fwd', (time += 0.01));
  for (let k = 0; k < 10; ++k) push(1, 1, 'pause', (time += 0.01));
  // The reverse samples sit between the forward ones (as a real rig's do).
  for (let k = 0; k < count; ++k) push(Math.max(0, 1 - (k + 0.5) / (count - 1)), -1, 'rev', (time += 0.01));
  return { trace_id: 1, t, x, y, z, fx, fy, fz, phases };
}

function checkFrame(trace, mu, what) {
  const framed = dragFrameForces(trace);
  assert.equal(framed.normalSource, 'pairs', what);
  for (let i = 0; i < trace.t.length; ++i) {
    if (framed.s[i] === null) continue;
    const sign = trace.phases[i] === 'fwd' ? -1 : 1;
    assert.ok(Math.abs(framed.normal[i] - NORMAL_N) < 0.02, `${what}: normal ${framed.normal[i]} at sample ${i}`);
    assert.ok(Math.abs(framed.along[i] - sign * mu * NORMAL_N) < 0.02, `${what}: along ${framed.along[i]} at sample ${i}`);
    assert.ok(Math.abs(framed.lateral[i]) < 0.02, `${what}: lateral ${framed.lateral[i]} at sample ${i}`);
  }
  const window = frictionInWindow(trace, framed, 2, framed.pathLength - 2);
  assert.ok(Math.abs(window.mu - mu) < 0.002, `${what}: mu in the window ${window.mu}`);
  return framed;
}

test('a drag along x on a horizontal plane: friction along the drag, both passes', () => {
  const trace = makeTrace({ path: (u) => [20 * u, 0, 0], normalAt: () => [0, 0, 1], mu: 0.3 });
  const framed = checkFrame(trace, 0.3, 'along x');
  assert.ok(Math.abs(framed.pathLength - 20) < 1e-9);
});

test('a drag along y: the friction shows in the drag frame, not in world fx', () => {
  const trace = makeTrace({ path: (u) => [0, 20 * u, 0], normalAt: () => [0, 0, 1], mu: 0.13 });
  checkFrame(trace, 0.13, 'along y');
  // What the old plot drew: fx is zero in both passes, so no friction at all.
  assert.ok(trace.fx.every((v) => Math.abs(v) < 1e-12));
});

test('a vertical drag on a wall: the normal force is horizontal, the friction vertical', () => {
  const trace = makeTrace({ path: (u) => [0, 0, 30 - 20 * u], normalAt: () => [1, 0, 0], mu: 0.5 });
  checkFrame(trace, 0.5, 'vertical');
});

test('a drag around a cylinder (r 40 mm, 20 mm of arc): the frame turns with the surface', () => {
  const r = 40;
  const arc = 20 / r;
  const angle = (u) => -arc / 2 + arc * u;
  const trace = makeTrace({
    path: (u) => [r * Math.cos(angle(u)), 5, r * Math.sin(angle(u))],
    normalAt: (u) => [Math.cos(angle(u)), 0, Math.sin(angle(u))],
    mu: 0.25,
  });
  const framed = checkFrame(trace, 0.25, 'cylinder');
  assert.ok(Math.abs(framed.pathLength - 20) < 0.01, `arc length ${framed.pathLength}`);
});

test('friction deflected sideways shows in the lateral component, opposite in the two passes', () => {
  const trace = makeTrace({ path: (u) => [20 * u, 0, 0], normalAt: () => [0, 0, 1], mu: 0.2, lateral: 0.08 });
  const framed = dragFrameForces(trace);
  const fwd = 50;
  const rev = trace.phases.indexOf('rev') + 50;
  assert.ok(Math.abs(framed.lateral[fwd] - 0.4) < 0.01, `forward lateral ${framed.lateral[fwd]}`);
  assert.ok(Math.abs(framed.lateral[rev] + 0.4) < 0.01, `reverse lateral ${framed.lateral[rev]}`);
  assert.ok(Math.abs(framed.normal[fwd] - NORMAL_N) < 0.01);
  assert.ok(Math.abs(framed.along[fwd] + 0.2 * NORMAL_N) < 0.01);
});

test('without pair normals (no reverse force) the fit normal is used', () => {
  const trace = makeTrace({ path: (u) => [0, 20 * u, 0], normalAt: () => [0, 0, 1], mu: 0.2 });
  trace.phases.forEach((p, i) => { if (p === 'rev') { trace.fx[i] = 0; trace.fy[i] = 0; trace.fz[i] = 0; } });
  assert.throws(() => dragFrameForces(trace), /no pair normal and no fit normal/);
  const framed = dragFrameForces(trace, { x: 0, y: 0.1, z: 1 });
  assert.equal(framed.normalSource, 'fit');
  const i = 50;
  assert.ok(Math.abs(framed.normal[i] - NORMAL_N) < 1e-9, 'the fit normal is made perpendicular to the motion');
  assert.ok(Math.abs(framed.along[i] + 0.2 * NORMAL_N) < 1e-9);
});

test('traces that cannot be framed are named with the reason', () => {
  const good = () => makeTrace({ path: (u) => [20 * u, 0, 0], normalAt: () => [0, 0, 1], mu: 0.2, count: 10 });
  let trace = good();
  delete trace.fy;
  assert.throws(() => dragFrameForces(trace), /trace 1: column fy is missing/);
  trace = good();
  trace.fz.pop();
  assert.throws(() => dragFrameForces(trace), /column fz has 29 values, t has 30/);
  trace = good();
  trace.x[3] = NaN;
  assert.throws(() => dragFrameForces(trace), /x\[3\] is not a finite number/);
  trace = good();
  trace.phases = trace.phases.map((p) => (p === 'rev' ? 'fwd' : p));
  assert.throws(() => dragFrameForces(trace), /needs a forward and a reverse pass of 2\+ samples \(has 20 and 0\)/);
  trace = good();
  trace.phases[0] = 'sideways';
  assert.throws(() => dragFrameForces(trace), /phase 'sideways' at sample 0/);
  trace = good();
  trace.x = trace.x.map(() => 1);
  assert.throws(() => dragFrameForces(trace), /the forward pass does not move/);
});
