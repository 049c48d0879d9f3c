// What an operator needs from a job's event log (ListJobEvents through
// /api/jobs/:id/event-log): which rig did what, the recent events, the probe
// failures, the rate of accepted traces and the time to completion.
// Pure logic, no DOM: the page renders it, the unit tests feed it events.
//
// Rate: accepted traces per second over the RATE_WINDOW_S seconds of event
// time before the newest accepted trace ((count - 1) / time between the first
// and the last of them), or from the last two when that window holds one.
// Event times are the server's clock, so no browser clock enters the rate.
// ETA: the sites the plan still has to measure (pending + issued) at that
// rate. An adaptive plan adds sites as it refines, so the ETA covers the
// sites known now and says so.

export const RATE_WINDOW_S = 30;
export const RECENT_LIMIT = 200;      // events kept for the list
export const FAILURE_LIMIT = 500;     // probe failures kept
const ACCEPTED_TIMES_LIMIT = 5000;    // enough for any window at rig speeds

export class JobActivity {
  constructor(jobId) {
    this.jobId = jobId;
    this.cursor = 0;               // the last event_id taken in
    this.eventCount = 0;
    this.recent = [];              // newest last
    this.failures = [];            // probe_failed events, newest last
    this.rigStats = new Map();     // rig -> { rig, accepted, failed, last_time }
    this.acceptedTimesMs = [];     // server times of accepted traces, ascending
    this.problems = [];            // event details that could not be read
  }

  /** Takes events in event_id order; ids at or below the cursor are ignored (a repeated page). Returns how many were new. */
  add(events) {
    let added = 0;
    for (const e of events) {
      if (!(e.event_id > this.cursor)) continue;
      this.cursor = e.event_id;
      this.eventCount += 1;
      added += 1;
      this.recent.push(e);
      if (e.detail_error) this.problems.push(e.detail_error);
      const d = e.detail || {};
      const timeMs = e.time ? Date.parse(e.time) : NaN;
      if (e.kind === 'trace_accepted') {
        this.rig(d.rig, timeMs).accepted += 1;
        if (Number.isFinite(timeMs)) this.acceptedTimesMs.push(timeMs);
      } else if (e.kind === 'probe_failed') {
        this.rig(d.rig, timeMs).failed += 1;
        this.failures.push(e);
      }
    }
    if (this.recent.length > RECENT_LIMIT) this.recent.splice(0, this.recent.length - RECENT_LIMIT);
    if (this.failures.length > FAILURE_LIMIT) this.failures.splice(0, this.failures.length - FAILURE_LIMIT);
    if (this.acceptedTimesMs.length > ACCEPTED_TIMES_LIMIT) this.acceptedTimesMs.splice(0, this.acceptedTimesMs.length - ACCEPTED_TIMES_LIMIT);
    // Out-of-order times (clock steps on the server) would break the window.
    this.acceptedTimesMs.sort((a, b) => a - b);
    return added;
  }

  rig(name, timeMs) {
    const key = typeof name === 'string' && name ? name : '(unnamed rig)';
    let stats = this.rigStats.get(key);
    if (!stats) {
      stats = { rig: key, accepted: 0, failed: 0, last_time_ms: NaN };
      this.rigStats.set(key, stats);
    }
    if (Number.isFinite(timeMs) && !(timeMs <= stats.last_time_ms)) stats.last_time_ms = timeMs;
    return stats;
  }

  /** Per rig: accepted traces, failures, last event time; most traces first. */
  rigs() {
    return [...this.rigStats.values()].sort((a, b) => b.accepted - a.accepted || a.rig.localeCompare(b.rig));
  }

  /** { perSecond, count, spanS } or null with fewer than two accepted traces. */
  rate() {
    const times = this.acceptedTimesMs;
    if (times.length < 2) return null;
    const last = times.at(-1);
    let first = times.length - 1;
    while (first > 0 && times[first - 1] >= last - RATE_WINDOW_S * 1000) first -= 1;
    if (first === times.length - 1) first = times.length - 2;  // one in the window: the last two
    const spanS = (last - times[first]) / 1000;
    const count = times.length - first;
    if (!(spanS > 0)) return null;
    return { perSecond: (count - 1) / spanS, count, spanS };
  }

  /**
   * Time to completion for a job's progress (api form) and state:
   * { seconds, remaining, text }. Not running, nothing left or no rate:
   * seconds null and the text says why.
   */
  eta(progress, state) {
    const remaining = progress ? progress.pending + progress.issued : 0;
    if (state !== 'RUNNING') return { seconds: null, remaining, text: `job ${String(state).toLowerCase()}` };
    if (remaining === 0) return { seconds: null, remaining, text: 'no sites left to measure' };
    const r = this.rate();
    if (!r) return { seconds: null, remaining, text: `${remaining} sites left; rate not known yet` };
    const seconds = remaining / r.perSecond;
    return { seconds, remaining, text: `~${formatDuration(seconds)} for the ${remaining} sites known now` };
  }
}

/** 75 -> "1 min 15 s", 3725 -> "1 h 02 min", 8.4 -> "8.4 s", 12.4 -> "12 s". */
export function formatDuration(seconds) {
  if (!Number.isFinite(seconds) || seconds < 0) return '-';
  if (seconds < 10) return `${seconds.toFixed(1)} s`;
  const s = Math.round(seconds);
  if (s < 60) return `${s} s`;
  if (s < 3600) return `${Math.floor(s / 60)} min ${String(s % 60).padStart(2, '0')} s`;
  return `${Math.floor(s / 3600)} h ${String(Math.floor((s % 3600) / 60)).padStart(2, '0')} min`;
}

/** One line of text for an event (api form), for the event list. */
export function describeEvent(e) {
  if (e.detail_error) return e.detail_error;
  const d = e.detail || {};
  switch (e.kind) {
    case 'job_created':
      return `job created${d.initial_commands !== undefined ? `, ${d.initial_commands} commands issued` : ''}`;
    case 'job_state':
      return `${d.from ?? '?'} -> ${d.to ?? '?'}`;
    case 'trace_accepted':
      return `L${d.level ?? '?'} v${d.vertex ?? '?'} measured by ${d.rig || '?'}, mu ${Number.isFinite(d.mu) ? d.mu.toFixed(3) : '-'}`;
    case 'probe_failed':
      return `command ${d.command_id ?? '?'} failed at ${d.rig || '?'} (${d.kind || 'transient'}, ` +
        `${d.will_retry ? 'will retry' : 'given up'}): ${d.reason ?? ''}`;
    default:
      return `${e.kind} ${JSON.stringify(d)}`;
  }
}
