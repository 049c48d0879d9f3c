"""SurfmapError: the one exception type of the client."""

from __future__ import annotations

import grpc


class SurfmapError(Exception):
    """A call failed.

    ``code`` is the gRPC status code (``grpc.StatusCode``): the server's
    (NOT_FOUND for an unknown id, INVALID_ARGUMENT for a bad field,
    FAILED_PRECONDITION for a call in the wrong state, UNAUTHENTICATED /
    PERMISSION_DENIED with tokens, DEADLINE_EXCEEDED when the per-call timeout
    ran out, UNAVAILABLE when the server cannot be reached), or
    INVALID_ARGUMENT for an argument the client rejected before sending.
    ``message`` is the server's message verbatim; ``method`` names the call.
    """

    def __init__(self, code: grpc.StatusCode, message: str, method: str = "") -> None:
        self.code = code
        self.message = message
        self.method = method
        prefix = f"{method}: " if method else ""
        super().__init__(f"{prefix}{code.name}: {message}")


def error_from_rpc(error: grpc.RpcError, method: str) -> SurfmapError:
    """Converts what grpcio raises (a grpc.RpcError that is also a grpc.Call)."""
    code = error.code() if hasattr(error, "code") else grpc.StatusCode.UNKNOWN
    details = error.details() if hasattr(error, "details") else str(error)
    return SurfmapError(code or grpc.StatusCode.UNKNOWN, details or "", method)


def invalid_argument(method: str, message: str) -> SurfmapError:
    """A client-side rejection: the request was never sent."""
    return SurfmapError(grpc.StatusCode.INVALID_ARGUMENT, message, method)
