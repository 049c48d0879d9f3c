// The operator panels under the map: rate and time to completion with the
// rigs, the probe failures with their reasons, and the job's event list.
// Renders a JobActivity (job_activity.js) and the plan's failed sites; keeps
// no state of its own.
//
// Reported in data attributes (for debugging and the browser test):
// #rate-panel[data-rate (traces/s), data-eta-s, data-events],
// #rig-table tr[data-rig, data-accepted, data-failed],
// #failure-list li[data-level, data-vertex, data-state],
// #event-list li[data-event-id, data-kind, data-command-id].
import { describeEvent, formatDuration } from './job_activity.js';

const $ = (id) => document.getElementById(id);

const clock = (iso) => (iso ? new Date(iso).toLocaleTimeString([], { hour12: false }) : '--:--:--');

/** Rate, ETA and the per-rig table. */
export function renderRate(activity, job) {
  const panel = $('rate-panel');
  const rate = activity.rate();
  const eta = activity.eta(job?.progress, job?.state);
  const lines = [
    rate ? `${rate.perSecond.toFixed(2)} traces/s (last ${rate.count} traces over ${formatDuration(rate.spanS)})` : 'rate: fewer than two traces yet',
    `time to completion: ${eta.text}`,
  ];
  const newest = activity.acceptedTimesMs.at(-1);
  if (Number.isFinite(newest)) lines.push(`last trace at ${clock(new Date(newest).toISOString())} (server time)`);
  $('rate-text').textContent = lines.join('\n');
  panel.dataset.rate = rate ? rate.perSecond.toFixed(4) : '';
  panel.dataset.etaS = eta.seconds === null ? '' : eta.seconds.toFixed(1);
  panel.dataset.events = String(activity.eventCount);

  const table = $('rig-table');
  table.replaceChildren();
  const rigs = activity.rigs();
  if (rigs.length === 0) return;
  const head = table.insertRow();
  for (const h of ['rig', 'traces', 'failures', 'last event']) head.insertCell().textContent = h;
  for (const r of rigs) {
    const row = table.insertRow();
    row.dataset.rig = r.rig;
    row.dataset.accepted = String(r.accepted);
    row.dataset.failed = String(r.failed);
    const lastIso = Number.isFinite(r.last_time_ms) ? new Date(r.last_time_ms).toISOString() : null;
    for (const v of [r.rig, r.accepted, r.failed, clock(lastIso)]) row.insertCell().textContent = String(v);
    if (r.failed > 0) row.cells[2].className = 'bad';
  }
}

/**
 * The plan's sites that have a failure reason (given up, or re-queued after
 * one), with the reason the rig gave; `planError` when the plan could not be
 * read. Sites come from GET /api/jobs/:id/plan.
 */
export function renderFailures(sites, planError, failureEvents = 0) {
  const list = $('failure-list');
  list.replaceChildren();
  const failing = (sites || []).filter((s) => s.failure_reason);
  $('failure-count').textContent = sites ? `(${failing.filter((s) => s.state === 'FAILED').length} given up)` : '';
  if (planError) {
    const li = document.createElement('li');
    li.className = 'bad';
    li.textContent = `plan: ${planError}`;
    list.append(li);
    return;
  }
  if (failing.length === 0) {
    // The plan forgets a reason once its site is measured; the log keeps it.
    const li = document.createElement('li');
    li.className = 'muted';
    li.textContent = failureEvents > 0
      ? `no site failing now (${failureEvents} probe failure${failureEvents === 1 ? '' : 's'} in the events, since retried)`
      : 'no failures';
    list.append(li);
    return;
  }
  for (const s of failing) {
    const li = document.createElement('li');
    li.dataset.level = String(s.level);
    li.dataset.vertex = String(s.vertex);
    li.dataset.state = s.state;
    // attempts counts every issue of the site, the current one included.
    const plural = s.attempts === 1 ? '' : 's';
    const what = s.state === 'FAILED'
      ? `given up after ${s.attempts} attempt${plural}:`
      : `${s.state.toLowerCase()}, ${s.attempts} attempt${plural} · last failure:`;
    li.innerHTML = '<span class="where"></span> <span class="reason"></span>';
    li.querySelector('.where').textContent = `L${s.level} v${s.vertex} · ${what}`;
    li.querySelector('.reason').textContent = s.failure_reason;
    list.append(li);
  }
}

/** Newest first; an accepted trace is a link to its sample (`onOpenCommand(command_id)`). */
export function renderEvents(activity, onOpenCommand) {
  const list = $('event-list');
  list.replaceChildren();
  if (activity.recent.length === 0) {
    list.innerHTML = '<li class="muted">no events yet</li>';
    return;
  }
  for (let k = activity.recent.length - 1; k >= 0; --k) {
    const e = activity.recent[k];
    const li = document.createElement('li');
    li.dataset.eventId = String(e.event_id);
    li.dataset.kind = e.kind;
    li.className = `event-${e.kind}${e.detail_error ? ' bad' : ''}`;
    li.innerHTML = '<span class="time"></span> <span class="text"></span>';
    li.querySelector('.time').textContent = clock(e.time);
    li.querySelector('.text').textContent = describeEvent(e);
    if (e.kind === 'trace_accepted' && e.detail && e.detail.command_id !== undefined) {
      li.dataset.commandId = String(e.detail.command_id);
      li.classList.add('link');
      li.title = 'show this sample and its trace';
      li.addEventListener('click', () => onOpenCommand(e.detail.command_id));
    }
    list.append(li);
  }
}
