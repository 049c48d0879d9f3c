"""The texture exports written from a hand-built GetMap response (no server),
parsed back: every attribute checked, unknowns as the format says."""

from __future__ import annotations

import base64
import json
import math
import struct
from typing import Any

import numpy as np

from surfmap_client import texture_export as te
from surfmap_client._stubs import pb


def _response() -> Any:
    # A unit square of two triangles, 4 vertices; vertex 3 unknown.
    m = pb.MapLevel(job_id=7, level=2, vertex_count=4)
    m.mu.extend([0.3, 0.5, 0.31, math.nan])
    m.mu_uncertainty.extend([0.01, 0.02, 0.03, math.nan])
    m.sigma.extend([0.11, 0.16, 0.0, 0.0])
    m.a1.extend([0.6, 1.61, 0.0, 0.0])
    m.a2.extend([0.25, -0.73, 0.0, 0.0])
    m.region.extend([0, 1, 0, -1])
    m.boundary_probability.extend([0.0, 0.5, 0.1, 0.0])
    m.regions.add(region=0, mu=0.305, mu_se=0.003, piece_count=4, roughness_piece_count=3,
                  reflection=[0.8, 0.25], ar_coefficients=[0.6, 0.25], sigma=0.11, area_mm2=2.0)
    m.regions.add(region=1, mu=0.5, mu_se=0.004, piece_count=2, roughness_piece_count=2,
                  reflection=[0.93, -0.73], ar_coefficients=[1.61, -0.73], sigma=0.16, area_mm2=1.0)
    s = m.samples.add()
    s.fit.roughness.grid_step_mm = 0.05
    mesh = pb.GetMeshResponse(level=2)
    for x, y in [(0, 0), (10, 0), (0, 10), (10, 10)]:
        mesh.positions.add(x=x, y=y, z=0)
        mesh.normals.add(x=0, y=0, z=1)
    mesh.triangle_indices.extend([0, 1, 3, 0, 3, 2])
    return pb.GetMapResponse(map=m, mesh=mesh)


def _accessor(doc, blob, index, dtype, width):
    a = doc["accessors"][index]
    v = doc["bufferViews"][a["bufferView"]]
    data = np.frombuffer(blob, dtype=dtype, count=a["count"] * width, offset=v["byteOffset"])
    return data.reshape(a["count"], width) if width > 1 else data


def _check_gltf(doc, blob):
    attrs = doc["meshes"][0]["primitives"][0]["attributes"]
    pos = _accessor(doc, blob, attrs["POSITION"], np.float32, 3)
    np.testing.assert_allclose(pos[3], [0.010, 0.010, 0.0], rtol=1e-6)  # metres
    mu = _accessor(doc, blob, attrs["_MU"], np.float32, 1)
    np.testing.assert_allclose(mu, [0.3, 0.5, 0.31, -1.0], rtol=1e-6)  # -1 = unknown
    np.testing.assert_allclose(_accessor(doc, blob, attrs["_MU_STD"], np.float32, 1), [0.01, 0.02, 0.03, -1], rtol=1e-6)
    np.testing.assert_allclose(_accessor(doc, blob, attrs["_SIGMA"], np.float32, 1), [0.11, 0.16, 0, 0], rtol=1e-6)
    np.testing.assert_allclose(_accessor(doc, blob, attrs["_A1"], np.float32, 1), [0.6, 1.61, 0, 0], rtol=1e-6)
    np.testing.assert_allclose(_accessor(doc, blob, attrs["_A2"], np.float32, 1), [0.25, -0.73, 0, 0], rtol=1e-6)
    # k1 = a1 / (1 - a2): rubber 0.6 / 0.75 = 0.8; masonite 1.61 / 1.73 = 0.9306.
    np.testing.assert_allclose(_accessor(doc, blob, attrs["_K1"], np.float32, 1)[:2], [0.8, 1.61 / 1.73], rtol=1e-6)
    np.testing.assert_allclose(_accessor(doc, blob, attrs["_K2"], np.float32, 1)[:2], [0.25, -0.73], rtol=1e-6)
    np.testing.assert_array_equal(_accessor(doc, blob, attrs["_REGION"], np.float32, 1), [0, 1, 0, -1])
    np.testing.assert_allclose(_accessor(doc, blob, attrs["_BOUNDARY_PROBABILITY"], np.float32, 1),
                               [0, 0.5, 0.1, 0], rtol=1e-6)
    idx = _accessor(doc, blob, doc["meshes"][0]["primitives"][0]["indices"], np.uint32, 1)
    np.testing.assert_array_equal(idx, [0, 1, 3, 0, 3, 2])
    extras = doc["meshes"][0]["extras"]["surfmap"]
    assert extras["format"] == te.TEXTURE_GLTF_FORMAT
    assert extras["grid_step_mm"] == 0.05
    assert [r["mu"] for r in extras["texture_model"]["regions"]] == [0.305, 0.5]


def test_gltf_round_trip(tmp_path):
    path = tmp_path / "map.gltf"
    assert te.write_texture_file(_response(), str(path)) == "gltf"
    doc = json.loads(path.read_text())
    uri = doc["buffers"][0]["uri"]
    blob = base64.b64decode(uri.split(",", 1)[1])
    assert len(blob) == doc["buffers"][0]["byteLength"]
    _check_gltf(doc, blob)


def test_glb_round_trip(tmp_path):
    path = tmp_path / "map.glb"
    assert te.write_texture_file(_response(), str(path)) == "glb"
    data = path.read_bytes()
    magic, version, total = struct.unpack_from("<4sII", data, 0)
    assert (magic, version, total) == (b"glTF", 2, len(data))
    json_len, kind = struct.unpack_from("<I4s", data, 12)
    assert kind == b"JSON"
    doc = json.loads(data[20:20 + json_len])
    bin_len, kind = struct.unpack_from("<I4s", data, 20 + json_len)
    assert kind == b"BIN\0"
    _check_gltf(doc, data[28 + json_len:28 + json_len + bin_len])


def test_texture_json(tmp_path):
    path = tmp_path / "map.texture.json"
    assert te.write_texture_file(_response(), str(path)) == "texture-json"
    doc = json.loads(path.read_text())
    assert doc["format"] == te.TEXTURE_MODEL_FORMAT
    assert doc["grid_step_mm"] == 0.05 and doc["units"]["sigma"] == "N"
    assert doc["vertex_count"] == 4 and doc["unassigned_vertex_count"] == 1
    r1 = doc["regions"][1]
    assert r1["ar_coefficients"] == [1.61, -0.73] and r1["vertex_count"] == 1
    # Masonite's AR(2) process std: 0.16 * sqrt(15.99) = 0.6397 N (docs/texture-model.md).
    assert abs(r1["roughness_std_n"] - 0.6397) < 1e-3


def test_ply_round_trip(tmp_path):
    path = tmp_path / "map.ply"
    te.write_texture_file(_response(), str(path))
    lines = path.read_text().splitlines()
    end = lines.index("end_header")
    props = [ln.split()[-1] for ln in lines[:end] if ln.startswith("property") and "list" not in ln]
    assert props == ["x", "y", "z", "nx", "ny", "nz", "mu", "mu_std", "sigma", "a1", "a2", "k1", "k2", "region",
                     "boundary_probability"]
    rows = [ln.split() for ln in lines[end + 1:end + 5]]
    col = {name: i for i, name in enumerate(props)}
    assert float(rows[1][col["mu"]]) == 0.5 and rows[3][col["mu"]] == "nan"
    assert float(rows[1][col["k1"]]) == 1.61 / 1.73
    assert int(rows[3][col["region"]]) == -1
    assert lines[end + 5:] == ["3 0 1 3", "3 0 3 2"]
    assert "comment grid_step_mm 0.05" in lines
