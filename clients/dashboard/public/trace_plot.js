// A drag trace as an inline SVG, in the drag's own frame (drag_frame.js), like
// the figures of Lloyd & Pai: the normal force, the force along the drag
// (friction) with the lateral force, and the fit's per-pair mu when the
// sample carries it, in panels along the path (mm from the start of the
// forward pass; the reverse pass runs back over the same path, so it is
// plotted at the same positions), forward solid, reverse dashed, the pause
// left out (the probe does not move), and the fit's data window shaded.
// Reading it: the force along the drag is about -mu N in the forward pass and
// +mu N in the reverse one, so the gap between the two curves is 2 mu N
// whatever way the drag runs; wiggles are the texture the AR model describes.
import { dragFrameForces, frictionInWindow } from './drag_frame.js';
import { niceTicks } from './ticks.js';

const SVG_NS = 'http://www.w3.org/2000/svg';
const W = 380;
const H = 420;
const M = { left: 42, right: 10, top: 22, bottom: 28 };

function el(name, attrs, text) {
  const node = document.createElementNS(SVG_NS, name);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, String(v));
  if (text !== undefined) node.textContent = text;
  return node;
}

// The padded min..max of the values at the samples `pick` accepts.
function rangeOf(arrays, pick, padFraction, minPad) {
  let lo = Infinity;
  let hi = -Infinity;
  for (const values of arrays) {
    for (let i = 0; i < values.length; ++i) {
      if (!pick(i) || values[i] === null) continue;
      lo = Math.min(lo, values[i]);
      hi = Math.max(hi, values[i]);
    }
  }
  const pad = (hi - lo) * padFraction || minPad;
  return [lo - pad, hi + pad];
}

/**
 * Replaces container's content with the plot; `fit` (api form) adds the
 * window, the per-pair mu and the fallback normal. A trace that cannot be
 * framed shows why instead of a plot.
 */
export function drawTracePlot(container, trace, fit) {
  container.replaceChildren();
  for (const key of Object.keys(container.dataset)) delete container.dataset[key];
  let framed;
  try {
    framed = dragFrameForces(trace, fit?.friction?.normal ?? null);
  } catch (err) {
    container.textContent = `cannot plot: ${err.message}`;
    return;
  }
  const s = framed.s;
  const xMax = framed.pathLength;
  const px = (x) => M.left + (x / xMax) * (W - M.left - M.right);
  const svg = el('svg', { viewBox: `0 0 ${W} ${H}`, role: 'img', 'aria-label': `trace ${trace.trace_id}: normal force and friction along the drag` });

  // Panels sharing the path axis: the normal force (~ N) and the force along
  // the drag (~ mu N, with the lateral force on the same scale) differ by an
  // order of magnitude, so each gets its own scale; below them mu =
  // tan(theta/2) of each forward/reverse pair in the window.
  const pairS = (fit && fit.friction && fit.friction.pair_s_mm) || [];
  const pairMu = (fit && fit.friction && fit.friction.pair_mu) || [];
  const withMu = pairMu.length > 0 && pairMu.length === pairS.length;
  const hasWindow = Boolean(fit && fit.friction && fit.friction.window_end_mm > fit.friction.window_start_mm);
  const gap = 14;
  const count = withMu ? 3 : 2;
  const panelH = (H - M.top - M.bottom - gap * (count - 1)) / count;
  const panels = [
    { series: [{ values: framed.normal, colour: '#f0a04b', width: 1.2 }], title: 'normal force (N)', top: M.top },
    {
      series: [{ values: framed.along, colour: '#5ab0ff', width: 1.2 }, { values: framed.lateral, colour: '#9aa3ad', width: 0.8 }],
      title: 'along the drag (blue), lateral (grey), N',
      top: M.top + panelH + gap,
    },
  ];
  for (const panel of panels) {
    const [lo, hi] = rangeOf(panel.series.map((x) => x.values), (i) => s[i] !== null, 0.08, 0.5);
    const bottom = panel.top + panelH;
    const py = (y) => bottom - ((y - lo) / (hi - lo)) * panelH;
    if (hasWindow) {
      const x0 = px(fit.friction.window_start_mm);
      svg.append(el('rect', { x: x0, y: panel.top, width: px(fit.friction.window_end_mm) - x0, height: panelH, fill: '#ffffff', 'fill-opacity': 0.06 }));
    }
    for (const v of niceTicks(lo, hi, 4)) {
      svg.append(el('line', { x1: M.left, x2: W - M.right, y1: py(v), y2: py(v), stroke: v === 0 ? '#4a5260' : '#2e343e' }));
      svg.append(el('text', { x: M.left - 4, y: py(v) + 3, 'text-anchor': 'end' }, String(v)));
    }
    for (const { values, colour, width } of panel.series) {
      for (const [phase, dash] of [['fwd', ''], ['rev', '4 3']]) {
        const pts = [];
        for (let i = 0; i < s.length; ++i) {
          if (trace.phases[i] === phase && s[i] !== null) pts.push(`${px(s[i]).toFixed(1)},${py(values[i]).toFixed(1)}`);
        }
        if (pts.length > 1) {
          svg.append(el('polyline', { points: pts.join(' '), fill: 'none', stroke: colour, 'stroke-width': width, 'stroke-dasharray': dash }));
        }
      }
    }
    svg.append(el('text', { x: W - M.right - 2, y: panel.top + 10, 'text-anchor': 'end' }, panel.title));
  }
  if (withMu) drawPairMu(svg, { top: M.top + 2 * (panelH + gap), height: panelH, px }, pairS, pairMu, fit.friction.mu);
  for (const v of niceTicks(0, xMax, 6)) {
    svg.append(el('text', { x: px(v), y: H - M.bottom + 12, 'text-anchor': 'middle' }, String(v)));
  }
  svg.append(el('text', { x: (M.left + W - M.right) / 2, y: H - 4, 'text-anchor': 'middle' }, 'position along the path (mm); shaded: fit window'));
  const legend = [['forward', ''], ['reverse', '4 3']];
  legend.forEach(([label, dash], k) => {
    const x = M.left + k * 90;
    svg.append(el('line', { x1: x, x2: x + 18, y1: 10, y2: 10, stroke: '#d8dde5', 'stroke-dasharray': dash, 'stroke-width': 1.5 }));
    svg.append(el('text', { x: x + 22, y: 13 }, label));
  });
  container.append(svg);

  // What the plot shows, for people debugging and the browser test: the mean
  // forces over the fit's window (the middle 80 % of the path without one)
  // and the friction they imply, (along_rev - along_fwd) / (2 normal).
  const [w0, w1] = hasWindow ? [fit.friction.window_start_mm, fit.friction.window_end_mm] : [0.1 * xMax, 0.9 * xMax];
  const seen = frictionInWindow(trace, framed, w0, w1);
  container.dataset.traceId = String(trace.trace_id);
  container.dataset.pointCount = String(trace.t.length);
  container.dataset.pairCount = String(withMu ? pairMu.length : 0);
  container.dataset.normalSource = framed.normalSource;
  if (seen) {
    container.dataset.plotMu = seen.mu.toFixed(4);
    container.dataset.alongFwd = seen.fwd.along.toFixed(4);
    container.dataset.alongRev = seen.rev.along.toFixed(4);
    container.dataset.normalMean = ((seen.fwd.normal + seen.rev.normal) / 2).toFixed(4);
    container.dataset.lateralMean = ((seen.fwd.lateral + seen.rev.lateral) / 2).toFixed(4);
  }
}

// The estimator's per-pair mu (dots) and its mean (line), on the path axis.
function drawPairMu(svg, { top, height, px }, s, mu, mean) {
  let lo = Math.min(...mu, mean);
  let hi = Math.max(...mu, mean);
  const pad = (hi - lo) * 0.08 || 0.02;
  lo -= pad;
  hi += pad;
  const py = (y) => top + height - ((y - lo) / (hi - lo)) * height;
  for (const v of niceTicks(lo, hi, 3)) {
    svg.append(el('line', { x1: M.left, x2: W - M.right, y1: py(v), y2: py(v), stroke: '#2e343e' }));
    svg.append(el('text', { x: M.left - 4, y: py(v) + 3, 'text-anchor': 'end' }, String(v)));
  }
  const dots = el('g', { class: 'pair-mu', fill: '#c8e06a' });
  for (let i = 0; i < mu.length; ++i) dots.append(el('circle', { cx: px(s[i]).toFixed(1), cy: py(mu[i]).toFixed(1), r: 1.4 }));
  svg.append(dots);
  svg.append(el('line', { x1: px(s[0]), x2: px(s[s.length - 1]), y1: py(mean), y2: py(mean), stroke: '#ff6b6b', 'stroke-width': 1.2 }));
  svg.append(el('text', { x: W - M.right - 2, y: top + 10, 'text-anchor': 'end' }, `mu per pair (mean ${mean.toFixed(4)})`));
}
