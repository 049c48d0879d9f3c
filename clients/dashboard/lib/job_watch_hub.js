// One WatchJob stream per job, shared by every browser watching that job.
//
// The first subscriber to a job opens the stream (with the map, so the server
// computes and sends it once however many browsers watch); the last one to
// leave cancels it. Each update goes to every subscriber as
//   job      the JobInfo (JSON form), on every update;
//   map      the map at the job's finest level (JSON form), at most once per
//            mapIntervalMs (latest wins; the last one is never dropped), because
//            a map is large and a fast rig produces many updates per second;
//   end      { job } when the server ends the stream (the job completed or was
//            cancelled); the subscribers are then closed;
//   failure  { code, message } when the stream fails (server gone, NOT_FOUND,
//            UNAUTHENTICATED...); the subscribers are then closed.
// A subscriber that joins a running stream gets the latest job and map at once.
//
// Subscribers are sinks: { send(eventName, data), close() }. The hub never
// throws at them; a sink that throws is dropped.
import { GRPC_CODE_NAMES } from './http_errors.js';
import { jobForm, mapForm } from './json_forms.js';

export class JobWatchHub {
  /**
   * @param {{openStream: (jobId: number) => import('node:events').EventEmitter & {cancel(): void},
   *          mapIntervalMs?: number, log?: (line: string) => void}} options
   *   openStream starts WatchJob(job_id, include_map = true) and returns the
   *   grpc-js stream ('data', 'end', 'error' events; cancel()).
   */
  constructor({ openStream, mapIntervalMs = 500, log = () => {} }) {
    this.openStream = openStream;
    this.mapIntervalMs = mapIntervalMs;
    this.log = log;
    this.watches = new Map();  // job id -> watch state
  }

  /** Adds a sink for a job's updates; returns the function that removes it. */
  subscribe(jobId, sink) {
    let watch = this.watches.get(jobId);
    if (!watch) watch = this.#open(jobId);
    watch.sinks.add(sink);
    if (watch.lastJob) this.#deliver(watch, sink, 'job', watch.lastJob);
    if (watch.lastMap) this.#deliver(watch, sink, 'map', watch.lastMap);
    return () => this.#unsubscribe(jobId, watch, sink);
  }

  /** What is open: [{ job_id, subscribers, updates, maps_sent }]. */
  stats() {
    return [...this.watches.entries()].map(([jobId, w]) => ({
      job_id: jobId, subscribers: w.sinks.size, updates: w.updates, maps_sent: w.mapsSent,
    }));
  }

  /** Cancels every stream and closes every sink (server shutdown). */
  closeAll() {
    for (const [jobId, watch] of [...this.watches.entries()]) this.#finish(jobId, watch, null);
  }

  #open(jobId) {
    const watch = {
      sinks: new Set(), stream: null, lastJob: null, lastMap: null,
      pendingMap: false, mapTimer: null, lastMapSentAt: 0, updates: 0, mapsSent: 0, done: false,
    };
    this.watches.set(jobId, watch);
    this.log(`watch job ${jobId}: WatchJob stream opened`);
    const stream = this.openStream(jobId);
    watch.stream = stream;
    stream.on('data', (update) => this.#onUpdate(jobId, watch, update));
    stream.on('end', () => this.#finish(jobId, watch, { event: 'end', data: { job: watch.lastJob } }));
    stream.on('error', (err) => {
      if (watch.done) return;  // our own cancel() ends in CANCELLED: expected
      const code = GRPC_CODE_NAMES[err.code] ?? 'UNKNOWN';
      const message = `surfmapd: ${err.details || err.message}`;
      this.log(`watch job ${jobId}: stream failed: ${code}: ${message}`);
      this.#finish(jobId, watch, { event: 'failure', data: { code, message } });
    });
    return watch;
  }

  #onUpdate(jobId, watch, update) {
    if (watch.done) return;
    watch.updates += 1;
    if (update.job) {
      watch.lastJob = jobForm(update.job);
      this.#broadcast(watch, 'job', watch.lastJob);
    }
    if (update.map) {
      watch.lastMap = mapForm(update.map);
      this.#scheduleMap(watch);
    }
  }

  #scheduleMap(watch) {
    watch.pendingMap = true;
    if (watch.mapTimer) return;  // the timer will send the latest
    const wait = watch.lastMapSentAt + this.mapIntervalMs - Date.now();
    if (wait <= 0) {
      this.#flushMap(watch);
    } else {
      watch.mapTimer = setTimeout(() => {
        watch.mapTimer = null;
        this.#flushMap(watch);
      }, wait);
    }
  }

  #flushMap(watch) {
    if (!watch.pendingMap || !watch.lastMap) return;
    watch.pendingMap = false;
    watch.lastMapSentAt = Date.now();
    watch.mapsSent += 1;
    this.#broadcast(watch, 'map', watch.lastMap);
  }

  #broadcast(watch, event, data) {
    for (const sink of [...watch.sinks]) this.#deliver(watch, sink, event, data);
  }

  #deliver(watch, sink, event, data) {
    try {
      sink.send(event, data);
    } catch (err) {
      this.log(`watch: dropping a subscriber that failed: ${err.message}`);
      watch.sinks.delete(sink);
    }
  }

  #unsubscribe(jobId, watch, sink) {
    if (!watch.sinks.delete(sink)) return;
    if (watch.sinks.size === 0 && !watch.done) {
      this.log(`watch job ${jobId}: last subscriber left, cancelling WatchJob`);
      this.#finish(jobId, watch, null);
    }
  }

  // Ends a watch: the final map first (so nobody misses the last state), then
  // the closing event, then the sinks; cancels the stream if it is still open.
  #finish(jobId, watch, closing) {
    if (watch.done) return;
    if (watch.mapTimer) {
      clearTimeout(watch.mapTimer);
      watch.mapTimer = null;
    }
    if (closing) this.#flushMap(watch);
    watch.done = true;
    if (this.watches.get(jobId) === watch) this.watches.delete(jobId);
    if (closing) this.#broadcast(watch, closing.event, closing.data);
    else watch.stream.cancel();
    for (const sink of [...watch.sinks]) {
      try { sink.close(); } catch { /* already gone */ }
    }
    watch.sinks.clear();
    if (closing) this.log(`watch job ${jobId}: WatchJob stream ended (${closing.event})`);
  }
}

