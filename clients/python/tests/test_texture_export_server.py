"""export_map against the REAL server: a completed job's map written as GLB,
glTF, PLY and the texture-model JSON, parsed back and compared with the map
the server answers (GetMap) for the same job."""

from __future__ import annotations

import json
import struct

import numpy as np
import pytest


def _glb_chunks(path):
    data = path.read_bytes()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    assert magic == b"glTF" and version == 2 and length == len(data)
    json_len, json_type = struct.unpack_from("<I4s", data, 12)
    assert json_type == b"JSON"
    doc = json.loads(data[20:20 + json_len])
    bin_at = 20 + json_len
    bin_len, bin_type = struct.unpack_from("<I4s", data, bin_at)
    assert bin_type == b"BIN\x00"
    return doc, data[bin_at + 8:bin_at + 8 + bin_len]


def _attribute(doc, blob, name):
    accessor = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"][name]]
    view = doc["bufferViews"][accessor["bufferView"]]
    width = {"SCALAR": 1, "VEC3": 3}[accessor["type"]]
    values = np.frombuffer(blob, dtype=np.float32, count=accessor["count"] * width,
                           offset=view["byteOffset"] + accessor.get("byteOffset", 0))
    return values.reshape(accessor["count"], width) if width > 1 else values


def test_glb_carries_the_served_map_vertex_for_vertex(client, completed_job, tmp_path):
    job_id = completed_job.job.job_id
    served = client.get_map(job_id)
    path = tmp_path / "plate.glb"
    assert client.export_map(job_id, str(path)) == "glb"
    doc, blob = _glb_chunks(path)
    positions = _attribute(doc, blob, "POSITION")
    assert positions.shape == (served.vertex_count, 3)
    # glTF is in metres; the map in millimetres.
    np.testing.assert_allclose(positions * 1000.0, served.positions, atol=1e-3)
    np.testing.assert_allclose(_attribute(doc, blob, "_MU"), served.mu, rtol=1e-6)
    np.testing.assert_allclose(_attribute(doc, blob, "_MU_STD"), served.mu_uncertainty, rtol=1e-5, atol=1e-7)
    np.testing.assert_array_equal(_attribute(doc, blob, "_REGION").astype(np.int64), served.region)


def test_texture_json_holds_every_served_region(client, completed_job, tmp_path):
    job_id = completed_job.job.job_id
    served = client.get_map(job_id)
    path = tmp_path / "plate.texture.json"
    assert client.export_map(job_id, str(path)) == "texture-json"
    model = json.loads(path.read_text())
    assert model["job_id"] == job_id and model["level"] == served.level
    assert model["vertex_count"] == served.vertex_count
    assert len(model["regions"]) == len(served.regions) >= 2  # the plate has three materials
    for exported, region in zip(model["regions"], served.regions):
        assert exported["mu"] == pytest.approx(region.mu)
        assert exported["ar_coefficients"] == pytest.approx(list(region.ar_coefficients))
        assert exported["vertex_count"] == int((served.region == region.region).sum())


def test_ply_and_gltf_name_the_same_vertices(client, completed_job, tmp_path):
    job_id = completed_job.job.job_id
    served = client.get_map(job_id)
    ply = tmp_path / "plate.ply"
    assert client.export_map(job_id, str(ply)) == "ply"
    lines = ply.read_text().splitlines()
    end = lines.index("end_header")
    header = lines[:end]
    assert f"element vertex {served.vertex_count}" in header
    names = [line.split()[-1] for line in header if line.startswith("property ") and "list" not in line]
    rows = np.array([[float(v) for v in line.split()] for line in lines[end + 1:end + 1 + served.vertex_count]])
    np.testing.assert_allclose(rows[:, names.index("mu")], served.mu, rtol=1e-6)
    gltf = tmp_path / "plate.gltf"
    assert client.export_map(job_id, str(gltf), format="gltf") == "gltf"
    assert json.loads(gltf.read_text())["asset"]["version"] == "2.0"
    with pytest.raises(ValueError, match="unknown texture export format"):
        client.export_map(job_id, str(tmp_path / "plate.xyz"))
