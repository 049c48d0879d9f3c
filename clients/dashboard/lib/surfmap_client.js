// The dashboard's only way to talk to surfmapd: a READ-ONLY gRPC client.
//
// The proto is loaded at run time from proto/surfmap/v1/surfmap.proto (the
// single source of every client; nothing is generated or copied). Only the
// calls in READ_CALLS can be made through this object: the steering and probing
// RPCs (CreateJob, Pause/Resume/Cancel, RefitJob, LeaseCommand, SubmitTrace...)
// are not reachable from the dashboard at all, by construction.
//
// Contract:
//   const client = createSurfmapClient({ address, token, timeoutMs, protoPath });
//   await client.call('GetJob', { job_id: 3 })   -> the response object
//       rejects with the grpc-js error (err.code = grpc status number,
//       err.details = the server's message) on any failure, including the
//       deadline (timeoutMs) which every unary call carries;
//   client.watchJob({ job_id, include_map }) -> a grpc-js ClientReadableStream
//       (no deadline: it lives as long as the job or until cancel());
//   client.close().
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import grpc from '@grpc/grpc-js';
import protoLoader from '@grpc/proto-loader';

const here = path.dirname(fileURLToPath(import.meta.url));
export const DEFAULT_PROTO_PATH = path.resolve(here, '../../../proto/surfmap/v1/surfmap.proto');

// Every unary RPC the dashboard may make, and the service that owns it.
export const READ_CALLS = Object.freeze({
  ListObjects: 'ObjectService',
  GetObject: 'ObjectService',
  GetMesh: 'ObjectService',
  ListJobs: 'JobService',
  GetJob: 'JobService',
  GetPlan: 'JobService',
  ListJobEvents: 'JobService',
  ListSamples: 'MapService',
  GetSample: 'MapService',
  GetMap: 'MapService',
  QueryMap: 'MapService',
  GetTrace: 'TraceService',
});

// The one streaming call it makes (also read-only).
export const WATCH_CALL = Object.freeze({ WatchJob: 'JobService' });

// How messages come out of grpc-js: ids are int64 but far below 2^53, so
// plain numbers are safe and easier for the page; enums as their names.
const LOADER_OPTIONS = {
  keepCase: true,
  longs: Number,
  enums: String,
  defaults: true,
  arrays: true,
  oneofs: true,
};

/**
 * @param {{address: string, token?: string, timeoutMs?: number, protoPath?: string}} options
 */
export function createSurfmapClient({ address, token = '', timeoutMs = 10000, protoPath = DEFAULT_PROTO_PATH }) {
  const definition = protoLoader.loadSync(protoPath, LOADER_OPTIONS);
  const pkg = grpc.loadPackageDefinition(definition).surfmap.v1;

  // Bearer token on every call, streaming included (the server's RequestGate
  // wants role "read" or higher). It goes in per-call metadata because grpc-js
  // refuses call credentials on an insecure channel (loopback lab use; TLS
  // plugs in at the server's RequestGate and here, together).
  const credentials = grpc.credentials.createInsecure();
  const metadata = () => {
    const md = new grpc.Metadata();
    if (token) md.set('authorization', `Bearer ${token}`);
    return md;
  };

  const channelOptions = {
    // Maps of fine levels are large (the server's own limit is 64 MiB).
    'grpc.max_receive_message_length': 256 * 1024 * 1024,
  };
  const stubs = {};
  for (const service of new Set([...Object.values(READ_CALLS), ...Object.values(WATCH_CALL)])) {
    stubs[service] = new pkg[service](address, credentials, channelOptions);
  }

  function call(method, request) {
    const service = READ_CALLS[method];
    if (!service) {
      return Promise.reject(new Error(`surfmap_client: '${method}' is not a read-only call the dashboard may make`));
    }
    const stub = stubs[service];
    return new Promise((resolve, reject) => {
      const deadline = new Date(Date.now() + timeoutMs);
      stub[method](request, metadata(), { deadline }, (err, response) => {
        if (err) reject(err);
        else resolve(response);
      });
    });
  }

  function watchJob(request) {
    return stubs[WATCH_CALL.WatchJob].WatchJob(request, metadata());
  }

  function close() {
    for (const stub of Object.values(stubs)) stub.close();
  }

  return { call, watchJob, close, address };
}
