// The HTTP side against a fake surfmapd client: routes and their JSON forms,
// request checks, gRPC errors -> HTTP, read-only methods, static files that
// cannot escape their folders, and the SSE channel sharing one WatchJob.
import assert from 'node:assert/strict';
import { EventEmitter } from 'node:events';
import http from 'node:http';
import { after, before, test } from 'node:test';
import { startDashboardServer } from './dashboard_server.js';

const JOB = {
  job_id: 3, state: 'JOB_STATE_RUNNING',
  spec: { object_id: 1, property: 'PROPERTY_FRICTION', mode: 'SAMPLING_MODE_ADAPTIVE', coarsest_level: 0, finest_level: 1,
    threshold: 2, budget: 0, probe: { segment_length_mm: 20, speed_mm_s: 10, normal_force_n: 5 }, seed: 9, max_retries: 2,
    lease: { seconds: 60, nanos: 500000000 } },
  progress: { measured: 4, pending: 1, issued: 2, failed: 1, skipped: 0, budget_left: -1, complete: false, leased: 1,
    levels: [{ level: 0, measured: 4, pending: 1, issued: 2, failed: 1, leased: 1 }, { level: 1, measured: 0, pending: 0, issued: 0, failed: 0 }] },
  created: { seconds: 1700000000, nanos: 0 },
  updated: { seconds: 0, nanos: 0 },
};

function grpcError(code, details) {
  return Object.assign(new Error(`${code} ${details}`), { code, details });
}

class FakeStream extends EventEmitter {
  cancel() {
    this.cancelled = true;
    this.emit('error', grpcError(1, 'Cancelled on client'));
  }
}

const calls = [];
const streams = [];
const fakeClient = {
  address: 'fake:1',
  async call(method, request) {
    calls.push([method, request]);
    switch (method) {
      case 'ListObjects':
        return { objects: [{ object_id: 1, name: 'bottle', format: 'MESH_FORMAT_OBJ', control_vertex_count: 4, control_face_count: 4, created: { seconds: 1700000000, nanos: 0 } }] };
      case 'GetJob':
        if (request.job_id !== 3) throw grpcError(5, `job ${request.job_id} does not exist`);
        return { job: JOB };
      case 'GetMesh':
        return { object_id: 1, level: request.level, positions: [{ x: 1.23456789, y: 0, z: 0 }, { x: 0, y: 1, z: 0 }, { x: 0, y: 0, z: 1 }],
          normals: [{ x: 1, y: 0, z: 0 }, { x: 0, y: 1, z: 0 }, { x: 0, y: 0, z: 1 }], triangle_indices: [0, 1, 2] };
      case 'QueryMap':
        return { values: request.points.map((p) => ({ surface_point: p, normal: { x: 0, y: 0, z: 1 }, distance_mm: 0, mu: 0.25, mu_uncertainty: 0.01, sigma: 0.1, a1: 0.5, a2: -0.2 })) };
      case 'ListJobEvents': {
        const all = [
          { event_id: 7, job_id: 3, time: { seconds: 1700000000, nanos: 0 }, kind: 'job_created', detail_json: '{"initial_commands":4}' },
          { event_id: 9, job_id: 3, time: { seconds: 1700000001, nanos: 0 }, kind: 'trace_accepted',
            detail_json: '{"command_id":2,"level":0,"vertex":5,"mu":0.13,"rig":"rig-a"}' },
          { event_id: 12, job_id: 3, time: { seconds: 1700000002, nanos: 0 }, kind: 'probe_failed', detail_json: 'not json' },
        ];
        return { events: all.filter((e) => e.event_id > request.after_event_id).slice(0, request.limit) };
      }
      case 'GetTrace':
        return { trace_id: request.trace_id, command_id: 2, job_id: 3,
          samples: { t: [0, 0.1], x: [0, 1], y: [0, 0], z: [0, 0], fx: [-1, 1], fy: [0, 0], fz: [5, 5], phases: ['PHASE_FORWARD', 'PHASE_REVERSE'] } };
      default:
        throw grpcError(12, `fake has no ${method}`);
    }
  },
  watchJob(request) {
    const s = new FakeStream();
    s.request = request;
    streams.push(s);
    return s;
  },
};

let dash;
const logLines = [];
before(async () => {
  dash = await startDashboardServer({ client: fakeClient, host: '127.0.0.1', port: 0, log: (l) => logLines.push(l), mapIntervalMs: 0 });
});
after(async () => { await dash.close(); });

// Raw requests: node's http client sends the path as given (no '..' folding).
function request(path, method = 'GET') {
  return new Promise((resolve, reject) => {
    const req = http.request(`${dash.url}${path}`, { method }, (res) => {
      let body = '';
      res.on('data', (c) => { body += c; });
      res.on('end', () => resolve({ status: res.statusCode, headers: res.headers, body }));
    });
    req.on('error', reject);
    req.end();
  });
}
const getJson = async (path) => {
  const r = await request(path);
  return { status: r.status, json: JSON.parse(r.body) };
};

test('lists objects in the API form', async () => {
  const { status, json } = await getJson('/api/objects');
  assert.equal(status, 200);
  assert.deepEqual(json.objects[0], { object_id: 1, name: 'bottle', format: 'OBJ', control_vertex_count: 4, control_face_count: 4, created: '2023-11-14T22:13:20.000Z' });
});

test('a job: enum prefixes off, durations in seconds, unset timestamps null, total sites', async () => {
  const { status, json } = await getJson('/api/jobs/3');
  assert.equal(status, 200);
  assert.equal(json.job.state, 'RUNNING');
  assert.equal(json.job.spec.mode, 'ADAPTIVE');
  assert.equal(json.job.spec.lease_s, 60.5);
  assert.equal(json.job.updated, null);
  assert.equal(json.job.progress.total, 8);
  assert.equal(json.job.progress.leased, 1);
  assert.deepEqual(json.job.progress.levels.map((l) => l.leased), [1, null], 'an uncounted level is null, not 0');
});

test('gRPC errors keep their code name and message and get the matching HTTP status', async () => {
  const { status, json } = await getJson('/api/jobs/4');
  assert.equal(status, 404);
  assert.deepEqual(json, { error: { code: 'NOT_FOUND', message: 'surfmapd: job 4 does not exist' } });
  const unimplemented = await getJson('/api/jobs/3/samples');
  assert.equal(unimplemented.status, 501);
  assert.equal(unimplemented.json.error.code, 'UNIMPLEMENTED');
});

test('bad ids and parameters are INVALID_ARGUMENT naming the value', async () => {
  let r = await getJson('/api/jobs/0');
  assert.equal(r.status, 400);
  assert.equal(r.json.error.message, "job id '0' is not a positive integer");
  r = await getJson('/api/jobs/3/query?x=1&y=nan&z=0');
  assert.equal(r.status, 400);
  assert.equal(r.json.error.message, "query parameter y='nan' is not a finite number");
  r = await getJson('/api/jobs/3/query?x=1&z=0');
  assert.equal(r.json.error.message, 'query parameter y is missing');
  r = await getJson('/api/objects/1/mesh?level=7');
  assert.equal(r.json.error.message, 'query parameter level=7 is out of range [0, 6]');
});

test('query passes the point and returns its value', async () => {
  const { status, json } = await getJson('/api/jobs/3/query?x=1.5&y=-2&z=3');
  assert.equal(status, 200);
  assert.deepEqual(json.point, { x: 1.5, y: -2, z: 3 });
  assert.equal(json.value.mu, 0.25);
  assert.deepEqual(calls.at(-1), ['QueryMap', { job_id: 3, points: [{ x: 1.5, y: -2, z: 3 }] }]);
});

test('mesh comes flat and rounded; trace phases as words', async () => {
  const mesh = (await getJson('/api/objects/1/mesh?level=2')).json.mesh;
  assert.equal(mesh.level, 2);
  assert.deepEqual(mesh.positions, [1.2346, 0, 0, 0, 1, 0, 0, 0, 1]);
  assert.deepEqual(mesh.triangles, [0, 1, 2]);
  assert.equal(mesh.triangle_count, 1);
  const trace = (await getJson('/api/traces/5')).json.trace;
  assert.deepEqual(trace.phases, ['fwd', 'rev']);
  assert.equal(trace.sample_count, 2);
});

test('event log: a cursor and a limit, detail parsed, bad detail named, bad cursor refused', async () => {
  let r = await getJson('/api/jobs/3/event-log?after=7&limit=5');
  assert.equal(r.status, 200);
  assert.deepEqual(calls.at(-1), ['ListJobEvents', { job_id: 3, after_event_id: 7, limit: 5 }]);
  assert.equal(r.json.next_after, 12);
  assert.deepEqual(r.json.events[0], {
    event_id: 9, job_id: 3, time: '2023-11-14T22:13:21.000Z', kind: 'trace_accepted',
    detail: { command_id: 2, level: 0, vertex: 5, mu: 0.13, rig: 'rig-a' },
  });
  assert.equal(r.json.events[1].detail, null);
  assert.match(r.json.events[1].detail_error, /^event 12: detail_json is not JSON/);
  r = await getJson('/api/jobs/3/event-log');
  assert.deepEqual(calls.at(-1), ['ListJobEvents', { job_id: 3, after_event_id: 0, limit: 1000 }]);
  assert.equal(r.json.events.length, 3);
  r = await getJson('/api/jobs/3/event-log?after=12');
  assert.deepEqual([r.json.events, r.json.next_after], [[], 12], 'nothing new: the cursor stays');
  r = await getJson('/api/jobs/3/event-log?after=-1');
  assert.equal(r.status, 400);
  assert.equal(r.json.error.message, "query parameter after='-1' is not a non-negative integer");
  r = await getJson('/api/jobs/3/event-log?limit=10001');
  assert.equal(r.json.error.message, 'query parameter limit=10001 is out of range [1, 10000]');
});

test('only GET and HEAD: the dashboard is read-only', async () => {
  for (const method of ['POST', 'PUT', 'DELETE', 'PATCH']) {
    const r = await request('/api/jobs/3', method);
    assert.equal(r.status, 405, method);
    assert.equal(r.headers.allow, 'GET, HEAD');
  }
});

test('static files: the page and three.js are served, nothing outside their folders', async () => {
  const page = await request('/');
  assert.equal(page.status, 200);
  assert.match(page.body, /importmap/);
  const three = await request('/vendor/three/build/three.module.js', 'HEAD');
  assert.equal(three.status, 200);
  assert.match(three.headers['content-type'], /javascript/);
  for (const path of ['/app/../server.js', '/app/..%2fserver.js', '/vendor/three/package.json', '/vendor/three/build/../../../package.json', '/etc/passwd']) {
    assert.equal((await request(path)).status, 404, path);
  }
});

test('one log line per request', async () => {
  const before = logLines.length;
  await request('/api/objects');
  await new Promise((r) => setTimeout(r, 20));
  const lines = logLines.slice(before);
  assert.equal(lines.length, 1);
  assert.match(lines[0], /^\S+Z GET \/api\/objects 200 [0-9.]+ms [0-9]+B$/);
});

// Reads an SSE response until `count` events arrived; resolves with them and the request.
function readEvents(path, count) {
  return new Promise((resolve, reject) => {
    const events = [];
    const req = http.get(`${dash.url}${path}`, (res) => {
      let buf = '';
      res.on('data', (chunk) => {
        buf += chunk;
        let idx;
        while ((idx = buf.indexOf('\n\n')) >= 0) {
          const block = buf.slice(0, idx);
          buf = buf.slice(idx + 2);
          const event = /^event: (.*)$/m.exec(block);
          const data = /^data: (.*)$/m.exec(block);
          if (event) events.push([event[1], JSON.parse(data[1])]);
          if (events.length === count) resolve({ events, req, res });
        }
      });
    });
    req.on('error', reject);
  });
}

const waitFor = async (pred, what) => {
  for (let i = 0; i < 200; ++i) {
    if (pred()) return;
    await new Promise((r) => setTimeout(r, 10));
  }
  assert.fail(`timed out waiting for ${what}`);
};

test('SSE: two browsers share one WatchJob (with the map); it is cancelled when both leave', async () => {
  const first = readEvents('/api/jobs/3/events', 1);
  await waitFor(() => streams.length === 1, 'the stream to open');
  const second = readEvents('/api/jobs/3/events', 1);
  await waitFor(() => dash.hub.stats()[0]?.subscribers === 2, 'two subscribers');
  assert.equal(streams.length, 1);
  assert.deepEqual(streams[0].request, { job_id: 3, include_map: true });
  streams[0].emit('data', { job: JOB, map: null });
  const [a, b] = await Promise.all([first, second]);
  assert.equal(a.events[0][0], 'job');
  assert.equal(b.events[0][1].progress.measured, 4);
  a.req.destroy();
  b.req.destroy();
  await waitFor(() => streams[0].cancelled === true, 'the stream to be cancelled');
  assert.deepEqual(dash.hub.stats(), []);
});

test('SSE for an unknown job is a plain 404, no stream opened', async () => {
  const opened = streams.length;
  const { status, json } = await getJson('/api/jobs/4/events');
  assert.equal(status, 404);
  assert.equal(json.error.code, 'NOT_FOUND');
  assert.equal(streams.length, opened);
});
