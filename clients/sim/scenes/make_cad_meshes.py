#!/usr/bin/env python3
"""Writes the CAD-export scenes' meshes (cad_case_m.obj).

Meshes of the kind a CAD package exports for a machined or moulded part: flat
faces meeting at sharp edges, each face tessellated as a grid of right
triangles about 6 mm across (finer than the job's site spacing, so the server
coarsens them), vertices shared along the edges, written in metres. The
scene's JSON says "surface": "facets": the facets are the object, not a
Loop control mesh. Deterministic, so the committed files are this script's
output:

    python3 clients/sim/scenes/make_cad_meshes.py clients/sim/scenes
"""
import math
import sys


def box_grid(size, cell):
    """A closed box [0, sx] x [0, sy] x [0, sz] centred on the origin, each face
    a grid of cells no larger than `cell`, outward-facing triangles."""
    counts = [max(1, math.ceil(s / cell)) for s in size]
    index = {}
    vertices = []

    def vertex(i, j, k):
        key = (i, j, k)
        if key not in index:
            index[key] = len(vertices)
            vertices.append(tuple(size[a] * (key[a] / counts[a]) - size[a] / 2 for a in range(3)))
        return index[key]

    faces = []
    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for side in (0, counts[axis]):
            for a in range(counts[u]):
                for b in range(counts[v]):
                    corner = []
                    for da, db in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        ijk = [0, 0, 0]
                        ijk[axis], ijk[u], ijk[v] = side, a + da, b + db
                        corner.append(vertex(*ijk))
                    # (u, v, axis) is right-handed: counter-clockwise in (u, v)
                    # faces +axis; the low side is wound the other way.
                    if side == 0:
                        corner = corner[::-1]
                    # Alternate the diagonal, as exporters do, so no direction is preferred.
                    if (a + b) % 2 == 0:
                        faces += [(corner[0], corner[1], corner[2]), (corner[0], corner[2], corner[3])]
                    else:
                        faces += [(corner[0], corner[1], corner[3]), (corner[1], corner[2], corner[3])]
    return vertices, faces


def write_obj(path, vertices, faces, comment):
    with open(path, "w") as out:
        out.write(f"# {comment}\n")
        for x, y, z in vertices:
            out.write(f"v {x / 1000:.6f} {y / 1000:.6f} {z / 1000:.6f}\n")
        for a, b, c in faces:
            out.write(f"f {a + 1} {b + 1} {c + 1}\n")


def main():
    directory = sys.argv[1] if len(sys.argv) > 1 else "."
    vertices, faces = box_grid((160.0, 100.0, 70.0), 6.0)
    write_obj(f"{directory}/cad_case_m.obj", vertices, faces,
              "cad_case_m: a 160 x 100 x 70 mm case as a CAD export, 6 mm facets, metres (make_cad_meshes.py)")


if __name__ == "__main__":
    main()
