"""The map as a texture model for renderers: the same files as
``surfmap map get --format gltf|glb|ply|texture-json`` (docs/texture-model.md),
written from a GetMap response (with its mesh).

    client.export_map(job_id, "bottle.gltf")          # format from the suffix
    write_texture_json(response, "bottle.texture.json")

glTF: one triangle primitive, POSITION in metres, NORMAL, and FLOAT SCALAR
custom attributes _MU _MU_STD _SIGMA _A1 _A2 _K1 _K2 _REGION
_BOUNDARY_PROBABILITY (unknown = -1 where the value is never negative; _A*/_K*
are 0 where sigma is unknown); ``meshes[0].extras.surfmap`` carries the job,
level, grid step, units and the per-region texture model.
"""

from __future__ import annotations

import base64
import json
import math
import struct
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

TEXTURE_MODEL_FORMAT = "surfmap.texture-model.v1"
TEXTURE_GLTF_FORMAT = "surfmap.texture-gltf.v1"
TEXTURE_PLY_FORMAT = "surfmap.texture-ply.v1"
UNITS = {"length": "mm", "force": "N", "mu": "1", "sigma": "N", "grid_step": "mm"}
MODEL_TEXT = ("F_t = mu F_n + r(s) against the sliding direction; r(k) = a1 r(k-1) + ... + ap r(k-p) + sigma e(k), "
              "e ~ N(0,1), k = round(s / grid_step_mm), s = arc length slid (mm)")
_GLTF_FLOAT = 5126
_GLTF_UINT = 5125


def grid_step_of(map_level: Any) -> float:
    """The AR grid step of the map's samples' fits (mm), 0.1 when none has one."""
    for s in map_level.samples:
        step = s.fit.roughness.grid_step_mm
        if math.isfinite(step) and step > 0:
            return float(step)
    return 0.1


def _reflection(a1: float, a2: float) -> Tuple[float, float]:
    """AR(2) -> reflection coefficients (Levinson step-down): k2 = a2, k1 = a1 / (1 - a2)."""
    k2 = a2
    k1 = a1 / (1.0 - k2) if k2 != 1.0 else 0.0
    return k1, k2


def texture_arrays(response: Any) -> Dict[str, Any]:
    """Per-vertex arrays of a GetMapResponse (positions, normals, triangles,
    mu, mu_std, sigma, a1, a2, k1, k2, region, boundary_probability) plus
    job_id, level, grid_step_mm. ValueError without a mesh."""
    m, mesh = response.map, response.mesh
    n = len(mesh.positions)
    if n == 0:
        raise ValueError(f"map of job {m.job_id} has no mesh: fetch it with include_mesh")
    out: Dict[str, Any] = {"job_id": int(m.job_id), "level": int(m.level), "grid_step_mm": grid_step_of(m)}
    out["positions"] = np.array([(p.x, p.y, p.z) for p in mesh.positions], dtype=float)
    out["normals"] = np.array([(p.x, p.y, p.z) for p in mesh.normals], dtype=float) if len(mesh.normals) == n else None
    out["triangles"] = np.array(mesh.triangle_indices, dtype=np.int64).reshape(-1, 3)
    nan = np.full(n, np.nan)
    out["mu"] = np.array(m.mu, dtype=float) if len(m.mu) == n else nan.copy()
    out["mu_std"] = np.array(m.mu_uncertainty, dtype=float) if len(m.mu_uncertainty) == n else nan.copy()
    rough = len(m.sigma) == n and len(m.a1) == n and len(m.a2) == n
    for name in ("sigma", "a1", "a2"):
        out[name] = np.array(getattr(m, name), dtype=float) if rough else None
    if rough:
        k = np.array([_reflection(a1, a2) for a1, a2 in zip(out["a1"], out["a2"])], dtype=float).reshape(n, 2)
        known = np.isfinite(out["sigma"]) & (out["sigma"] > 0)
        k[~known] = 0.0
        out["k1"], out["k2"] = k[:, 0], k[:, 1]
    else:
        out["k1"] = out["k2"] = None
    region = list(getattr(m, "region", []))
    out["region"] = np.array(region, dtype=np.int64) if len(region) == n else None
    bp = list(getattr(m, "boundary_probability", []))
    out["boundary_probability"] = np.array(bp, dtype=float) if len(bp) == n else None
    out["regions"] = list(getattr(m, "regions", []))
    return out


def _number(v: float) -> Optional[float]:
    return float(v) if math.isfinite(v) else None


def _impulse_gain(a: List[float], tail: float = 1e-8, max_len: int = 512) -> float:
    """sum h_j^2 of the AR model's impulse response (Var r = sigma^2 * gain)."""
    h: List[float] = []
    energy = 0.0
    p = len(a)
    for n in range(max_len):
        v = 1.0 if n == 0 else 0.0
        for i in range(1, min(p, n) + 1):
            v += a[i - 1] * h[n - i]
        h.append(v)
        energy += v * v
        if n >= max(p, 1) and sum(x * x for x in h[-max(p, 1):]) < tail * energy:
            break
    return energy


def texture_model(response: Any) -> Dict[str, Any]:
    """The texture model JSON document (``surfmap.texture-model.v1``)."""
    t = texture_arrays(response)
    n = len(t["positions"])
    region = t["region"]
    counts = np.bincount(region[region >= 0], minlength=len(t["regions"])) if region is not None else None
    regions = []
    for i, r in enumerate(t["regions"]):
        a = [float(x) for x in r.ar_coefficients]
        std = r.sigma * math.sqrt(_impulse_gain(a)) if a and r.sigma > 0 else 0.0
        regions.append({
            "region": int(r.region), "mu": _number(r.mu), "mu_se": _number(r.mu_se), "mu_spread": _number(r.mu_spread),
            "piece_count": int(r.piece_count), "roughness_piece_count": int(r.roughness_piece_count),
            "ar_order": len(a), "ar_coefficients": a, "reflection": [float(x) for x in r.reflection],
            "sigma": _number(r.sigma), "roughness_std_n": _number(std), "area_mm2": _number(r.area_mm2),
            "vertex_count": int(counts[i]) if counts is not None and i < len(counts) else 0,
        })
    return {
        "format": TEXTURE_MODEL_FORMAT, "job_id": t["job_id"], "level": t["level"], "units": UNITS,
        "grid_step_mm": t["grid_step_mm"], "model": MODEL_TEXT, "vertex_count": n,
        "unassigned_vertex_count": int((region < 0).sum()) if region is not None else n,
        "regions": regions,
    }


def write_texture_json(response: Any, path: str) -> None:
    with open(path, "w", encoding="utf-8") as out:
        json.dump(texture_model(response), out, indent=1)
        out.write("\n")


def _known_or(values: np.ndarray, unknown: float = -1.0) -> np.ndarray:
    return np.where(np.isfinite(values), values, unknown).astype(np.float32)


def gltf_document(response: Any) -> Tuple[Dict[str, Any], bytes]:
    """The glTF JSON (without its buffer's uri) and the binary buffer."""
    t = texture_arrays(response)
    n = len(t["positions"])
    blob = bytearray()
    views: List[Dict[str, Any]] = []
    accessors: List[Dict[str, Any]] = []

    def add(data: np.ndarray, component: int, kind: str, target: int) -> int:
        while len(blob) % 4:
            blob.append(0)
        raw = data.tobytes()
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(raw), "target": target})
        blob.extend(raw)
        count = data.shape[0] if data.ndim == 1 or kind != "SCALAR" else data.size
        accessors.append({"bufferView": len(views) - 1, "componentType": component, "count": int(count), "type": kind})
        return len(accessors) - 1

    pos = (t["positions"] * 1e-3).astype(np.float32)
    attributes = {"POSITION": add(pos, _GLTF_FLOAT, "VEC3", 34962)}
    accessors[-1]["min"] = [float(v) for v in pos.min(axis=0)]
    accessors[-1]["max"] = [float(v) for v in pos.max(axis=0)]
    if t["normals"] is not None:
        nrm = t["normals"].astype(np.float32)
        length = np.linalg.norm(nrm, axis=1, keepdims=True)
        nrm = np.where(length > 0, nrm / np.where(length > 0, length, 1), np.array([0, 0, 1], dtype=np.float32))
        attributes["NORMAL"] = add(nrm.astype(np.float32), _GLTF_FLOAT, "VEC3", 34962)
    attributes["_MU"] = add(_known_or(t["mu"]), _GLTF_FLOAT, "SCALAR", 34962)
    attributes["_MU_STD"] = add(_known_or(t["mu_std"]), _GLTF_FLOAT, "SCALAR", 34962)
    if t["sigma"] is not None:
        known = np.isfinite(t["sigma"])
        attributes["_SIGMA"] = add(_known_or(t["sigma"]), _GLTF_FLOAT, "SCALAR", 34962)
        for name in ("a1", "a2", "k1", "k2"):
            v = np.where(known & np.isfinite(t[name]), t[name], 0.0).astype(np.float32)
            attributes["_" + name.upper()] = add(v, _GLTF_FLOAT, "SCALAR", 34962)
    if t["region"] is not None:
        attributes["_REGION"] = add(t["region"].astype(np.float32), _GLTF_FLOAT, "SCALAR", 34962)
    if t["boundary_probability"] is not None:
        attributes["_BOUNDARY_PROBABILITY"] = add(_known_or(t["boundary_probability"]), _GLTF_FLOAT, "SCALAR", 34962)
    indices = add(t["triangles"].astype(np.uint32).ravel(), _GLTF_UINT, "SCALAR", 34963)
    while len(blob) % 4:
        blob.append(0)
    extras = {"format": TEXTURE_GLTF_FORMAT, "job_id": t["job_id"], "level": t["level"],
              "grid_step_mm": t["grid_step_mm"], "position_units": "m", "map_units": UNITS, "unknown_value": -1.0,
              "ar_order": 2 if t["sigma"] is not None else 0, "texture_model": texture_model(response)}
    doc = {
        "asset": {"version": "2.0", "generator": "surfmap_client"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": "surfmap_map"}],
        "meshes": [{"name": f"surfmap job {t['job_id']} level {t['level']}",
                    "primitives": [{"attributes": attributes, "indices": indices, "mode": 4}],
                    "extras": {"surfmap": extras}}],
        "accessors": accessors, "bufferViews": views, "buffers": [{"byteLength": len(blob)}],
    }
    assert n == accessors[0]["count"]
    return doc, bytes(blob)


def write_gltf(response: Any, path: str, binary: Optional[bool] = None) -> None:
    """A .gltf (buffer embedded as a data URI) or, for binary (default: a
    .glb suffix), a GLB container."""
    doc, blob = gltf_document(response)
    if binary is None:
        binary = str(path).lower().endswith(".glb")
    if not binary:
        doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode("ascii")
        with open(path, "w", encoding="utf-8") as out:
            json.dump(doc, out)
        return
    text = json.dumps(doc).encode("utf-8")
    text += b" " * (-len(text) % 4)
    total = 12 + 8 + len(text) + 8 + len(blob)
    with open(path, "wb") as out:
        out.write(struct.pack("<4sII", b"glTF", 2, total))
        out.write(struct.pack("<I4s", len(text), b"JSON") + text)
        out.write(struct.pack("<I4s", len(blob), b"BIN\0") + blob)


def write_ply(response: Any, path: str) -> None:
    """ASCII PLY with every per-vertex attribute (as the CLI's ``--format ply``)."""
    t = texture_arrays(response)
    n = len(t["positions"])
    columns: List[Tuple[str, np.ndarray]] = [("x", t["positions"][:, 0]), ("y", t["positions"][:, 1]),
                                             ("z", t["positions"][:, 2])]
    if t["normals"] is not None:
        columns += [("nx", t["normals"][:, 0]), ("ny", t["normals"][:, 1]), ("nz", t["normals"][:, 2])]
    columns += [("mu", t["mu"]), ("mu_std", t["mu_std"])]
    if t["sigma"] is not None:
        columns += [(name, t[name]) for name in ("sigma", "a1", "a2", "k1", "k2")]
    lines = ["ply", "format ascii 1.0", f"comment {TEXTURE_PLY_FORMAT}", f"comment job_id {t['job_id']}",
             f"comment level {t['level']}", f"comment grid_step_mm {t['grid_step_mm']!r}", "comment units mm N",
             f"element vertex {n}"]
    lines += [f"property double {name}" for name, _ in columns]
    if t["region"] is not None:
        lines.append("property int region")
    if t["boundary_probability"] is not None:
        lines.append("property double boundary_probability")
    lines += [f"element face {len(t['triangles'])}", "property list uchar int vertex_indices", "end_header"]

    def fmt(v: float) -> str:
        return "nan" if not math.isfinite(v) else repr(float(v))

    for v in range(n):
        fields = [fmt(c[v]) for _, c in columns]
        if t["region"] is not None:
            fields.append(str(int(t["region"][v])))
        if t["boundary_probability"] is not None:
            fields.append(fmt(t["boundary_probability"][v]))
        lines.append(" ".join(fields))
    lines += [f"3 {a} {b} {c}" for a, b, c in t["triangles"]]
    with open(path, "w", encoding="utf-8") as out:
        out.write("\n".join(lines) + "\n")


def write_texture_file(response: Any, path: str, format: Optional[str] = None) -> str:
    """Writes ``path`` in ``format`` (gltf, glb, ply, texture-json; default
    from the suffix). Returns the format used. ValueError for an unknown one."""
    fmt = format
    if fmt is None:
        lower = str(path).lower()
        fmt = ("texture-json" if lower.endswith(".texture.json") else "glb" if lower.endswith(".glb")
               else "gltf" if lower.endswith(".gltf") else "ply" if lower.endswith(".ply") else "")
    if fmt in ("gltf", "glb"):
        write_gltf(response, path, binary=fmt == "glb")
    elif fmt == "ply":
        write_ply(response, path)
    elif fmt == "texture-json":
        write_texture_json(response, path)
    else:
        raise ValueError(f"unknown texture export format for {path!r}: use gltf, glb, ply or texture-json")
    return fmt
