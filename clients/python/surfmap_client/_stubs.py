"""The generated protobuf/gRPC modules of proto/surfmap/v1/surfmap.proto.

They are generated at build time into ``<build>/clients/python/gen`` (CMake
target ``surfmap_python_stubs``) and never committed; that directory must be on
``PYTHONPATH``. Importing them in one place gives one clear message when it is
not.
"""

try:
    from surfmap.v1 import surfmap_pb2 as pb  # noqa: F401
    from surfmap.v1 import surfmap_pb2_grpc as pb_grpc  # noqa: F401
except ImportError as error:  # pragma: no cover - exercised only on a broken set-up
    raise ImportError(
        "surfmap_client needs the Python stubs generated from proto/surfmap/v1/surfmap.proto: "
        "build the CMake target 'surfmap_python_stubs' and put <build dir>/clients/python/gen on "
        f"PYTHONPATH (import failed: {error})"
    ) from error

__all__ = ["pb", "pb_grpc"]
