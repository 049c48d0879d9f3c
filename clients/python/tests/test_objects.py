"""Objects: upload (OBJ path, PLY bytes), list, get, mesh, errors."""

from __future__ import annotations

import grpc
import numpy as np
import pytest

import surfmap_client as sc


def obj_to_ascii_ply(obj_text: str) -> bytes:
    """The same control mesh as an ASCII PLY (v and f lines only; faces may be polygons)."""
    vertices, faces = [], []
    for line in obj_text.splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            vertices.append(parts[1:4])
        elif parts[0] == "f":
            faces.append([int(p.split("/")[0]) - 1 for p in parts[1:]])
    lines = ["ply", "format ascii 1.0", f"element vertex {len(vertices)}", "property float x", "property float y",
             "property float z", f"element face {len(faces)}", "property list uchar int vertex_indices",
             "end_header"]
    lines += [" ".join(v) for v in vertices]
    lines += [" ".join([str(len(f))] + [str(i) for i in f]) for f in faces]
    return ("\n".join(lines) + "\n").encode("ascii")


def test_upload_path_and_ply_bytes_give_the_same_mesh(client, lab):
    from_obj = client.upload_object(lab.mesh(), name="plate-obj")
    assert from_obj.object_id > 0
    assert from_obj.name == "plate-obj"
    assert from_obj.format == "obj"
    assert from_obj.created is not None
    # plate.obj: 160 triangles (clients/sim/scenes/README.md)
    assert from_obj.control_face_count == 160

    ply = obj_to_ascii_ply(lab.mesh().read_text())
    from_ply = client.upload_object(ply, name="plate-ply")
    assert from_ply.format == "ply"
    assert from_ply.object_id != from_obj.object_id
    assert from_ply.control_vertex_count == from_obj.control_vertex_count
    assert from_ply.control_face_count == from_obj.control_face_count

    listed = {o.object_id: o for o in client.list_objects()}
    assert listed[from_obj.object_id].name == "plate-obj"
    assert listed[from_ply.object_id].name == "plate-ply"
    assert client.get_object(from_ply.object_id) == from_ply


CAD_BOX_TRIANGLES = ((0, 2, 3), (0, 3, 1), (4, 5, 7), (4, 7, 6), (0, 1, 5), (0, 5, 4),
                     (2, 6, 7), (2, 7, 3), (0, 4, 6), (0, 6, 2), (1, 3, 7), (1, 7, 5))
CAD_BOX_OBJ = ("".join(f"v {x} {y} {z}\n" for z in (-0.05, 0.05) for y in (-0.05, 0.05) for x in (-0.05, 0.05))
               + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in CAD_BOX_TRIANGLES))


def test_a_cad_box_uploaded_as_facets_is_served_on_its_faces(client):
    """A 100 mm box of 12 triangles, in metres: as facets its served surface is the box; as a control mesh a blob."""
    box = client.upload_object(CAD_BOX_OBJ.encode(), name="cad-box", format="obj", units="m", facets=True)
    assert box.surface == "facets"
    assert client.get_object(box.object_id).surface == "facets"
    off = np.abs(np.abs(client.get_mesh(box.object_id, 2).positions).max(axis=1) - 50.0)
    assert off.max() < 1e-6
    blob = client.upload_object(CAD_BOX_OBJ.encode(), name="cad-blob", format="obj", units="m")
    assert blob.surface == "control_mesh"
    off = np.abs(np.abs(client.get_mesh(blob.object_id, 2).positions).max(axis=1) - 50.0)
    assert off.max() > 10.0


def test_name_defaults_to_the_file_stem(client, lab):
    assert client.upload_object(lab.mesh()).name == "plate"


def test_mesh_levels(client, lab):
    obj = client.upload_object(lab.mesh())
    level0 = client.get_mesh(obj.object_id, 0)
    assert level0.positions.shape == (obj.control_vertex_count, 3)
    assert level0.normals.shape == level0.positions.shape
    assert level0.triangles.shape == (obj.control_face_count, 3)
    np.testing.assert_allclose(np.linalg.norm(level0.normals, axis=1), 1.0, atol=1e-9)
    level1 = client.get_mesh(obj.object_id, 1)
    # Loop subdivision splits every triangle in four.
    assert level1.triangles.shape == (4 * obj.control_face_count, 3)
    assert level1.triangles.max() < len(level1.positions)
    # The plate lies in z = 0, so every limit position does too.
    np.testing.assert_allclose(level1.positions[:, 2], 0.0, atol=1e-9)


def test_unknown_object_is_not_found(client):
    for call in (lambda: client.get_object(987654), lambda: client.get_mesh(987654, 0),
                 lambda: client.create_job(987654)):
        with pytest.raises(sc.SurfmapError) as caught:
            call()
        assert caught.value.code == grpc.StatusCode.NOT_FOUND
        assert "987654" in caught.value.message


def test_bad_mesh_is_invalid_argument_with_the_server_message(client):
    with pytest.raises(sc.SurfmapError) as caught:
        client.upload_object(b"this is not a mesh\n", name="junk", format="obj")
    assert caught.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert caught.value.method == "UploadObject"
    assert caught.value.message  # the server says what is wrong


def test_local_argument_errors_are_surfmap_errors(client, tmp_path):
    with pytest.raises(sc.SurfmapError) as caught:
        client.upload_object(tmp_path / "missing.obj")
    assert caught.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert "missing.obj" in caught.value.message
    with pytest.raises(sc.SurfmapError) as caught:
        client.upload_object(b"v 0 0 0\n", format="3mf")
    assert "3mf" in caught.value.message
    with pytest.raises(sc.SurfmapError) as caught:
        client.upload_object(b"v 0 0 0\n", units="furlong")
    assert "furlong" in caught.value.message
