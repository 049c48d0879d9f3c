"""The generated protobuf/gRPC modules of proto/surfmap/v1/surfmap.proto.

They are generated at build time into ``<build>/clients/python/gen`` (CMake
target ``surfmap_python_stubs``, part of ``all``) and never committed. They are
looked for, in this order:

1. ``$SURFMAP_PYTHON_STUBS``: a directory holding ``surfmap/v1/*_pb2*.py``
   (for a build directory elsewhere; set but wrong is an error, not a
   fallback, so a typo is not hidden by an older build);
2. already importable (``surfmap.v1`` on ``sys.path``, e.g. PYTHONPATH);
3. ``<source tree>/build/clients/python/gen``, when this package is used from
   a checkout (in place, or installed with ``pip install -e``) and built with
   the documented ``build/`` directory.

Importing them in one place gives one clear message when none is found.
"""

from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path
from types import ModuleType
from typing import List, Tuple

STUBS_ENV = "SURFMAP_PYTHON_STUBS"
# clients/python/surfmap_client/_stubs.py -> the source tree's root.
_SOURCE_ROOT = Path(__file__).resolve().parents[3]
DEFAULT_STUBS_DIR = _SOURCE_ROOT / "build" / "clients" / "python" / "gen"
_STUB_FILE = Path("surfmap") / "v1" / "surfmap_pb2.py"


def _import_stubs() -> Tuple[ModuleType, ModuleType]:
    pb_module = importlib.import_module("surfmap.v1.surfmap_pb2")
    grpc_module = importlib.import_module("surfmap.v1.surfmap_pb2_grpc")
    return pb_module, grpc_module


def _use_directory(directory: Path) -> Tuple[ModuleType, ModuleType]:
    sys.path.insert(0, str(directory))
    return _import_stubs()


def load_stubs() -> Tuple[ModuleType, ModuleType]:
    """(surfmap_pb2, surfmap_pb2_grpc); ImportError saying what was tried and how to fix it."""
    tried: List[str] = []
    configured = os.environ.get(STUBS_ENV)
    if configured:
        directory = Path(configured)
        if not (directory / _STUB_FILE).is_file():
            raise ImportError(
                f"surfmap_client: {STUBS_ENV}={configured} has no {_STUB_FILE}: point it at "
                "<build dir>/clients/python/gen after building the CMake target 'surfmap_python_stubs'")
        return _use_directory(directory)
    try:
        return _import_stubs()
    except ImportError as error:
        tried.append(f"import surfmap.v1 from sys.path ({error})")
    if (DEFAULT_STUBS_DIR / _STUB_FILE).is_file():
        return _use_directory(DEFAULT_STUBS_DIR)
    tried.append(f"{DEFAULT_STUBS_DIR} (no {_STUB_FILE})")
    raise ImportError(
        "surfmap_client needs the Python stubs generated from proto/surfmap/v1/surfmap.proto. Build them "
        "(cmake --build build --target surfmap_python_stubs) "
        f"and, for a build directory other than build/, set {STUBS_ENV}=<build dir>/clients/python/gen. "
        "Tried: " + "; ".join(tried))


pb, pb_grpc = load_stubs()

__all__ = ["pb", "pb_grpc", "load_stubs", "STUBS_ENV", "DEFAULT_STUBS_DIR"]
