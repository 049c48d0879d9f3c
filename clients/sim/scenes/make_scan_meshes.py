#!/usr/bin/env python3
"""Writes the scan-like held-out scenes' meshes (scan_pebble_m.obj, scan_vase_m.obj,
scan_stone_m.obj, scan_dome_m.obj,
scan_handle_m.obj).

Meshes of the kind a scanner hands a lab: dense (thousands of vertices, far
denser than the job's site spacing, so the server simplifies them to a control
mesh of its own), irregular, with smooth bumps and 0.05 mm noise, written in
metres; the stone is denser (10,242 vertices, ~1.5 mm apart) with 0.1 mm
noise, the kind whose fine map level, moved onto the scan, folds into
slivers. Seeded, so the committed files are this script's output:

    python3 clients/sim/scenes/make_scan_meshes.py clients/sim/scenes

(needs python3-numpy).
"""
import sys

import numpy as np


def icosphere(subdivisions):
    t = (1 + 5 ** 0.5) / 2
    vertices = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
                (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    vertices = [np.array(v, float) / np.linalg.norm(v) for v in vertices]
    for _ in range(subdivisions):
        midpoints, finer = {}, []

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoints:
                m = vertices[a] + vertices[b]
                vertices.append(m / np.linalg.norm(m))
                midpoints[key] = len(vertices) - 1
            return midpoints[key]

        for a, b, c in faces:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            finer += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = finer
    return vertices, faces


def ring_by_angle(vertices, ids, scale=(1.0, 1.0)):
    """A ring's vertex ids in order of angle round the z axis (of x / scale[0],
    y / scale[1]: an ellipse's rings), and those angles in [0, 2 pi)."""
    angles = np.mod(np.arctan2(vertices[ids, 1] / scale[1], vertices[ids, 0] / scale[0]), 2 * np.pi)
    order = np.argsort(angles)
    return [ids[k] for k in order], angles[order]


def zip_rings(lower, angle_lower, upper, angle_upper):
    """Triangles between two rings ordered by angle (any counts): each step
    advances the ring whose next vertex comes first."""
    nl, nu = len(lower), len(upper)
    faces = []
    a = b = 0
    while a < nl or b < nu:
        next_lower = angle_lower[(a + 1) % nl] + (2 * np.pi if a + 1 >= nl else 0)
        next_upper = angle_upper[(b + 1) % nu] + (2 * np.pi if b + 1 >= nu else 0)
        if b >= nu or (a < nl and next_lower < next_upper):
            faces.append((lower[a % nl], lower[(a + 1) % nl], upper[b % nu]))
            a += 1
        else:
            faces.append((lower[a % nl], upper[(b + 1) % nu], upper[b % nu]))
            b += 1
    return faces


def orient_outward(vertices, faces, centre):
    """Each face counter-clockwise seen from outside: its normal away from
    `centre`, a point inside the object."""
    outward = []
    for a, b, c in faces:
        normal = np.cross(vertices[b] - vertices[a], vertices[c] - vertices[a])
        away = (vertices[a] + vertices[b] + vertices[c]) / 3 - np.asarray(centre, float)
        outward.append((a, b, c) if normal @ away > 0 else (a, c, b))
    return outward


def pebble():
    """An ellipsoid 124 x 88 x 72 mm with bumps: an icosphere subdivided 4 times
    (2,562 vertices), turned off the axes first so no vertex sits on one."""
    directions, faces = icosphere(4)
    rng = np.random.default_rng(7)
    radii = np.array([62.0, 44.0, 36.0])
    angle, axis = 0.61, np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    turn = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
    vertices = []
    for u in directions:
        u = turn @ u
        bump = 1.8 * (np.sin(3 * u[0] + 1) * np.cos(2 * u[1]) + 0.5 * np.sin(4 * u[2] + 2 * u[0]))
        vertices.append(u * radii + u * (bump + rng.normal(0, 0.05)))
    return np.array(vertices), faces


def stone():
    """A flat river stone 140 x 100 x 56 mm (strongly curved round its rim):
    an icosphere subdivided 5 times (10,242 vertices), turned off the axes,
    with bumps and 0.1 mm noise."""
    directions, faces = icosphere(5)
    rng = np.random.default_rng(23)
    radii = np.array([70.0, 50.0, 28.0])
    angle, axis = 0.37, np.array([-0.6, 0.2, 0.77]) / np.linalg.norm([-0.6, 0.2, 0.77])
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    turn = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
    vertices = []
    for u in directions:
        u = turn @ u
        bump = 1.2 * (np.sin(4 * u[0] + 2) * np.cos(3 * u[1]) + 0.6 * np.sin(5 * u[2] - u[1]))
        vertices.append(u * radii + u * (bump + rng.normal(0, 0.1)))
    return np.array(vertices), faces


def revolution(profile, rings, around, rng, bump):
    """A closed body of revolution about z from a (radius, z) profile that
    starts and ends on the axis: `rings` stations at jittered arc lengths
    along it (the two ends are the poles), `around` vertices on each ring
    from a random start angle, the radius moved by bump(angle, z) and 0.05 mm
    noise; rings joined by angle, faces oriented outwards."""
    length = np.r_[0, np.cumsum(np.linalg.norm(np.diff(profile, axis=0), axis=1))]
    s = np.linspace(0, length[-1], rings)
    s[1:-1] += rng.uniform(-0.3, 0.3, rings - 2) * (length[-1] / rings)
    r, z = np.interp(s, length, profile[:, 0]), np.interp(s, length, profile[:, 1])
    vertices = [(0, 0, 0)]
    for i in range(1, rings - 1):
        start = rng.uniform(0, 2 * np.pi)
        for j in range(around):
            a = start + 2 * np.pi * j / around
            radius = r[i] + bump(a, z[i]) + rng.normal(0, 0.05)
            vertices.append((radius * np.cos(a), radius * np.sin(a), z[i] + rng.normal(0, 0.05)))
    vertices.append((0, 0, z[-1]))
    vertices = np.array(vertices)

    def ring(i):
        return list(range(1 + (i - 1) * around, 1 + i * around))

    faces = [(0, ring(1)[(j + 1) % around], ring(1)[j]) for j in range(around)]
    for i in range(1, rings - 2):
        faces += zip_rings(*ring_by_angle(vertices, ring(i)), *ring_by_angle(vertices, ring(i + 1)))
    top, last = len(vertices) - 1, ring(rings - 2)
    faces += [(top, last[j], last[(j + 1) % around]) for j in range(around)]
    return vertices, orient_outward(vertices, faces, (0, 0, z[-1] / 2))  # from a point on the axis


def vase():
    """A vase of revolution 150 mm tall, radius 30-45 mm: 56 rings at jittered
    heights, 60 vertices each at a random start angle (3,362 vertices), joined
    ring to ring by angle, with bumps and noise."""
    profile = np.array([(0, 0), (30, 0), (38, 8), (44, 30), (45, 55), (41, 80), (34, 105), (30, 125), (32, 140),
                        (34, 150), (0, 150)], float)
    return revolution(profile, 58, 60, np.random.default_rng(11),
                      lambda a, z: 1.2 * np.sin(3 * a + z / 20) * np.cos(z / 35))


def handle():
    """A tool handle 130 mm long, radius 13-20 mm (strongly curved all round:
    a 20 mm drag round it turns ~60 degrees), rounded at both ends: 66 rings
    at jittered heights, 52 vertices each at a random start angle (3,434
    vertices), with 0.05 mm noise, its axis turned 50 degrees off z (a scan
    arrives in the scanner's frame, not the object's)."""
    profile = np.array([(0, 0), (9, 0.8), (15, 3), (18, 7), (19, 14), (19, 30), (20, 45), (20.5, 65), (20, 85),
                        (19, 100), (16, 110), (13.5, 122), (11, 128), (6, 130), (0, 130)], float)
    vertices, faces = revolution(profile, 68, 52, np.random.default_rng(31),
                                 lambda a, z: 0.3 * np.sin(2 * a + z / 15))
    # Centre the handle on the origin, then turn its axis 50 degrees about y.
    c, s = np.cos(np.radians(50)), np.sin(np.radians(50))
    turn = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return (vertices - (0, 0, 65)) @ turn.T, faces


def dome():
    """An open scan of a dome resting on a table (the scanner never saw its
    underside, so the mesh has a boundary round its base): a half-ellipsoid
    130 x 100 mm across and 55 mm tall, 40 rings of latitude at jittered
    angles with as many vertices as keep them ~2.2 mm apart (4,305 vertices),
    each ring from a random start, with bumps and 0.05 mm noise."""
    rng = np.random.default_rng(31)
    radii = np.array((65.0, 50.0, 55.0))
    rings = 40
    polar = np.linspace(0, np.pi / 2, rings + 1)[1:]
    polar[:-1] += rng.uniform(-0.25, 0.25, rings - 1) * (np.pi / 2 / rings)
    vertices = [np.array((0.0, 0.0, radii[2]))]
    ring_ids = []
    for t in polar:
        n = max(6, int(round(2 * np.pi * 58 * np.sin(t) / 2.2)))
        start = rng.uniform(0, 2 * np.pi)
        ids = []
        for j in range(n):
            p = start + 2 * np.pi * j / n
            u = np.array((np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)))
            bump = 1.0 * np.sin(3 * p + 4 * t) * np.sin(2 * t)
            q = u * radii + u * (bump + rng.normal(0, 0.05))
            if t == polar[-1]:
                q[2] = rng.normal(0, 0.05)  # the base ring, where the table cut the scan
            vertices.append(q)
            ids.append(len(vertices) - 1)
        ring_ids.append(ids)
    vertices = np.array(vertices)

    first, _ = ring_by_angle(vertices, ring_ids[0], radii[:2])
    faces = [(0, first[j], first[(j + 1) % len(first)]) for j in range(len(first))]
    for i in range(rings - 1):
        # The upper ring started at its vertex nearest the lower one's first,
        # its angles carried on past 2 pi (rings of different counts).
        lower, angle_lower = ring_by_angle(vertices, ring_ids[i], radii[:2])
        upper, angle_upper = ring_by_angle(vertices, ring_ids[i + 1], radii[:2])
        s = int(np.argmin(np.abs(np.angle(np.exp(1j * (angle_upper - angle_lower[0]))))))
        upper = upper[s:] + upper[:s]
        angle_upper = np.r_[angle_upper[s:], angle_upper[:s] + 2 * np.pi]
        if angle_upper[0] > angle_lower[0] + np.pi:
            angle_upper = angle_upper - 2 * np.pi
        faces += zip_rings(lower, angle_lower, upper, angle_upper)
    return vertices, orient_outward(vertices, faces, (0, 0, 0))  # from the centre of the base


def write_obj(path, title, vertices, faces):
    with open(path, "w") as out:
        out.write(f"# {title}: written by make_scan_meshes.py; units m\n")
        for p in vertices:
            out.write("v %.7f %.7f %.7f\n" % tuple(np.asarray(p) / 1000))
        for a, b, c in faces:
            out.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))
    print(f"{path}: {len(vertices)} vertices, {len(faces)} triangles")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: make_scan_meshes.py OUTPUT_DIR")
    write_obj(f"{sys.argv[1]}/scan_pebble_m.obj", "scan-like pebble", *pebble())
    write_obj(f"{sys.argv[1]}/scan_vase_m.obj", "scan-like vase", *vase())
    write_obj(f"{sys.argv[1]}/scan_stone_m.obj", "scan-like river stone", *stone())
    write_obj(f"{sys.argv[1]}/scan_dome_m.obj", "scan-like dome, open at its base", *dome())
    write_obj(f"{sys.argv[1]}/scan_handle_m.obj", "scan-like tool handle, its axis off z", *handle())
