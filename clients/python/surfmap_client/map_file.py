"""A SurfaceMap as the project's map file (``surfmap map get --format json``).

The format ``surfmap.map.v1`` is defined in clients/remote/map_json.h; this writes
the members its readers use (``surfmap-rig score`` among them): job_id, level,
vertex_count, per-vertex position/normal/mu/mu_uncertainty/sigma/a1/a2,
triangles, the samples (site, position, drag direction, segment length, mu,
mu_std) and a summary. Unknown values (NaN) are written as null. The full
protobuf ``fit`` object of each sample, which the CLI adds, is left out.
"""

from __future__ import annotations

import json
import math
from typing import Any, Dict, List

import numpy as np

from .records import SurfaceMap

MAP_FILE_FORMAT = "surfmap.map.v1"


def _numbers(values: np.ndarray) -> List[Any]:
    return [float(v) if math.isfinite(v) else None for v in np.asarray(values, dtype=float).ravel()]


def _points(values: np.ndarray) -> List[List[Any]]:
    return [_numbers(row) for row in np.asarray(values, dtype=float)]


def map_to_document(surface: SurfaceMap) -> Dict[str, Any]:
    """The map file as a JSON-ready dict. ValueError when the map has no mesh
    (fetched with include_mesh=False): its readers need vertex positions."""
    if surface.positions is None or surface.triangles is None:
        raise ValueError(f"map of job {surface.job_id} has no mesh: fetch it with get_map(include_mesh=True)")
    vertices: Dict[str, Any] = {"position": _points(surface.positions)}
    if surface.normals is not None:
        vertices["normal"] = _points(surface.normals)
    for name in ("mu", "mu_uncertainty", "sigma", "a1", "a2"):
        vertices[name] = _numbers(getattr(surface, name))
    samples = []
    per_level: Dict[str, int] = {}
    for s in surface.samples:
        per_level[str(s.level)] = per_level.get(str(s.level), 0) + 1
        record: Dict[str, Any] = {
            "trace_id": s.trace_id, "command_id": s.command_id, "site": {"level": s.level, "vertex": s.vertex},
            "position": _numbers(s.position), "drag_direction": _numbers(s.drag_direction),
            "segment_length_mm": s.segment_length_mm,
        }
        if s.fit is not None:
            record["mu"] = s.fit.friction.mu
            record["mu_std"] = s.fit.friction.mu_std
        samples.append(record)
    known = surface.mu[np.isfinite(surface.mu)]
    unc = surface.mu_uncertainty[np.isfinite(surface.mu_uncertainty)]
    summary: Dict[str, Any] = {
        "samples": len(surface.samples), "samples_per_level": per_level,
        "mu_min": float(known.min()) if known.size else None, "mu_max": float(known.max()) if known.size else None,
        "mu_mean": float(known.mean()) if known.size else None,
        "mu_uncertainty_mean": float(unc.mean()) if unc.size else None,
    }
    return {
        "format": MAP_FILE_FORMAT, "job_id": surface.job_id, "level": surface.level,
        "vertex_count": surface.vertex_count, "vertices": vertices,
        "triangles": [[int(i) for i in tri] for tri in surface.triangles],
        "samples": samples, "summary": summary,
    }


def write_map_file(surface: SurfaceMap, path: str) -> None:
    """Writes ``map_to_document(surface)`` to ``path`` (see there for errors)."""
    with open(path, "w", encoding="utf-8") as out:
        json.dump(map_to_document(surface), out)
