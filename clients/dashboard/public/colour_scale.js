// What the surface can be coloured by, the colour map and the legend.
// Viridis (perceptually uniform, readable in grey scale and by most colour-blind
// viewers). mu is shown on a fixed range by default (0..1: colours compare
// between jobs, and the estimator's noise on a uniform object stays one
// colour); the other quantities on the data's own min..max, never narrower
// than MIN_SPANS (so 0.001 of noise is not stretched over the whole map).
// Legend ticks are round values chosen by the range, with the digits it needs.
import { niceTicks, stepDecimals, tickStep } from './ticks.js';

export const QUANTITIES = Object.freeze({
  mu: { label: 'friction coefficient mu', unit: '' },
  mu_uncertainty: { label: 'uncertainty of mu (std)', unit: '' },
  sigma: { label: 'roughness sigma', unit: 'N' },
  a1: { label: 'roughness AR a1', unit: '' },
  a2: { label: 'roughness AR a2', unit: '' },
});

// matplotlib's viridis at 0, 1/8, ..., 1 (sRGB).
const STOPS = [
  [0x44, 0x01, 0x54], [0x48, 0x28, 0x78], [0x3e, 0x49, 0x89], [0x31, 0x68, 0x8e], [0x26, 0x82, 0x8e],
  [0x1f, 0x9e, 0x89], [0x35, 0xb7, 0x79], [0x6e, 0xce, 0x58], [0xfd, 0xe7, 0x25],
];

/** t in [0, 1] -> [r, g, b] in [0, 1] (sRGB). NaN -> grey. */
export function viridis(t) {
  if (!Number.isFinite(t)) return [0.5, 0.5, 0.5];
  const x = Math.min(1, Math.max(0, t)) * (STOPS.length - 1);
  const i = Math.min(STOPS.length - 2, Math.floor(x));
  const f = x - i;
  const a = STOPS[i];
  const b = STOPS[i + 1];
  return [0, 1, 2].map((k) => (a[k] + (b[k] - a[k]) * f) / 255);
}

/** The finite min..max of the values; a flat field gets a small window around it. */
export function valueRange(values) {
  let lo = Infinity;
  let hi = -Infinity;
  for (const v of values) {
    if (Number.isFinite(v)) {
      if (v < lo) lo = v;
      if (v > hi) hi = v;
    }
  }
  if (lo === Infinity) return null;
  if (hi - lo < 1e-9) {
    const pad = Math.max(Math.abs(lo) * 0.01, 1e-6);
    return { min: lo - pad, max: hi + pad };
  }
  return { min: lo, max: hi };
}

/** Default fixed ranges: the span each quantity takes on real surfaces
 * (mu of the paper's materials lies in 0..1; a stationary AR(2) has
 * |a1| < 2 and |a2| < 1). */
export const FIXED_RANGES = Object.freeze({
  mu: Object.freeze([0, 1]),
  mu_uncertainty: Object.freeze([0, 0.1]),
  sigma: Object.freeze([0, 0.5]),
  a1: Object.freeze([-2, 2]),
  a2: Object.freeze([-1, 1]),
});

/** The scale each quantity starts with: mu fixed, the rest the data range. */
export const DEFAULT_SCALE_MODES = Object.freeze({
  mu: 'fixed', mu_uncertainty: 'data', sigma: 'data', a1: 'data', a2: 'data',
});

/** The narrowest data range shown per quantity: about the estimator's own
 * scatter on one material (mu 0.02: repeat drags on glass scatter by ~0.005;
 * AR coefficients carry standard errors ~0.07). */
export const MIN_SPANS = Object.freeze({
  mu: 0.02, mu_uncertainty: 0.002, sigma: 0.01, a1: 0.1, a2: 0.1,
});

/** The data range widened about its centre to at least minSpan; `widened` says whether it was. */
export function widenRange(range, minSpan) {
  if (!(minSpan > 0) || range.max - range.min >= minSpan) return { range, widened: false };
  const centre = (range.min + range.max) / 2;
  return { range: { min: centre - minSpan / 2, max: centre + minSpan / 2 }, widened: true };
}

/**
 * The colour range for `values` under `scale` ({ mode: 'data', minSpan } or
 * { mode: 'fixed', min, max }). Returns { range, outside, error, note }:
 * range null when there is no finite value; `outside` counts finite values
 * beyond a fixed range (drawn at its end colours); an unusable fixed range
 * (not two numbers with min < max) falls back to the data range and says
 * why in `error`; `note` says when the data range was widened to minSpan.
 */
export function chooseRange(values, scale) {
  const raw = valueRange(values);
  if (!raw) return { range: null, outside: 0, error: '', note: '' };
  const minSpan = scale && scale.minSpan ? scale.minSpan : 0;
  const { range: data, widened } = widenRange(raw, minSpan);
  const note = widened
    ? `data span ${formatSpan(raw.max - raw.min)} < ${minSpan}: scale widened to ${minSpan} about the data`
    : '';
  if (!scale || scale.mode !== 'fixed') return { range: data, outside: 0, error: '', note };
  const min = typeof scale.min === 'number' ? scale.min : Number.parseFloat(scale.min);
  const max = typeof scale.max === 'number' ? scale.max : Number.parseFloat(scale.max);
  if (!Number.isFinite(min) || !Number.isFinite(max) || !(max > min)) {
    return {
      range: data,
      outside: 0,
      error: `fixed scale needs two numbers with min < max (got "${scale.min}" .. "${scale.max}"); showing the data range`,
      note,
    };
  }
  let outside = 0;
  for (const v of values) if (Number.isFinite(v) && (v < min || v > max)) outside += 1;
  return { range: { min, max }, outside, error: '', note: '' };
}

function formatSpan(span) {
  return span > 0 ? span.toPrecision(2) : '0';
}

/**
 * The legend's ticks for a range: round values inside it (about five),
 * each { value, frac (0 = top = max), text } with the decimals the step
 * needs, so a narrow range reads 0.1296 0.1298 ... not 0.130 0.130 ...
 */
export function legendTicks(range) {
  const step = tickStep(range.min, range.max, 5);
  const decimals = stepDecimals(step);
  return niceTicks(range.min, range.max, 5).map((value) => ({
    value,
    frac: (range.max - value) / (range.max - range.min),
    text: value.toFixed(decimals),
  }));
}

/** Draws the bar (max at the top) and its tick labels (legendTicks). */
export function drawLegend({ titleEl, barCanvas, ticksEl }, quantity, range) {
  const q = QUANTITIES[quantity];
  titleEl.textContent = q.unit ? `${q.label} (${q.unit})` : q.label;
  const ctx = barCanvas.getContext('2d');
  const h = barCanvas.height;
  for (let y = 0; y < h; ++y) {
    const [r, g, b] = viridis(1 - y / (h - 1));
    ctx.fillStyle = `rgb(${Math.round(r * 255)},${Math.round(g * 255)},${Math.round(b * 255)})`;
    ctx.fillRect(0, y, barCanvas.width, 1);
  }
  ticksEl.replaceChildren();
  for (const tick of legendTicks(range)) {
    const span = document.createElement('span');
    span.style.top = `${tick.frac * 100}%`;
    span.dataset.value = String(tick.value);
    span.textContent = tick.text;
    ticksEl.append(span);
  }
}
