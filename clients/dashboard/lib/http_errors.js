// How failures reach the browser: one JSON shape, { error: { code, message } },
// with `code` a gRPC status name and the HTTP status chosen by its meaning.
//
// gRPC errors from surfmapd keep the server's code name and message (the
// message already names what is wrong); the dashboard's own checks of the
// request (a bad id, a missing parameter) use the same names.

// grpc status number -> name (the order of grpc's status.proto).
export const GRPC_CODE_NAMES = Object.freeze([
  'OK', 'CANCELLED', 'UNKNOWN', 'INVALID_ARGUMENT', 'DEADLINE_EXCEEDED', 'NOT_FOUND',
  'ALREADY_EXISTS', 'PERMISSION_DENIED', 'RESOURCE_EXHAUSTED', 'FAILED_PRECONDITION',
  'ABORTED', 'OUT_OF_RANGE', 'UNIMPLEMENTED', 'INTERNAL', 'UNAVAILABLE', 'DATA_LOSS',
  'UNAUTHENTICATED',
]);

// The usual gRPC -> HTTP mapping (as grpc-gateway does it). UNAVAILABLE is
// 503 so a browser knows to retry; a deadline is 504 (the gateway timed out).
const HTTP_STATUS_BY_NAME = Object.freeze({
  OK: 200,
  CANCELLED: 499,
  UNKNOWN: 500,
  INVALID_ARGUMENT: 400,
  DEADLINE_EXCEEDED: 504,
  NOT_FOUND: 404,
  ALREADY_EXISTS: 409,
  PERMISSION_DENIED: 403,
  RESOURCE_EXHAUSTED: 429,
  FAILED_PRECONDITION: 400,
  ABORTED: 409,
  OUT_OF_RANGE: 400,
  UNIMPLEMENTED: 501,
  INTERNAL: 500,
  UNAVAILABLE: 503,
  DATA_LOSS: 500,
  UNAUTHENTICATED: 401,
});

/** An error the dashboard raises itself, already in the API's terms. */
export class ApiError extends Error {
  constructor(codeName, message) {
    super(message);
    this.codeName = codeName;
  }
}

export function invalidArgument(message) {
  return new ApiError('INVALID_ARGUMENT', message);
}

export function notFound(message) {
  return new ApiError('NOT_FOUND', message);
}

/**
 * Any thrown value -> { httpStatus, body } for the response.
 * grpc-js errors carry a numeric `code` and the server's text in `details`.
 */
export function errorResponse(err) {
  let codeName = 'INTERNAL';
  let message = String(err && err.message ? err.message : err);
  if (err instanceof ApiError) {
    codeName = err.codeName;
  } else if (err && Number.isInteger(err.code) && GRPC_CODE_NAMES[err.code]) {
    codeName = GRPC_CODE_NAMES[err.code];
    message = `surfmapd: ${err.details || err.message}`;
  }
  return {
    httpStatus: HTTP_STATUS_BY_NAME[codeName] ?? 500,
    body: { error: { code: codeName, message } },
  };
}

export function httpStatusForCode(codeName) {
  return HTTP_STATUS_BY_NAME[codeName] ?? 500;
}
