// Axis and legend ticks: round values chosen by the range, and as many
// decimals as tell neighbouring ticks apart (a narrow range gets more digits
// instead of five equal labels).

/** Round tick values in [lo, hi], at most about `count`, 1, 2 or 5 times a power of ten apart. */
export function niceTicks(lo, hi, count) {
  const span = hi - lo;
  if (!(span > 0) || !Number.isFinite(span) || !(count >= 1)) {
    throw new Error(`ticks need a finite range with lo < hi and count >= 1 (got ${lo}..${hi}, count ${count})`);
  }
  const step = tickStep(lo, hi, count);
  const ticks = [];
  for (let k = Math.ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; ++k) ticks.push(Number((k * step).toPrecision(12)));
  return ticks;
}

/** The spacing niceTicks uses for [lo, hi]. */
export function tickStep(lo, hi, count) {
  const span = hi - lo;
  const mag = 10 ** Math.floor(Math.log10(span / count));
  return [1, 2, 5, 10].map((k) => k * mag).find((k) => span / k <= count * (1 + 1e-9)) ?? 10 * mag;
}

/** Decimals that show a step (0.02 -> 2, 0.0005 -> 4, 5 -> 0). */
export function stepDecimals(step) {
  return Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
}
