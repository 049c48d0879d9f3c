// The client loads the real proto, exposes only read calls, puts a deadline
// on every unary call and sends the bearer token (checked against small
// in-process gRPC servers built from the same proto).
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { test } from 'node:test';
import grpc from '@grpc/grpc-js';
import protoLoader from '@grpc/proto-loader';
import { DEFAULT_PROTO_PATH, READ_CALLS, WATCH_CALL, createSurfmapClient } from './surfmap_client.js';

const STEERING_AND_PROBING = [
  'UploadObject', 'CreateJob', 'PauseJob', 'ResumeJob', 'CancelJob', 'RefitJob',
  'LeaseCommand', 'SubmitTrace', 'SubmitTraceStream', 'ReportFailure',
];

test('the allow-list holds no steering or probing call', () => {
  for (const name of STEERING_AND_PROBING) {
    assert.equal(READ_CALLS[name], undefined, `${name} must not be callable`);
    assert.equal(WATCH_CALL[name], undefined);
  }
});

test('every allowed call exists in the proto under its service', () => {
  const proto = fs.readFileSync(DEFAULT_PROTO_PATH, 'utf8');
  for (const [method, service] of Object.entries({ ...READ_CALLS, ...WATCH_CALL })) {
    const serviceBody = proto.split(`service ${service} {`)[1];
    assert.ok(serviceBody, `service ${service} is in the proto`);
    assert.match(serviceBody.split('}')[0], new RegExp(`rpc ${method}\\(`), `${service}.${method} is in the proto`);
  }
});

test('a steering call is refused before anything is sent', async () => {
  const client = createSurfmapClient({ address: '127.0.0.1:1', timeoutMs: 200 });
  try {
    await assert.rejects(client.call('CancelJob', { job_id: 1 }), /not a read-only call/);
  } finally {
    client.close();
  }
});

test('unary calls carry a deadline', async () => {
  // A server that accepts ListObjects and never answers: without a deadline
  // the call would hang (and the test time out); with it, DEADLINE_EXCEEDED.
  const definition = protoLoader.loadSync(DEFAULT_PROTO_PATH, { keepCase: true });
  const pkg = grpc.loadPackageDefinition(definition).surfmap.v1;
  const server = new grpc.Server();
  server.addService(pkg.ObjectService.service, { ListObjects: () => {} });
  const port = await new Promise((resolve, reject) => {
    server.bindAsync('127.0.0.1:0', grpc.ServerCredentials.createInsecure(), (err, p) => (err ? reject(err) : resolve(p)));
  });
  const client = createSurfmapClient({ address: `127.0.0.1:${port}`, timeoutMs: 300 });
  const started = Date.now();
  try {
    await assert.rejects(client.call('ListObjects', {}), (err) => err.code === grpc.status.DEADLINE_EXCEEDED);
    assert.ok(Date.now() - started < 5000);
  } finally {
    client.close();
    server.forceShutdown();
  }
});

test('the bearer token goes with every call', async () => {
  const definition = protoLoader.loadSync(DEFAULT_PROTO_PATH, { keepCase: true });
  const pkg = grpc.loadPackageDefinition(definition).surfmap.v1;
  const seen = [];
  const server = new grpc.Server();
  server.addService(pkg.ObjectService.service, {
    ListObjects: (call, done) => {
      seen.push(call.metadata.get('authorization')[0]);
      done(null, { objects: [] });
    },
  });
  const port = await new Promise((resolve, reject) => {
    server.bindAsync('127.0.0.1:0', grpc.ServerCredentials.createInsecure(), (err, p) => (err ? reject(err) : resolve(p)));
  });
  const client = createSurfmapClient({ address: `127.0.0.1:${port}`, token: 's3cret', timeoutMs: 2000 });
  try {
    assert.deepEqual(await client.call('ListObjects', {}), { objects: [] });
    assert.deepEqual(seen, ['Bearer s3cret']);
  } finally {
    client.close();
    server.forceShutdown();
  }
});

test('with caPem the channel is TLS, and trusts that CA only', async () => {
  // A throw-away CA and a server certificate for 127.0.0.1, made by openssl.
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'dashboard-tls-'));
  const openssl = (...args) => execFileSync('openssl', args, { cwd: dir, stdio: 'ignore' });
  openssl('req', '-x509', '-newkey', 'rsa:2048', '-nodes', '-keyout', 'ca.key', '-out', 'ca.pem', '-days', '1',
    '-subj', '/CN=dashboard-test-ca');
  openssl('req', '-x509', '-newkey', 'rsa:2048', '-nodes', '-keyout', 'wrong.key', '-out', 'wrong.pem', '-days', '1',
    '-subj', '/CN=dashboard-wrong-ca');
  fs.writeFileSync(path.join(dir, 'server.ext'), 'subjectAltName=IP:127.0.0.1,DNS:localhost\n');
  openssl('req', '-newkey', 'rsa:2048', '-nodes', '-keyout', 'server.key', '-out', 'server.csr', '-subj', '/CN=localhost');
  openssl('x509', '-req', '-in', 'server.csr', '-CA', 'ca.pem', '-CAkey', 'ca.key', '-CAcreateserial', '-out',
    'server.pem', '-days', '1', '-extfile', 'server.ext');
  const read = (name) => fs.readFileSync(path.join(dir, name));

  const definition = protoLoader.loadSync(DEFAULT_PROTO_PATH, { keepCase: true });
  const pkg = grpc.loadPackageDefinition(definition).surfmap.v1;
  const server = new grpc.Server();
  server.addService(pkg.ObjectService.service, { ListObjects: (call, done) => done(null, { objects: [] }) });
  const credentials = grpc.ServerCredentials.createSsl(null, [
    { private_key: read('server.key'), cert_chain: read('server.pem') },
  ]);
  const port = await new Promise((resolve, reject) => {
    server.bindAsync('127.0.0.1:0', credentials, (err, p) => (err ? reject(err) : resolve(p)));
  });
  const address = `127.0.0.1:${port}`;
  const trusting = createSurfmapClient({ address, timeoutMs: 5000, caPem: read('ca.pem') });
  const plaintext = createSurfmapClient({ address, timeoutMs: 2000 });
  const wrong = createSurfmapClient({ address, timeoutMs: 2000, caPem: read('wrong.pem') });
  try {
    assert.deepEqual(await trusting.call('ListObjects', {}), { objects: [] });
    await assert.rejects(plaintext.call('ListObjects', {}), (err) => err.code === grpc.status.UNAVAILABLE
      || err.code === grpc.status.DEADLINE_EXCEEDED);
    await assert.rejects(wrong.call('ListObjects', {}), (err) => err.code === grpc.status.UNAVAILABLE
      || err.code === grpc.status.DEADLINE_EXCEEDED);
  } finally {
    for (const c of [trusting, plaintext, wrong]) c.close();
    server.forceShutdown();
    fs.rmSync(dir, { recursive: true, force: true });
  }
});
