// What the surface can be coloured by, the colour map and the legend.
// Viridis (perceptually uniform, readable in grey scale and by most colour-blind
// viewers). The range is the data's own min..max by default, so small contrasts
// show; a fixed range keeps colours comparable between jobs and objects.

export const QUANTITIES = Object.freeze({
  mu: { label: 'friction coefficient mu', unit: '', digits: 3 },
  mu_uncertainty: { label: 'uncertainty of mu (std)', unit: '', digits: 4 },
  sigma: { label: 'roughness sigma', unit: 'N', digits: 4 },
  a1: { label: 'roughness AR a1', unit: '', digits: 3 },
  a2: { label: 'roughness AR a2', unit: '', digits: 3 },
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

/**
 * The colour range for `values` under `scale` ({ mode: 'data' } or
 * { mode: 'fixed', min, max }). Returns { range, outside, error }: range null
 * when there is no finite value; `outside` counts finite values beyond a
 * fixed range (drawn at its end colours); an unusable fixed range (not two
 * numbers with min < max) falls back to the data range and says why.
 */
export function chooseRange(values, scale) {
  const data = valueRange(values);
  if (!data) return { range: null, outside: 0, error: '' };
  if (!scale || scale.mode !== 'fixed') return { range: data, outside: 0, error: '' };
  const min = typeof scale.min === 'number' ? scale.min : Number.parseFloat(scale.min);
  const max = typeof scale.max === 'number' ? scale.max : Number.parseFloat(scale.max);
  if (!Number.isFinite(min) || !Number.isFinite(max) || !(max > min)) {
    return {
      range: data,
      outside: 0,
      error: `fixed scale needs two numbers with min < max (got "${scale.min}" .. "${scale.max}"); showing the data range`,
    };
  }
  let outside = 0;
  for (const v of values) if (Number.isFinite(v) && (v < min || v > max)) outside += 1;
  return { range: { min, max }, outside, error: '' };
}

/** Draws the bar (max at the top) and its five tick labels. */
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
  for (let k = 0; k <= 4; ++k) {
    const frac = k / 4;
    const value = range.max - frac * (range.max - range.min);
    const span = document.createElement('span');
    span.style.top = `${frac * 100}%`;
    span.textContent = value.toFixed(q.digits);
    ticksEl.append(span);
  }
}
