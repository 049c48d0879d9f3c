// The page: object and job lists (polled), the selected job's progress and map
// (live from /api/jobs/:id/events), the operator panels (rate, time to
// completion, rigs, failures and the event list, from the job's event log and
// plan), and what is under a click (QueryMap, the nearest sample's fit and its
// trace); a click on an accepted trace in the event list shows that sample.
//
// The page reports what it shows in data attributes, for people debugging
// and for the browser test: #view[data-vertex-count, data-triangle-count,
// data-sample-count, data-map-updates, data-frames], #progress[data-measured,
// data-total, data-state, data-job], #point-info[data-mu],
// #trace-plot[data-trace-id, data-plot-mu, ...] and those of operations_view.js.
import {
  DEFAULT_SCALE_MODES, FIXED_RANGES, MIN_SPANS, QUANTITIES, chooseRange, drawLegend,
} from './colour_scale.js';
import { JobActivity } from './job_activity.js';
import { renderEvents, renderFailures, renderRate } from './operations_view.js';
import { SurfaceView } from './surface_view.js';
import { drawTracePlot } from './trace_plot.js';

const LIST_POLL_MS = 4000;
const EVENTS_RETRY_MS = 5000;
const EVENT_LOG_POLL_MS = 4000;   // besides a poll on every live job update
const EVENT_PAGE = 1000;

const $ = (id) => document.getElementById(id);
const state = {
  objects: [],
  jobs: [],
  jobId: null,
  job: null,
  mesh: null,        // { level, vertex_count, ... } of what the view shows
  map: null,
  quantity: 'mu',
  // Colour scale per quantity: the data's min..max or fixed limits (mu starts fixed).
  scale: {
    modes: { ...DEFAULT_SCALE_MODES },
    fixed: Object.fromEntries(Object.entries(FIXED_RANGES).map(([k, r]) => [k, [...r]])),
  },
  activity: null,    // JobActivity of the selected job (its event log)
  eventPoll: { running: false, again: false },
  planFailedCount: -1,  // progress.failed when the failure list was last read
  failureSites: new Set(),  // 'level/vertex' of the sites in the failure list
  lastJobState: null,
  events: null,
  selection: 0,      // bumps on every job change so late answers for an old job are dropped
  mapUpdates: 0,
  pick: null,
  autoSelected: false,
};

// ------------------------------------------------------------------ fetch

async function api(path) {
  const res = await fetch(path, { headers: { accept: 'application/json' } });
  let body = null;
  try {
    body = await res.json();
  } catch {
    throw new Error(`${path}: HTTP ${res.status} (no JSON body)`);
  }
  if (!res.ok) {
    const e = body && body.error ? body.error : { code: `HTTP ${res.status}`, message: '' };
    const err = new Error(`${e.code}: ${e.message}`);
    err.code = e.code;
    throw err;
  }
  return body;
}

function showError(message) {
  const banner = $('error-banner');
  banner.hidden = !message;
  banner.textContent = message || '';
}

function setConnection(ok, text) {
  const badge = $('connection');
  badge.textContent = text;
  badge.className = `badge ${ok ? 'ok' : 'down'}`;
}

// ------------------------------------------------------------------ formatting

const fmt = (v, digits = 3) => (Number.isFinite(v) ? v.toFixed(digits) : '-');
const vecText = (v, digits = 2) => (v ? `${fmt(v.x, digits)}, ${fmt(v.y, digits)}, ${fmt(v.z, digits)}` : '-');

function rowsTable(rows) {
  const table = document.createElement('table');
  table.className = 'values';
  for (const [label, value] of rows) {
    const tr = table.insertRow();
    tr.insertCell().textContent = label;
    const td = tr.insertCell();
    td.textContent = value;
    td.className = 'num';
  }
  return table;
}

function progressPercent(p) {
  if (!p || p.total === 0) return 0;
  return Math.round((100 * p.measured) / p.total);
}

// ------------------------------------------------------------------ lists

function renderObjects() {
  const list = $('object-list');
  list.replaceChildren();
  if (state.objects.length === 0) {
    list.innerHTML = '<li class="muted">no objects</li>';
    return;
  }
  for (const o of state.objects) {
    const li = document.createElement('li');
    li.dataset.objectId = o.object_id;
    li.innerHTML = `<div>#${o.object_id} <b></b></div><div class="sub"></div>`;
    li.querySelector('b').textContent = o.name;
    li.querySelector('.sub').textContent = `${o.control_vertex_count} vertices, ${o.control_face_count} faces, ${o.format}`;
    list.append(li);
  }
}

function jobRowTexts(j) {
  const objectName = state.objects.find((o) => o.object_id === j.spec.object_id)?.name ?? `object ${j.spec.object_id}`;
  return {
    title: `job ${j.job_id} · ${objectName}`,
    sub: `${j.spec.property.toLowerCase()}, ${j.spec.mode.toLowerCase()}, levels ${j.spec.coarsest_level}..${j.spec.finest_level} · ` +
      `${j.progress.measured}/${j.progress.total} (${progressPercent(j.progress)}%)`,
  };
}

function fillJobRow(li, j) {
  const texts = jobRowTexts(j);
  li.classList.toggle('selected', j.job_id === state.jobId);
  li.querySelector('.title').textContent = texts.title;
  const st = li.querySelector('.state');
  st.textContent = j.state;
  st.className = `state state-${j.state}`;
  li.querySelector('.sub').textContent = texts.sub;
}

function renderJobs() {
  const list = $('job-list');
  list.replaceChildren();
  if (state.jobs.length === 0) {
    list.innerHTML = '<li class="muted">no jobs</li>';
    return;
  }
  for (const j of [...state.jobs].sort((a, b) => b.job_id - a.job_id)) {
    const li = document.createElement('li');
    li.dataset.jobId = j.job_id;
    li.innerHTML = '<div><span class="title"></span> <span class="state"></span></div><div class="sub"></div>';
    fillJobRow(li, j);
    li.addEventListener('click', () => selectJob(j.job_id));
    list.append(li);
  }
}

// Live updates change the selected row in place (no list rebuild under the mouse).
function updateJobRow(j) {
  const idx = state.jobs.findIndex((x) => x.job_id === j.job_id);
  if (idx >= 0) state.jobs[idx] = j;
  const li = document.querySelector(`#job-list li[data-job-id="${j.job_id}"]`);
  if (li) fillJobRow(li, j);
}

async function refreshLists() {
  try {
    const [objects, jobs] = await Promise.all([api('/api/objects'), api('/api/jobs')]);
    state.objects = objects.objects;
    // A live job's row follows its event stream, which is fresher than this poll.
    state.jobs = jobs.jobs.map((j) => (j.job_id === state.jobId && state.job ? state.job : j));
    renderObjects();
    renderJobs();
    setConnection(true, 'connected');
    if (!state.autoSelected && state.jobId === null && state.jobs.length > 0) {
      state.autoSelected = true;
      const running = state.jobs.filter((j) => j.state === 'RUNNING');
      const pick = (running.length ? running : state.jobs).reduce((a, b) => (a.job_id > b.job_id ? a : b));
      selectJob(pick.job_id);
    }
  } catch (err) {
    setConnection(false, 'surfmapd unreachable');
    showError(`lists: ${err.message}`);
  }
}

// ------------------------------------------------------------------ the selected job

function renderJob() {
  const j = state.job;
  if (!j) return;
  const title = $('job-title');
  title.className = '';
  title.textContent = '';
  const name = state.objects.find((o) => o.object_id === j.spec.object_id)?.name ?? `object ${j.spec.object_id}`;
  const strong = document.createElement('b');
  strong.textContent = `job ${j.job_id} · ${name}`;
  const st = document.createElement('span');
  st.className = `state-${j.state}`;
  st.textContent = ` ${j.state} `;
  const spec = document.createElement('span');
  spec.className = 'muted';
  spec.textContent = `${j.spec.property.toLowerCase()} map, ${j.spec.mode.toLowerCase()}, levels ${j.spec.coarsest_level}..${j.spec.finest_level}` +
    `, threshold ${j.spec.threshold}, probe ${j.spec.probe?.segment_length_mm ?? '?'} mm at ${j.spec.probe?.speed_mm_s ?? '?'} mm/s`;
  title.append(strong, st, spec);

  const p = j.progress;
  const progress = $('progress');
  progress.dataset.job = String(j.job_id);
  progress.dataset.measured = String(p.measured);
  progress.dataset.total = String(p.total);
  progress.dataset.state = j.state;
  $('progress-fill').style.width = `${progressPercent(p)}%`;
  $('progress-text').textContent =
    `${p.measured} / ${p.total} sites measured (${progressPercent(p)}%) · ` +
    `${p.issued} issued${p.leased !== null && p.leased !== undefined ? ` (${p.leased} at a rig)` : ''}, ${p.pending} pending, ` +
    `${p.failed} failed, ${p.skipped} skipped${p.budget_left >= 0 ? ` · budget left ${p.budget_left}` : ''}`;
  const table = $('level-table');
  table.replaceChildren();
  const head = table.insertRow();
  for (const h of ['level', 'measured', 'issued', 'at a rig', 'pending', 'failed']) head.insertCell().textContent = h;
  for (const l of p.levels) {
    const row = table.insertRow();
    const leased = l.leased === null || l.leased === undefined ? '-' : l.leased;
    for (const v of [l.level, l.measured, l.issued, leased, l.pending, l.failed]) row.insertCell().textContent = String(v);
  }
  updateJobRow(j);
  if (state.activity) renderRate(state.activity, j);
  // The failure list changes when a site fails or is given up (the failed
  // count), when a re-queued site is measured (seen in the event log) and when
  // the job ends.
  const stateChanged = state.lastJobState !== null && state.lastJobState !== j.state;
  state.lastJobState = j.state;
  if (p.failed !== state.planFailedCount || stateChanged) refreshFailures(state.selection, p.failed);
}

// ------------------------------------------------------------------ operator panels

// The event list is rebuilt only when events arrived: a rebuild under the
// mouse would swallow a click.
function renderOperations() {
  const activity = state.activity;
  if (!activity) return;
  renderRate(activity, state.job);
  if (activity.renderedCursor === activity.cursor && activity.renderedCursor !== undefined) return;
  activity.renderedCursor = activity.cursor;
  renderEvents(activity, (commandId) => openCommandSample(commandId));
}

// Reads the event log after the cursor, page by page, then renders. One read
// at a time; a request while one runs makes it read again when done.
async function pollEventLog(selection) {
  if (state.eventPoll.running) {
    state.eventPoll.again = true;
    return;
  }
  state.eventPoll.running = true;
  try {
    do {
      state.eventPoll.again = false;
      const activity = state.activity;
      let failuresSeen = false;
      for (;;) {
        const page = await api(`/api/jobs/${activity.jobId}/event-log?after=${activity.cursor}&limit=${EVENT_PAGE}`);
        if (selection !== state.selection) return;
        activity.add(page.events);
        failuresSeen ||= page.events.some((e) => e.kind === 'probe_failed' ||
          (e.kind === 'trace_accepted' && e.detail && state.failureSites.has(`${e.detail.level}/${e.detail.vertex}`)));
        if (page.events.length < EVENT_PAGE) break;
      }
      renderOperations();
      if (failuresSeen) refreshFailures(selection, state.job?.progress?.failed ?? -1);
    } while (state.eventPoll.again && selection === state.selection);
  } catch (err) {
    if (selection === state.selection) showError(`event log: ${err.message}`);
  } finally {
    state.eventPoll.running = false;
  }
}

// The plan's failure reasons, read when the failed count changes or a probe
// failure arrives (a plan lists every site, so not on every update).
async function refreshFailures(selection, failedCount) {
  state.planFailedCount = failedCount;
  try {
    const plan = await api(`/api/jobs/${state.jobId}/plan`);
    if (selection !== state.selection) return;
    state.failureSites = new Set(plan.sites.filter((x) => x.failure_reason).map((x) => `${x.level}/${x.vertex}`));
    renderFailures(plan.sites, null, state.activity ? state.activity.failures.length : 0);
  } catch (err) {
    if (selection === state.selection) renderFailures(null, err.message);
  }
}

function viewMessage(text) {
  const msg = $('view-message');
  msg.hidden = !text;
  msg.textContent = text || '';
}

function currentScale() {
  const [min, max] = state.scale.fixed[state.quantity];
  return { mode: state.scale.modes[state.quantity], min, max, minSpan: MIN_SPANS[state.quantity] };
}

function recolour() {
  if (!state.map || !view.ok) return;
  const values = state.map[state.quantity] || [];
  const { range, outside, error, note } = chooseRange(values, currentScale());
  $('scale-note').textContent = error || (outside > 0 ? `${outside} vertices outside the scale (end colours)` : note);
  $('scale-note').classList.toggle('error', Boolean(error));
  view.setColours(values, range);
  const legend = $('legend');
  legend.hidden = !range;
  if (range) {
    drawLegend({ titleEl: $('legend-title'), barCanvas: $('legend-bar'), ticksEl: $('legend-ticks') }, state.quantity, range);
  }
  viewMessage(range ? '' : 'no samples yet: the map appears with the first measurement');
}

function applyMap(map) {
  state.map = map;
  state.mapUpdates += 1;
  recolour();
  view.setSamples(map.samples);
  const el = $('view');
  const s = view.stats();
  el.dataset.vertexCount = String(s.vertices);
  el.dataset.triangleCount = String(s.triangles);
  el.dataset.sampleCount = String(map.samples.length);
  el.dataset.mapUpdates = String(state.mapUpdates);
  el.dataset.mapLevel = String(map.level);
}

async function loadMapWithMesh(selection) {
  const body = await api(`/api/jobs/${state.jobId}/map?mesh=1`);
  if (selection !== state.selection) return;
  state.mesh = { level: body.mesh.level, vertex_count: body.mesh.vertex_count, object_id: body.mesh.object_id };
  view.setMesh(body.mesh);
  applyMap(body.map);
}

function onMapEvent(map, selection) {
  if (selection !== state.selection) return;
  if (!state.mesh || map.level !== state.mesh.level || map.vertex_count !== state.mesh.vertex_count) {
    loadMapWithMesh(selection).catch((err) => showError(`map: ${err.message}`));
    return;
  }
  applyMap(map);
}

function closeEvents() {
  if (state.events) {
    state.events.close();
    state.events = null;
  }
}

function openEvents(selection) {
  closeEvents();
  const es = new EventSource(`/api/jobs/${state.jobId}/events`);
  state.events = es;
  es.addEventListener('job', (e) => {
    if (selection !== state.selection) return;
    state.job = JSON.parse(e.data);
    renderJob();
    pollEventLog(selection);
  });
  es.addEventListener('map', (e) => onMapEvent(JSON.parse(e.data), selection));
  es.addEventListener('end', () => {
    // The job is over: nothing more will come, and a reconnect would only
    // replay the final state.
    es.close();
    if (state.events === es) state.events = null;
    $('view').dataset.live = 'ended';
  });
  es.addEventListener('failure', (e) => {
    const f = JSON.parse(e.data);
    showError(`live updates for job ${state.jobId}: ${f.code}: ${f.message}`);
    es.close();
    if (state.events === es) state.events = null;
    $('view').dataset.live = 'failed';
    // surfmapd restarting or briefly away: try again; other failures (NOT_FOUND,
    // PERMISSION_DENIED...) would only fail again.
    if (f.code === 'UNAVAILABLE') {
      setTimeout(() => {
        if (selection === state.selection && !state.events) {
          showError('');
          openEvents(selection);
        }
      }, EVENTS_RETRY_MS);
    }
  });
  es.addEventListener('open', () => { $('view').dataset.live = 'open'; });
  es.onerror = () => { $('view').dataset.live = 'reconnecting'; };
}

async function selectJob(jobId) {
  if (state.jobId === jobId && state.job) return;
  state.selection += 1;
  const selection = state.selection;
  state.jobId = jobId;
  state.job = null;
  state.map = null;
  state.mesh = null;
  state.mapUpdates = 0;
  state.activity = new JobActivity(jobId);
  state.planFailedCount = -1;
  state.failureSites = new Set();
  state.lastJobState = null;
  clearPick();
  closeEvents();
  renderOperations();
  history.replaceState(null, '', `#job=${jobId}`);
  for (const li of document.querySelectorAll('#job-list li[data-job-id]')) {
    li.classList.toggle('selected', Number(li.dataset.jobId) === jobId);
  }
  viewMessage('loading the map');
  showError('');
  try {
    const { job } = await api(`/api/jobs/${jobId}`);
    if (selection !== state.selection) return;
    state.job = job;
    renderJob();
    if (!view.ok) {
      viewMessage(view.error);
    } else {
      await loadMapWithMesh(selection);
    }
    if (selection !== state.selection) return;
    openEvents(selection);
    pollEventLog(selection);
  } catch (err) {
    if (selection === state.selection) {
      showError(`job ${jobId}: ${err.message}`);
      viewMessage('');
    }
  }
}

// ------------------------------------------------------------------ picking

function clearPick() {
  state.pick = null;
  $('point-body').className = 'muted';
  $('point-body').textContent = 'click the surface';
  $('point-info').removeAttribute('data-mu');
  $('sample-body').className = 'muted';
  $('sample-body').textContent = '-';
  $('trace-plot').replaceChildren();
  $('trace-plot').removeAttribute('data-trace-id');
  if (view.ok) view.showPick(null, null);
}

function nearestSample(point) {
  let best = null;
  let bestD = Infinity;
  for (const s of state.map?.samples ?? []) {
    const d = Math.hypot(s.position.x - point.x, s.position.y - point.y, s.position.z - point.z);
    if (d < bestD) { bestD = d; best = s; }
  }
  return best ? { sample: best, distance: bestD } : null;
}

async function onPick(point) {
  if (state.jobId === null) return;
  const selection = state.selection;
  state.pick = point;
  const near = nearestSample(point);
  view.showPick(point, near?.sample ?? null);
  try {
    const q = await api(`/api/jobs/${state.jobId}/query?x=${point.x}&y=${point.y}&z=${point.z}`);
    if (selection !== state.selection || state.pick !== point) return;
    const v = q.value;
    const body = $('point-body');
    body.className = '';
    body.replaceChildren(rowsTable([
      ['surface point (mm)', vecText(v.surface_point)],
      ['mu', `${fmt(v.mu, 4)} ± ${fmt(v.mu_uncertainty, 4)}`],
      ['roughness sigma (N)', fmt(v.sigma, 4)],
      ['AR a1, a2', `${fmt(v.a1)}, ${fmt(v.a2)}`],
      ['normal', vecText(v.normal, 3)],
      ['distance to surface (mm)', fmt(v.distance_mm, 3)],
    ]));
    $('point-info').dataset.mu = String(v.mu);
  } catch (err) {
    showError(`query: ${err.message}`);
  }
  if (!near) {
    $('sample-body').textContent = 'no samples yet';
    return;
  }
  await showSample(near.sample.trace_id, `${fmt(near.distance, 1)} mm away`, () => selection === state.selection && state.pick === point);
}

// An accepted trace picked in the event list: its sample (found by command
// id in the map, else in the job's sample list) is shown as if clicked.
async function openCommandSample(commandId) {
  const selection = state.selection;
  let sample = (state.map?.samples ?? []).find((s) => s.command_id === commandId);
  try {
    if (!sample) sample = (await api(`/api/jobs/${state.jobId}/samples`)).samples.find((s) => s.command_id === commandId);
    if (selection !== state.selection) return;
    if (!sample) {
      showError(`command ${commandId}: no sample of job ${state.jobId} has it`);
      return;
    }
  } catch (err) {
    showError(`samples: ${err.message}`);
    return;
  }
  const pick = { ...sample.position, fromEvent: commandId };
  state.pick = pick;
  if (view.ok) view.showPick(sample.position, sample);
  $('point-body').className = 'muted';
  $('point-body').textContent = `sample of command ${commandId} (from the event list)`;
  $('point-info').removeAttribute('data-mu');
  await showSample(sample.trace_id, 'from the event list', () => selection === state.selection && state.pick === pick);
}

async function showSample(traceId, where, stillWanted) {
  try {
    const id = traceId;
    const [{ sample }, { trace }] = await Promise.all([api(`/api/samples/${id}`), api(`/api/traces/${id}`)]);
    if (!stillWanted()) return;
    const f = sample.fit;
    const fr = f.friction;
    const ro = f.roughness;
    const body = $('sample-body');
    body.className = '';
    body.replaceChildren(rowsTable([
      ['trace', `${sample.trace_id} (site L${sample.site.level} v${sample.site.vertex}, ${where})`],
      ['rig', sample.rig_id || '(not recorded)'],
      ['drag direction', vecText(sample.drag_direction, 3)],
      ['mu (mean ± std)', `${fmt(fr.mu, 4)} ± ${fmt(fr.mu_std, 4)}`],
      ['mu median', fmt(fr.mu_median, 4)],
      ['pairs, window (mm)', `${fr.pair_count}, ${fmt(fr.window_start_mm, 1)}–${fmt(fr.window_end_mm, 1)}`],
      ['AR coefficients', ro.ar_coefficients.map((a, k) => `${fmt(a)} ± ${fmt(ro.ar_stderr[k] ?? NaN)}`).join(', ') || '-'],
      ['sigma (N)', `${fmt(ro.sigma, 4)}${ro.below_noise_floor ? ' (below noise floor)' : ''}`],
      ['stationary', ro.stationary ? 'yes' : 'no'],
      ['noise std (N)', fmt(f.noise_std, 4)],
      ['fit', `v${f.version} ${f.estimator}`],
    ]));
    drawTracePlot($('trace-plot'), trace, f);
  } catch (err) {
    showError(`sample: ${err.message}`);
  }
}

// ------------------------------------------------------------------ start

const view = new SurfaceView($('view'), { onPick });
$('view').dataset.webgl = view.ok ? 'ok' : 'unavailable';
if (!view.ok) viewMessage(view.error);

function showScaleInputs() {
  const fixed = state.scale.modes[state.quantity] === 'fixed';
  $('scale-mode').value = fixed ? 'fixed' : 'data';
  $('scale-fixed').hidden = !fixed;
  const [min, max] = state.scale.fixed[state.quantity];
  $('scale-min').value = String(min);
  $('scale-max').value = String(max);
}

$('quantity').addEventListener('change', (e) => {
  state.quantity = e.target.value;
  if (!QUANTITIES[state.quantity]) state.quantity = 'mu';
  showScaleInputs();
  recolour();
});
$('scale-mode').addEventListener('change', (e) => {
  state.scale.modes[state.quantity] = e.target.value === 'fixed' ? 'fixed' : 'data';
  showScaleInputs();
  recolour();
});
for (const [id, index] of [['scale-min', 0], ['scale-max', 1]]) {
  $(id).addEventListener('input', (e) => {
    // Kept as typed (a half-typed "-" is not a number yet); chooseRange says
    // what is wrong and falls back to the data range meanwhile.
    state.scale.fixed[state.quantity][index] = e.target.value;
    recolour();
  });
}
showScaleInputs();
const overlays = () => view.ok && view.setOverlayVisibility({ samples: $('show-samples').checked, segments: $('show-segments').checked });
$('show-samples').addEventListener('change', overlays);
$('show-segments').addEventListener('change', overlays);

api('/api/status').then((s) => { $('server-address').textContent = `surfmapd at ${s.server}`; }).catch(() => {});
const fromHash = /^#job=([0-9]+)$/.exec(location.hash);
if (fromHash) {
  state.autoSelected = true;
  selectJob(Number(fromHash[1]));
}
refreshLists();
setInterval(refreshLists, LIST_POLL_MS);
// Events also arrive without a live update (a paused job's failures, a
// finished job opened later): poll the log too.
setInterval(() => { if (state.activity) pollEventLog(state.selection); }, EVENT_LOG_POLL_MS);

// For the console and tests: what the view currently shows.
window.surfmapDashboard = { state, view };
