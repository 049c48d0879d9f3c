#!/usr/bin/env node
// surfmap dashboard: a read-only web view of a running surfmapd.
//
//   node clients/dashboard/server.js --server 127.0.0.1:50051 --listen 127.0.0.1:8080 [--token T] [--ca-file F]
//                                    [--timeout S]
//
// --server defaults to $SURFMAP_SERVER, then 127.0.0.1:50051 (as the CLI);
// --token to $SURFMAP_TOKEN (a token with role "read" is enough); --ca-file
// (default $SURFMAP_CA_FILE) connects with TLS trusting that CA. Prints
// "dashboard: listening on http://HOST:PORT" once it is up (--listen HOST:0
// binds a free port), then one line per request. SIGINT/SIGTERM stop it.
import { readFileSync } from 'node:fs';
import { parseArgs } from 'node:util';
import { startDashboardServer } from './lib/dashboard_server.js';
import { createSurfmapClient } from './lib/surfmap_client.js';

const USAGE = `usage: node server.js [--server HOST:PORT] [--listen HOST:PORT] [--token T] [--ca-file F] [--timeout S]
  --server   surfmapd address (default $SURFMAP_SERVER or 127.0.0.1:50051)
  --listen   where the dashboard serves HTTP (default 127.0.0.1:8080; port 0 = any free port)
  --token    bearer token for surfmapd (default $SURFMAP_TOKEN)
  --ca-file  connect with TLS, trusting the CA in this PEM file (default $SURFMAP_CA_FILE)
  --timeout  deadline of every unary gRPC call, seconds (default 10)`;

function fail(message) {
  process.stderr.write(`dashboard: ${message}\n${USAGE}\n`);
  process.exit(2);
}

function parseHostPort(text, option) {
  const m = /^(\[[^\]]+\]|[^:]+):([0-9]{1,5})$/.exec(text);
  if (!m || Number(m[2]) > 65535) fail(`${option} '${text}' is not HOST:PORT`);
  return { host: m[1].replace(/^\[|\]$/g, ''), port: Number(m[2]) };
}

let args;
try {
  args = parseArgs({
    options: {
      server: { type: 'string', default: process.env.SURFMAP_SERVER || '127.0.0.1:50051' },
      listen: { type: 'string', default: '127.0.0.1:8080' },
      token: { type: 'string', default: process.env.SURFMAP_TOKEN || '' },
      'ca-file': { type: 'string', default: process.env.SURFMAP_CA_FILE || '' },
      timeout: { type: 'string', default: '10' },
      help: { type: 'boolean', short: 'h', default: false },
    },
    strict: true,
    allowPositionals: false,
  }).values;
} catch (err) {
  fail(err.message);
}
if (args.help) {
  process.stdout.write(`${USAGE}\n`);
  process.exit(0);
}
parseHostPort(args.server, '--server');
const listen = parseHostPort(args.listen, '--listen');
const timeoutS = Number(args.timeout);
if (!Number.isFinite(timeoutS) || timeoutS <= 0) fail(`--timeout '${args.timeout}' is not a positive number of seconds`);

let caPem = null;
if (args['ca-file']) {
  try {
    caPem = readFileSync(args['ca-file']);
  } catch (err) {
    fail(`--ca-file '${args['ca-file']}' cannot be read: ${err.message}`);
  }
}

const client = createSurfmapClient({ address: args.server, token: args.token, timeoutMs: timeoutS * 1000, caPem });
let dashboard;
try {
  dashboard = await startDashboardServer({ client, host: listen.host, port: listen.port });
} catch (err) {
  process.stderr.write(`dashboard: cannot listen on ${args.listen}: ${err.message}\n`);
  process.exit(1);
}
console.log(`dashboard: listening on ${dashboard.url} (surfmapd at ${args.server}, read-only)`);

let stopping = false;
const stop = async (signal) => {
  if (stopping) return;
  stopping = true;
  console.log(`dashboard: ${signal}, stopping`);
  await dashboard.close();
  client.close();
  process.exit(0);
};
process.on('SIGINT', () => stop('SIGINT'));
process.on('SIGTERM', () => stop('SIGTERM'));
