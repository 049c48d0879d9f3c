// The dashboard's HTTP server: the page (static files), the JSON API
// (api_routes.js), the live channel GET /api/jobs/:id/events (Server-Sent
// Events from the shared WatchJob streams of job_watch_hub.js) and
// GET /api/status. GET and HEAD only: the dashboard changes nothing.
//
// Contract:
//   const dash = await startDashboardServer({ client, host, port, log });
//   dash.url      'http://host:port' (port 0 binds a free one)
//   dash.hub      the JobWatchHub (for /api/status and tests)
//   await dash.close()   ends every SSE stream and WatchJob, closes the server
// One log line per request when it finishes: time, method, path, status,
// duration, bytes (SSE requests are logged when they close).
import fs from 'node:fs';
import http from 'node:http';
import { findRoute } from './api_routes.js';
import { ApiError, errorResponse, httpStatusForCode } from './http_errors.js';
import { JobWatchHub } from './job_watch_hub.js';
import { contentType, resolveStatic } from './static_files.js';

const SSE_KEEPALIVE_MS = 15000;

function sendJson(res, status, body) {
  const text = JSON.stringify(body);
  res.writeHead(status, {
    'content-type': 'application/json; charset=utf-8',
    'content-length': Buffer.byteLength(text),
    'cache-control': 'no-store',
  });
  res.end(text);
}

function sendError(res, err) {
  const { httpStatus, body } = errorResponse(err);
  if (res.headersSent) {
    res.destroy();
    return;
  }
  sendJson(res, httpStatus, body);
}

function serveFile(req, res, file) {
  fs.readFile(file, (err, data) => {
    if (err) {
      sendError(res, new ApiError('NOT_FOUND', `cannot read ${req.url}: ${err.code}`));
      return;
    }
    res.writeHead(200, {
      'content-type': contentType(file),
      'content-length': data.length,
      'cache-control': 'no-cache',
    });
    res.end(req.method === 'HEAD' ? undefined : data);
  });
}

// Event stream for one browser: the sink the hub writes to.
function openEventStream(req, res, hub, jobId) {
  res.writeHead(200, {
    'content-type': 'text/event-stream; charset=utf-8',
    'cache-control': 'no-store',
    connection: 'keep-alive',
    'x-accel-buffering': 'no',
  });
  // A browser that loses the stream reconnects after this many ms by itself;
  // the page closes its EventSource on 'end' so a finished job is not re-watched.
  res.write('retry: 3000\n\n');
  let closed = false;
  const sink = {
    send(event, data) {
      if (closed) return;
      res.write(`event: ${event}\ndata: ${JSON.stringify(data)}\n\n`);
    },
    close() {
      if (closed) return;
      closed = true;
      res.end();
    },
  };
  const keepalive = setInterval(() => { if (!closed) res.write(': keepalive\n\n'); }, SSE_KEEPALIVE_MS);
  const unsubscribe = hub.subscribe(jobId, sink);
  res.on('close', () => {
    closed = true;
    clearInterval(keepalive);
    unsubscribe();
  });
}

/**
 * @param {{client: ReturnType<import('./surfmap_client.js').createSurfmapClient>,
 *          host?: string, port?: number, log?: (line: string) => void, mapIntervalMs?: number}} options
 */
export function startDashboardServer({ client, host = '127.0.0.1', port = 8080, log = console.log, mapIntervalMs = 500 }) {
  const hub = new JobWatchHub({
    openStream: (jobId) => client.watchJob({ job_id: jobId, include_map: true }),
    mapIntervalMs,
    log,
  });
  const sockets = new Set();

  const server = http.createServer((req, res) => {
    const started = process.hrtime.bigint();
    let bytes = 0;
    const write = res.write.bind(res);
    const end = res.end.bind(res);
    res.write = (chunk, ...rest) => { if (chunk) bytes += Buffer.byteLength(chunk); return write(chunk, ...rest); };
    res.end = (chunk, ...rest) => { if (chunk && typeof chunk !== 'function') bytes += Buffer.byteLength(chunk); return end(chunk, ...rest); };
    res.on('close', () => {
      const ms = Number(process.hrtime.bigint() - started) / 1e6;
      log(`${new Date().toISOString()} ${req.method} ${req.url} ${res.statusCode} ${ms.toFixed(1)}ms ${bytes}B`);
    });
    handle(req, res).catch((err) => sendError(res, err));
  });
  server.on('connection', (socket) => {
    sockets.add(socket);
    socket.on('close', () => sockets.delete(socket));
  });

  async function handle(req, res) {
    const url = new URL(req.url, 'http://dashboard.invalid');
    if (req.method !== 'GET' && req.method !== 'HEAD') {
      res.setHeader('allow', 'GET, HEAD');
      sendJson(res, 405, { error: { code: 'UNIMPLEMENTED', message: `${req.method} is not allowed: the dashboard is read-only (GET and HEAD)` } });
      return;
    }
    const pathname = url.pathname;
    if (pathname === '/api/status') {
      sendJson(res, 200, { server: client.address, watches: hub.stats() });
      return;
    }
    const events = pathname.match(/^\/api\/jobs\/([^/]+)\/events\/?$/);
    if (events) {
      const route = findRoute(`/api/jobs/${events[1]}`);
      const { job } = route.resolveParams();  // throws INVALID_ARGUMENT for a bad id
      // Fail fast on an unknown job with a normal HTTP error instead of an
      // event stream that fails at once.
      await client.call('GetJob', { job_id: job });
      openEventStream(req, res, hub, job);
      return;
    }
    if (pathname.startsWith('/api/')) {
      const route = findRoute(pathname);
      if (!route) {
        sendJson(res, 404, { error: { code: 'NOT_FOUND', message: `no API route ${pathname}` } });
        return;
      }
      const body = await route.handler({ client, params: route.resolveParams(), query: url.searchParams });
      sendJson(res, 200, body);
      return;
    }
    const file = resolveStatic(pathname);
    if (!file) {
      sendJson(res, httpStatusForCode('NOT_FOUND'), { error: { code: 'NOT_FOUND', message: `no file ${pathname}` } });
      return;
    }
    serveFile(req, res, file);
  }

  return new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(port, host, () => {
      server.off('error', reject);
      const addr = server.address();
      const shownHost = addr.family === 'IPv6' ? `[${addr.address}]` : addr.address;
      resolve({
        url: `http://${shownHost}:${addr.port}`,
        port: addr.port,
        hub,
        server,
        close: () => new Promise((done) => {
          hub.closeAll();
          server.close(() => done());
          for (const socket of sockets) socket.destroy();
        }),
      });
    });
  });
}
