// JobWatchHub against a fake WatchJob stream: one stream per job however many
// subscribers, closed when the last leaves, map updates coalesced, the final
// map never dropped, failures passed on with their code name.
import assert from 'node:assert/strict';
import { EventEmitter } from 'node:events';
import { test } from 'node:test';
import { JobWatchHub } from './job_watch_hub.js';

class FakeStream extends EventEmitter {
  constructor(jobId) {
    super();
    this.jobId = jobId;
    this.cancelled = false;
  }
  cancel() {
    this.cancelled = true;
    // grpc-js reports its own cancel as an error with code CANCELLED.
    this.emit('error', Object.assign(new Error('1 CANCELLED'), { code: 1, details: 'Cancelled on client' }));
  }
}

function fakeHub(mapIntervalMs = 0) {
  const streams = [];
  const hub = new JobWatchHub({
    openStream: (jobId) => {
      const s = new FakeStream(jobId);
      streams.push(s);
      return s;
    },
    mapIntervalMs,
  });
  return { hub, streams };
}

function recordingSink() {
  const sink = { events: [], closed: false };
  sink.send = (event, data) => sink.events.push([event, data]);
  sink.close = () => { sink.closed = true; };
  return sink;
}

function jobUpdate(measured, state = 'JOB_STATE_RUNNING', withMap = true) {
  return {
    job: {
      job_id: 7, state, spec: { object_id: 1, property: 'PROPERTY_FRICTION', mode: 'SAMPLING_MODE_ADAPTIVE' },
      progress: { measured, pending: 0, issued: 10 - measured, failed: 0, skipped: 0, budget_left: -1, complete: false, levels: [] },
    },
    map: withMap ? { job_id: 7, level: 1, vertex_count: 2, mu: [measured / 10, 0.5], mu_uncertainty: [0, 0], sigma: [0, 0], a1: [0, 0], a2: [0, 0], samples: [] } : null,
  };
}

test('two subscribers share one WatchJob stream, which closes when both leave', () => {
  const { hub, streams } = fakeHub();
  const a = recordingSink();
  const b = recordingSink();
  const leaveA = hub.subscribe(7, a);
  const leaveB = hub.subscribe(7, b);
  assert.equal(streams.length, 1);
  assert.deepEqual(hub.stats(), [{ job_id: 7, subscribers: 2, updates: 0, maps_sent: 0 }]);

  streams[0].emit('data', jobUpdate(3));
  for (const sink of [a, b]) {
    assert.deepEqual(sink.events.map(([e]) => e), ['job', 'map']);
    assert.equal(sink.events[0][1].progress.measured, 3);
    assert.equal(sink.events[0][1].state, 'RUNNING');
  }

  leaveA();
  assert.equal(streams[0].cancelled, false, 'one subscriber is still watching');
  leaveB();
  assert.equal(streams[0].cancelled, true);
  assert.deepEqual(hub.stats(), []);
  assert.equal(a.events.some(([e]) => e === 'failure'), false, 'our own cancel is not a failure');
});

test('a late subscriber gets the latest job and map at once', () => {
  const { hub, streams } = fakeHub();
  hub.subscribe(7, recordingSink());
  streams[0].emit('data', jobUpdate(4));
  const late = recordingSink();
  hub.subscribe(7, late);
  assert.equal(streams.length, 1);
  assert.deepEqual(late.events.map(([e]) => e), ['job', 'map']);
  assert.equal(late.events[1][1].mu[0], 0.4);
});

test('different jobs get different streams', () => {
  const { hub, streams } = fakeHub();
  hub.subscribe(7, recordingSink());
  hub.subscribe(8, recordingSink());
  assert.deepEqual(streams.map((s) => s.jobId), [7, 8]);
});

test('maps are coalesced to one per interval and the last one is delivered at the end', () => {
  const { hub, streams } = fakeHub(60000);  // far longer than the test
  const sink = recordingSink();
  hub.subscribe(7, sink);
  for (let m = 1; m <= 5; ++m) streams[0].emit('data', jobUpdate(m));
  const maps = () => sink.events.filter(([e]) => e === 'map').map(([, d]) => d.mu[0]);
  const jobs = sink.events.filter(([e]) => e === 'job').map(([, d]) => d.progress.measured);
  assert.deepEqual(jobs, [1, 2, 3, 4, 5], 'every progress update goes out');
  assert.deepEqual(maps(), [0.1], 'the first map at once, the rest wait for the interval');

  streams[0].emit('data', jobUpdate(10, 'JOB_STATE_COMPLETED'));
  streams[0].emit('end');
  assert.deepEqual(maps(), [0.1, 1.0], 'the final map is flushed before the end');
  const last = sink.events.at(-1);
  assert.equal(last[0], 'end');
  assert.equal(last[1].job.state, 'COMPLETED');
  assert.equal(sink.closed, true);
  assert.deepEqual(hub.stats(), []);
});

test('a failing stream reports the status name and message, then closes subscribers', () => {
  const { hub, streams } = fakeHub();
  const sink = recordingSink();
  hub.subscribe(7, sink);
  streams[0].emit('error', Object.assign(new Error('5 NOT_FOUND'), { code: 5, details: 'job 7 does not exist' }));
  assert.deepEqual(sink.events, [['failure', { code: 'NOT_FOUND', message: 'surfmapd: job 7 does not exist' }]]);
  assert.equal(sink.closed, true);
  // A new subscriber opens a new stream (e.g. after the server came back).
  hub.subscribe(7, recordingSink());
  assert.equal(streams.length, 2);
});

test('a sink that throws is dropped without disturbing the others', () => {
  const { hub, streams } = fakeHub();
  const bad = { send() { throw new Error('socket gone'); }, close() {} };
  const good = recordingSink();
  hub.subscribe(7, bad);
  hub.subscribe(7, good);
  streams[0].emit('data', jobUpdate(2, 'JOB_STATE_RUNNING', false));
  assert.deepEqual(good.events.map(([e]) => e), ['job']);
  assert.equal(hub.stats()[0].subscribers, 1);
});
