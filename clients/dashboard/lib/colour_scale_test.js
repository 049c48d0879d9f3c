// The page's colour range and legend ticks (public/colour_scale.js and
// public/ticks.js, plain ES modules, no DOM needed for these functions): data
// range, its minimum span, fixed range, what a bad fixed range does, and
// ticks that stay distinct on a narrow range.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import {
  DEFAULT_SCALE_MODES, FIXED_RANGES, MIN_SPANS, chooseRange, legendTicks, valueRange,
} from '../public/colour_scale.js';
import { niceTicks, stepDecimals } from '../public/ticks.js';

test('the data range ignores NaN and pads a flat field', () => {
  assert.deepEqual(valueRange([0.2, NaN, 0.5, 0.3]), { min: 0.2, max: 0.5 });
  const flat = valueRange([0.4, 0.4]);
  assert.ok(flat.min < 0.4 && flat.max > 0.4);
  assert.equal(valueRange([NaN]), null);
});

test('data mode is the data range; no values gives no range', () => {
  assert.deepEqual(chooseRange([0.1, 0.6], { mode: 'data', min: 0, max: 1 }), {
    range: { min: 0.1, max: 0.6 },
    outside: 0,
    error: '',
    note: '',
  });
  assert.equal(chooseRange([], { mode: 'fixed', min: 0, max: 1 }).range, null);
});

test('fixed mode uses the limits, typed or numeric, and counts values beyond them', () => {
  const r = chooseRange([-0.1, 0.2, 0.5, 1.3, NaN], { mode: 'fixed', min: '0', max: 1 });
  assert.deepEqual(r.range, { min: 0, max: 1 });
  assert.equal(r.outside, 2);
  assert.equal(r.error, '');
});

test('an unusable fixed range falls back to the data range and says why', () => {
  for (const [min, max] of [['', 1], ['-', 1], [1, 1], [2, 1], [0, 'abc']]) {
    const r = chooseRange([0.2, 0.4], { mode: 'fixed', min, max });
    assert.deepEqual(r.range, { min: 0.2, max: 0.4 }, `${min}..${max}`);
    assert.match(r.error, /min < max/, `${min}..${max}`);
  }
});

test('every quantity has a default fixed range with min < max', () => {
  for (const q of ['mu', 'mu_uncertainty', 'sigma', 'a1', 'a2']) {
    const [min, max] = FIXED_RANGES[q];
    assert.ok(min < max, q);
  }
});

test('a data range narrower than the minimum span is widened about its centre, and says so', () => {
  const noise = [0.1296, 0.1301, 0.1305, 0.1299];
  const r = chooseRange(noise, { mode: 'data', minSpan: MIN_SPANS.mu });
  assert.ok(Math.abs(r.range.min - 0.12005) < 1e-12 && Math.abs(r.range.max - 0.14005) < 1e-12, JSON.stringify(r.range));
  assert.match(r.note, /data span 0\.00090 < 0\.02: scale widened/);
  const wide = chooseRange([0.1, 0.5], { mode: 'data', minSpan: MIN_SPANS.mu });
  assert.deepEqual(wide.range, { min: 0.1, max: 0.5 });
  assert.equal(wide.note, '');
});

test('mu starts on the fixed scale, the others on the data range', () => {
  assert.equal(DEFAULT_SCALE_MODES.mu, 'fixed');
  for (const q of ['mu_uncertainty', 'sigma', 'a1', 'a2']) {
    assert.equal(DEFAULT_SCALE_MODES[q], 'data', q);
    assert.ok(MIN_SPANS[q] > 0, q);
  }
});

test('legend ticks are round values inside the range, distinct even when it is narrow', () => {
  const narrow = legendTicks({ min: 0.1295, max: 0.1305 });
  const texts = narrow.map((t) => t.text);
  assert.deepEqual(texts, ['0.1296', '0.1298', '0.1300', '0.1302', '0.1304']);
  assert.equal(new Set(texts).size, texts.length);
  for (const t of narrow) assert.ok(t.frac >= 0 && t.frac <= 1 && Math.abs(t.frac - (0.1305 - t.value) / 0.001) < 1e-9);
  assert.deepEqual(legendTicks({ min: 0, max: 1 }).map((t) => t.text), ['0.0', '0.2', '0.4', '0.6', '0.8', '1.0']);
  assert.deepEqual(legendTicks({ min: -2, max: 2 }).map((t) => t.text), ['-2', '-1', '0', '1', '2']);
  assert.deepEqual(legendTicks({ min: 0.118, max: 0.512 }).map((t) => t.text), ['0.2', '0.3', '0.4', '0.5']);
});

test('ticks: steps of 1, 2, 5 x 10^k and the decimals they need; a bad range is named', () => {
  assert.deepEqual(niceTicks(0, 20, 6), [0, 5, 10, 15, 20]);
  assert.deepEqual(niceTicks(-0.31, 0.29, 4), [-0.2, 0, 0.2]);
  assert.equal(stepDecimals(0.02), 2);
  assert.equal(stepDecimals(0.0005), 4);
  assert.equal(stepDecimals(5), 0);
  assert.throws(() => niceTicks(1, 1, 5), /lo < hi/);
  assert.throws(() => niceTicks(0, NaN, 5), /finite range/);
});
