// The JSON API the page uses: every route is a GET that makes read-only
// unary calls to surfmapd (through surfmap_client.js) and returns a JSON form
// (json_forms.js). The live channel (Server-Sent Events) is in dashboard_server.js.
//
// Contract: findRoute(pathname) -> { handler, params } or null;
// handler({ params, query, client }) resolves to the response body or rejects
// with an ApiError (bad request) or the grpc-js error (passed on as it is).
import { invalidArgument } from './http_errors.js';
import {
  eventForm, jobForm, mapForm, mapValueForm, meshForm, objectForm, planForm, sampleForm, traceForm,
} from './json_forms.js';

/** A positive integer id from the path, or INVALID_ARGUMENT naming it. */
export function parseId(text, what) {
  if (!/^[1-9][0-9]{0,15}$/.test(text)) {
    throw invalidArgument(`${what} '${text}' is not a positive integer`);
  }
  return Number(text);
}

/** An integer query parameter within [min, max], or its default when absent. */
export function parseIntParam(query, name, { min, max, fallback }) {
  const text = query.get(name);
  if (text === null || text === '') return fallback;
  if (!/^-?[0-9]{1,9}$/.test(text)) throw invalidArgument(`query parameter ${name}='${text}' is not an integer`);
  const value = Number(text);
  if (value < min || value > max) {
    throw invalidArgument(`query parameter ${name}=${value} is out of range [${min}, ${max}]`);
  }
  return value;
}

/** A finite number query parameter (required). */
export function parseNumberParam(query, name) {
  const text = query.get(name);
  if (text === null || text === '') throw invalidArgument(`query parameter ${name} is missing`);
  const value = Number(text);
  if (!Number.isFinite(value)) throw invalidArgument(`query parameter ${name}='${text}' is not a finite number`);
  return value;
}

export function parseBoolParam(query, name, fallback) {
  const text = query.get(name);
  if (text === null || text === '') return fallback;
  if (['1', 'true', 'yes'].includes(text)) return true;
  if (['0', 'false', 'no'].includes(text)) return false;
  throw invalidArgument(`query parameter ${name}='${text}' is not a boolean (1/0, true/false)`);
}

/** A non-negative integer cursor (an event id) from the query, or its default when absent. */
export function parseCursorParam(query, name) {
  const text = query.get(name);
  if (text === null || text === '') return 0;
  if (!/^[0-9]{1,15}$/.test(text)) throw invalidArgument(`query parameter ${name}='${text}' is not a non-negative integer`);
  return Number(text);
}

const MAX_LEVEL = 6;  // GetMeshRequest: subdivision level 0..6
const MAX_EVENTS = 10000;  // ListJobEventsRequest.limit: 1..10000

const ROUTES = [
  ['/api/objects', async ({ client }) => {
    const r = await client.call('ListObjects', {});
    return { objects: r.objects.map(objectForm) };
  }],
  ['/api/objects/:object', async ({ client, params }) => {
    const r = await client.call('GetObject', { object_id: params.object });
    return { object: objectForm(r.object) };
  }],
  ['/api/objects/:object/mesh', async ({ client, params, query }) => {
    const level = parseIntParam(query, 'level', { min: 0, max: MAX_LEVEL, fallback: 0 });
    const r = await client.call('GetMesh', { object_id: params.object, level });
    return { mesh: meshForm(r) };
  }],
  ['/api/jobs', async ({ client, query }) => {
    const objectId = query.get('object') ? parseId(query.get('object'), 'object id') : 0;
    const r = await client.call('ListJobs', { object_id: objectId });
    return { jobs: r.jobs.map(jobForm) };
  }],
  ['/api/jobs/:job', async ({ client, params }) => {
    const r = await client.call('GetJob', { job_id: params.job });
    return { job: jobForm(r.job) };
  }],
  ['/api/jobs/:job/plan', async ({ client, params }) => planForm(await client.call('GetPlan', { job_id: params.job }))],
  // The job's event log after a cursor (the SSE channel is /api/jobs/:id/events).
  ['/api/jobs/:job/event-log', async ({ client, params, query }) => {
    const after = parseCursorParam(query, 'after');
    const limit = parseIntParam(query, 'limit', { min: 1, max: MAX_EVENTS, fallback: 1000 });
    const r = await client.call('ListJobEvents', { job_id: params.job, after_event_id: after, limit });
    const events = r.events.map(eventForm);
    return { job_id: params.job, events, next_after: events.length ? events.at(-1).event_id : after };
  }],
  ['/api/jobs/:job/map', async ({ client, params, query }) => {
    const level = parseIntParam(query, 'level', { min: -1, max: MAX_LEVEL, fallback: -1 });
    const includeMesh = parseBoolParam(query, 'mesh', true);
    const r = await client.call('GetMap', { job_id: params.job, level, include_mesh: includeMesh });
    return { map: mapForm(r.map), mesh: includeMesh ? meshForm(r.mesh) : null };
  }],
  ['/api/jobs/:job/samples', async ({ client, params, query }) => {
    const fitVersion = parseIntParam(query, 'fit_version', { min: 0, max: 1e6, fallback: 0 });
    const r = await client.call('ListSamples', { job_id: params.job, fit_version: fitVersion });
    return { samples: r.samples.map(sampleForm) };
  }],
  ['/api/jobs/:job/query', async ({ client, params, query }) => {
    const point = { x: parseNumberParam(query, 'x'), y: parseNumberParam(query, 'y'), z: parseNumberParam(query, 'z') };
    const r = await client.call('QueryMap', { job_id: params.job, points: [point] });
    if (r.values.length !== 1) {
      throw new Error(`QueryMap returned ${r.values.length} values for 1 point`);
    }
    return { point, value: mapValueForm(r.values[0]) };
  }],
  ['/api/samples/:trace', async ({ client, params, query }) => {
    const fitVersion = parseIntParam(query, 'fit_version', { min: 0, max: 1e6, fallback: 0 });
    // include_series: the per-pair mu along the window (and the ACF), which
    // the trace plot draws under the forces.
    const r = await client.call('GetSample', { trace_id: params.trace, fit_version: fitVersion, include_series: true });
    return { sample: sampleForm(r.sample) };
  }],
  ['/api/traces/:trace', async ({ client, params }) => ({ trace: traceForm(await client.call('GetTrace', { trace_id: params.trace })) })],
];

const PARAM_NAMES = { job: 'job id', object: 'object id', trace: 'trace id' };

// Compiled once: '/api/jobs/:job/map' -> segments to compare.
const COMPILED = ROUTES.map(([pattern, handler]) => ({ segments: pattern.split('/'), handler, pattern }));

export function findRoute(pathname) {
  const parts = pathname.replace(/\/+$/, '').split('/');
  for (const route of COMPILED) {
    if (route.segments.length !== parts.length) continue;
    const params = {};
    let ok = true;
    for (let i = 0; i < parts.length && ok; ++i) {
      const seg = route.segments[i];
      if (seg.startsWith(':')) {
        const name = seg.slice(1);
        params[name] = () => parseId(decodeURIComponent(parts[i]), PARAM_NAMES[name]);
      } else if (seg !== parts[i]) {
        ok = false;
      }
    }
    if (!ok) continue;
    // Ids are parsed only once the route matched, so a bad id is a 400 that
    // names it rather than a 404.
    return {
      pattern: route.pattern,
      handler: route.handler,
      resolveParams: () => Object.fromEntries(Object.entries(params).map(([k, parse]) => [k, parse()])),
    };
  }
  return null;
}

export const ROUTE_PATTERNS = Object.freeze(ROUTES.map(([pattern]) => pattern));
