// The page's colour range (public/colour_scale.js, plain ES module, no DOM
// needed for these functions): data range, fixed range, and what a bad fixed
// range does.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { FIXED_RANGES, chooseRange, valueRange } from '../public/colour_scale.js';

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
