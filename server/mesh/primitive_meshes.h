// Control meshes built in code: test solids and the simulated rig's scenes.
// All are valid for ValidateControlMesh (closed ones wound counter-clockwise
// seen from outside), in mm.
#pragma once

#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "server/mesh/control_mesh.h"

namespace surfmap {

// Platonic solids centred on the origin with their vertices at `radius`.
ControlMesh MakeTetrahedron(double radius);   // 4 vertices, 4 faces
ControlMesh MakeOctahedron(double radius);    // 6 vertices, 8 faces
ControlMesh MakeIcosahedron(double radius);   // 12 vertices, 20 faces
// A box from -half to +half on each axis as a CAD program exports it: its 8
// corners, two triangles per face (12), outward winding.
ControlMesh MakeCadBox(double half);

// An icosahedron whose faces are split `subdivisions` times (0..6) into four,
// new vertices pushed out to the sphere: 20 * 4^s faces.
absl::StatusOr<ControlMesh> MakeIcosphere(double radius, int subdivisions);

// An open flat plate in z = 0 spanning [-w/2, w/2] x [-h/2, h/2], normal +z,
// nx x ny quads each split into two triangles, the diagonals chosen so that
// each corner vertex has one face (then the Loop limit keeps the corners; a
// 1 x 1 plate keeps two). Errors: non-positive sizes, nx or ny < 1.
absl::StatusOr<ControlMesh> MakeGridPlate(double width_mm, double height_mm, int nx, int ny);

// A closed surface of revolution about +z. `profile` is (radius, z) from the
// bottom pole to the top pole: first and last points have radius 0 and become
// single vertices with triangle fans, the others become rings of `segments`
// vertices. Errors: fewer than 3 profile points, poles off the axis,
// non-positive interior radii, segments < 3, non-finite values.
absl::StatusOr<ControlMesh> MakeSurfaceOfRevolution(const std::vector<Eigen::Vector2d>& profile, int segments);

// A closed cylinder of `radius` from z = 0 to z = height with flat caps
// (ring vertices at each of rings + 1 heights, a centre vertex per cap).
// 2 * segments * (rings + 1) faces.
absl::StatusOr<ControlMesh> MakeCylinder(double radius_mm, double height_mm, int segments, int rings);

// A closed bottle standing on z = 0: flat base with a rounded heel, straight
// body, a smooth shoulder, a straight neck, closed flat top. The control
// rings are widened so that the Loop limit surface, which shrinks a polygon
// ring by (4 + 2 cos(2 pi / segments)) / 6, has about `body_radius_mm` on the
// body. Defaults: 12 segments, 15 rings, 360 faces, 182 vertices.
struct BottleShape {
  double body_radius_mm = 40.0;
  double height_mm = 200.0;
  double body_top_mm = 130.0;    // where the shoulder starts
  double neck_radius_mm = 14.0;
  double neck_length_mm = 30.0;  // the neck ends at height_mm
  int segments = 12;
  double max_ring_spacing_mm = 30.0;  // between the body's rings, heel to shoulder
  // One ring at the base, two on the shoulder, the neck's two ends only: the
  // fewest control vertices that keep the shape (a coarse level 0 to sample).
  bool minimal_rings = false;
};
absl::StatusOr<ControlMesh> MakeBottle(const BottleShape& shape = {});

}  // namespace surfmap
