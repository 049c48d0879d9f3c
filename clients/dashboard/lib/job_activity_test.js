// The operator's view of a job's event log (public/job_activity.js): rigs,
// failures, rate and time to completion from events in the API's form.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { JobActivity, RECENT_LIMIT, describeEvent, formatDuration } from '../public/job_activity.js';

const T0 = Date.parse('2026-01-05T10:00:00.000Z');
let nextId = 1;
function event(kind, detail, secondsAfterT0) {
  return { event_id: nextId++, job_id: 3, time: new Date(T0 + secondsAfterT0 * 1000).toISOString(), kind, detail };
}
const accepted = (rig, s, extra = {}) => event('trace_accepted', { command_id: nextId, level: 0, vertex: 4, mu: 0.13, rig, ...extra }, s);

test('counts per rig, failures kept, repeated pages ignored', () => {
  const a = new JobActivity(3);
  const page = [
    event('job_created', { initial_commands: 82 }, 0),
    accepted('rig-a', 1), accepted('rig-b', 1.5), accepted('rig-a', 2),
    event('probe_failed', { command_id: 9, reason: 'force limit tripped', kind: 'transient', rig: 'rig-b', will_retry: true }, 3),
  ];
  assert.equal(a.add(page), 5);
  assert.equal(a.add(page), 0, 'the same page again adds nothing');
  assert.equal(a.cursor, page.at(-1).event_id);
  assert.deepEqual(a.rigs().map((r) => [r.rig, r.accepted, r.failed]), [['rig-a', 2, 0], ['rig-b', 1, 1]]);
  assert.equal(a.rigs()[1].last_time_ms, T0 + 3000);
  assert.equal(a.failures.length, 1);
  assert.equal(a.failures[0].detail.reason, 'force limit tripped');
});

test('rate over the last 30 s of event time; ETA for the sites known now', () => {
  const a = new JobActivity(3);
  assert.equal(a.rate(), null);
  // 10 traces over the first 90 s (slow), then 31 over the last 30 s (1/s).
  const events = [];
  for (let k = 0; k < 10; ++k) events.push(accepted('rig-a', k * 10));
  for (let k = 0; k <= 30; ++k) events.push(accepted('rig-a', 100 + k));
  a.add(events);
  const r = a.rate();
  assert.equal(r.count, 31);
  assert.ok(Math.abs(r.perSecond - 1) < 1e-9, `rate ${r.perSecond}`);
  const eta = a.eta({ pending: 40, issued: 20 }, 'RUNNING');
  assert.equal(eta.remaining, 60);
  assert.ok(Math.abs(eta.seconds - 60) < 1e-9);
  assert.equal(eta.text, '~1 min 00 s for the 60 sites known now');
  assert.equal(a.eta({ pending: 0, issued: 0 }, 'RUNNING').text, 'no sites left to measure');
  assert.equal(a.eta({ pending: 3, issued: 0 }, 'PAUSED').seconds, null);
});

test('one trace in the window: the rate of the last two', () => {
  const a = new JobActivity(3);
  a.add([accepted('r', 0), accepted('r', 100)]);
  assert.ok(Math.abs(a.rate().perSecond - 0.01) < 1e-12);
  assert.equal(new JobActivity(3).eta({ pending: 2, issued: 1 }, 'RUNNING').text, '3 sites left; rate not known yet');
});

test('the recent list is bounded; events read as one line each', () => {
  const a = new JobActivity(3);
  const many = [];
  for (let k = 0; k < RECENT_LIMIT + 50; ++k) many.push(accepted('r', k));
  a.add(many);
  assert.equal(a.recent.length, RECENT_LIMIT);
  assert.equal(a.recent.at(-1).event_id, many.at(-1).event_id);
  assert.equal(a.eventCount, RECENT_LIMIT + 50);
  assert.equal(describeEvent(accepted('rig-a', 0, { level: 1, vertex: 17, mu: 0.5012 })), 'L1 v17 measured by rig-a, mu 0.501');
  assert.equal(describeEvent(event('probe_failed', { command_id: 4, reason: 'outside the workspace', kind: 'unreachable', rig: 'arm-2', will_retry: false }, 0)),
    'command 4 failed at arm-2 (unreachable, given up): outside the workspace');
  assert.equal(describeEvent(event('job_state', { from: 'RUNNING', to: 'PAUSED' }, 0)), 'RUNNING -> PAUSED');
  assert.equal(describeEvent({ event_id: 5, kind: 'probe_failed', detail: null, detail_error: 'event 5: detail_json is not JSON' }),
    'event 5: detail_json is not JSON');
  assert.equal(describeEvent(event('new_kind', { a: 1 }, 0)), 'new_kind {"a":1}');
});

test('durations read as people say them', () => {
  assert.equal(formatDuration(8.4), '8.4 s');
  assert.equal(formatDuration(12.4), '12 s');
  assert.equal(formatDuration(75), '1 min 15 s');
  assert.equal(formatDuration(3725), '1 h 02 min');
  assert.equal(formatDuration(NaN), '-');
});
