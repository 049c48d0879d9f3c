// A drag trace as an inline SVG: fz and fx (N), and the fit's per-pair mu when
// the sample carries it, in panels along the path (mm from the
// start of the forward pass; the reverse pass runs back over the same path, so
// it is plotted at the same positions), forward solid, reverse dashed, the
// pause left out (the probe does not move), and the fit's data window shaded.
// Reading it: where the two passes' fx separate symmetrically the friction is
// Coulomb-like; wiggles are the texture the AR model describes.

const SVG_NS = 'http://www.w3.org/2000/svg';
const W = 380;
const H = 340;
const M = { left: 42, right: 10, top: 22, bottom: 28 };

function el(name, attrs, text) {
  const node = document.createElementNS(SVG_NS, name);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, String(v));
  if (text !== undefined) node.textContent = text;
  return node;
}

/** Arc-length position along the path per sample; null for pause samples. */
export function pathPositions(trace) {
  const n = trace.t.length;
  const s = new Array(n).fill(null);
  let fwdLength = 0;
  let last = -1;
  for (let i = 0; i < n; ++i) {
    if (trace.phases[i] !== 'fwd') continue;
    if (last >= 0) fwdLength += Math.hypot(trace.x[i] - trace.x[last], trace.y[i] - trace.y[last], trace.z[i] - trace.z[last]);
    s[i] = fwdLength;
    last = i;
  }
  let back = 0;
  last = -1;
  for (let i = 0; i < n; ++i) {
    if (trace.phases[i] !== 'rev') continue;
    if (last >= 0) back += Math.hypot(trace.x[i] - trace.x[last], trace.y[i] - trace.y[last], trace.z[i] - trace.z[last]);
    s[i] = fwdLength - back;
    last = i;
  }
  return s;
}

function niceTicks(lo, hi, count) {
  const span = hi - lo;
  const raw = span / count;
  const mag = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 5, 10].map((k) => k * mag).find((k) => span / k <= count) ?? 10 * mag;
  const ticks = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + 1e-9; v += step) ticks.push(Number(v.toPrecision(12)));
  return ticks;
}

/** Replaces container's content with the plot; `fit` (api form) adds the window. */
export function drawTracePlot(container, trace, fit) {
  container.replaceChildren();
  const s = pathPositions(trace);
  let xMax = 0;
  for (const v of s) if (v !== null) xMax = Math.max(xMax, v);
  if (xMax <= 0) {
    container.textContent = 'trace has no moving samples';
    return;
  }
  const px = (x) => M.left + (x / xMax) * (W - M.left - M.right);
  const svg = el('svg', { viewBox: `0 0 ${W} ${H}`, role: 'img', 'aria-label': `trace ${trace.trace_id}: fx and fz along the path` });

  // Panels sharing the path axis: fz (~ the normal force) and fx (~ the
  // friction) differ by an order of magnitude, so each gets its own scale;
  // below them mu = tan(theta/2) of each forward/reverse pair in the window.
  const pairS = (fit && fit.friction && fit.friction.pair_s_mm) || [];
  const pairMu = (fit && fit.friction && fit.friction.pair_mu) || [];
  const withMu = pairMu.length > 0 && pairMu.length === pairS.length;
  const gap = 14;
  const count = withMu ? 3 : 2;
  const panelH = (H - M.top - M.bottom - gap * (count - 1)) / count;
  const panels = [
    { key: 'fz', top: M.top, colour: '#f0a04b' },
    { key: 'fx', top: M.top + panelH + gap, colour: '#5ab0ff' },
  ];
  for (const panel of panels) {
    let lo = Infinity;
    let hi = -Infinity;
    for (let i = 0; i < s.length; ++i) {
      if (s[i] === null) continue;
      lo = Math.min(lo, trace[panel.key][i]);
      hi = Math.max(hi, trace[panel.key][i]);
    }
    const pad = (hi - lo) * 0.08 || 0.5;
    lo -= pad;
    hi += pad;
    const bottom = panel.top + panelH;
    const py = (y) => bottom - ((y - lo) / (hi - lo)) * panelH;
    if (fit && fit.friction && fit.friction.window_end_mm > fit.friction.window_start_mm) {
      const x0 = px(fit.friction.window_start_mm);
      svg.append(el('rect', { x: x0, y: panel.top, width: px(fit.friction.window_end_mm) - x0, height: panelH, fill: '#ffffff', 'fill-opacity': 0.06 }));
    }
    for (const v of niceTicks(lo, hi, 4)) {
      svg.append(el('line', { x1: M.left, x2: W - M.right, y1: py(v), y2: py(v), stroke: '#2e343e' }));
      svg.append(el('text', { x: M.left - 4, y: py(v) + 3, 'text-anchor': 'end' }, String(v)));
    }
    for (const [phase, dash] of [['fwd', ''], ['rev', '4 3']]) {
      const pts = [];
      for (let i = 0; i < s.length; ++i) {
        if (trace.phases[i] === phase && s[i] !== null) pts.push(`${px(s[i]).toFixed(1)},${py(trace[panel.key][i]).toFixed(1)}`);
      }
      if (pts.length > 1) {
        svg.append(el('polyline', { points: pts.join(' '), fill: 'none', stroke: panel.colour, 'stroke-width': 1.2, 'stroke-dasharray': dash }));
      }
    }
    svg.append(el('text', { x: W - M.right - 2, y: panel.top + 10, 'text-anchor': 'end' }, `${panel.key} (N)`));
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
  container.dataset.traceId = String(trace.trace_id);
  container.dataset.pointCount = String(trace.t.length);
  container.dataset.pairCount = String(withMu ? pairMu.length : 0);
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
