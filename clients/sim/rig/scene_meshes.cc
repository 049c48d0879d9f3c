#include "clients/sim/rig/scene_meshes.h"

#include <cmath>
#include <numbers>
#include <string>

#include <Eigen/Geometry>
#include "absl/strings/str_cat.h"
#include "server/mesh/primitive_meshes.h"

namespace surfmap {
namespace {

// A turn that puts no icosphere vertex on a world axis or plane of symmetry,
// as a scan's remesher would not.
Eigen::Matrix3d OffAxisTurn() {
  return Eigen::AngleAxisd(0.47, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
}

// An icosphere (subdivided twice: 162 vertices) pushed out along each
// vertex's direction onto the surface `radius_along(direction)` gives.
template <typename RadiusFn>
absl::StatusOr<ControlMesh> StarShapedMesh(const RadiusFn& radius_along) {
  absl::StatusOr<ControlMesh> sphere = MakeIcosphere(1.0, 2);
  if (!sphere.ok()) return sphere.status();
  const Eigen::Matrix3d turn = OffAxisTurn();
  for (Eigen::Vector3d& p : sphere->positions) {
    const Eigen::Vector3d d = (turn * p).normalized();
    p = radius_along(d) * d;
  }
  return sphere;
}

absl::StatusOr<ControlMesh> BandedVase() {
  // (radius, z) from the bottom pole to the top pole; the rings' heights are
  // uneven, as a remesher leaves them.
  const std::vector<Eigen::Vector2d> profile = {
      {0, 0},   {27, 0},   {37, 6},   {44, 25},  {47, 47},  {45, 66},
      {42, 92}, {35, 114}, {30, 133}, {29, 148}, {31, 160}, {0, 160}};
  return MakeSurfaceOfRevolution(profile, 11);
}

absl::StatusOr<ControlMesh> StripBlock() {
  return StarShapedMesh([](const Eigen::Vector3d& d) {
    const double s = std::pow(d.x() / 70.0, 4) + std::pow(d.y() / 45.0, 4) + std::pow(d.z() / 30.0, 4);
    return std::pow(s, -0.25);
  });
}

absl::StatusOr<ControlMesh> DottedEgg() {
  return StarShapedMesh([](const Eigen::Vector3d& d) {
    const double s = std::pow(d.x() / 46.0, 2) + std::pow(d.y() / 40.0, 2) + std::pow(d.z() / 60.0, 2);
    return 1.0 / std::sqrt(s);
  });
}

// A torus about z: `around` vertices along the major circle, `tube` around
// the tube, both rings started at odd angles. The control tube radius is set
// so that the Loop limit's tube is about `tube_radius` (a ring of n vertices
// shrinks by (4 + 2 cos(2 pi / n)) / 6 in the limit).
ControlMesh Torus(double major_radius, double tube_radius, int around, int tube) {
  const double shrink = (4.0 + 2.0 * std::cos(2.0 * std::numbers::pi / tube)) / 6.0;
  const double r = tube_radius / shrink;
  ControlMesh mesh;
  for (int i = 0; i < around; ++i) {
    const double phi = 2.0 * std::numbers::pi * (i + 0.31) / around;
    for (int j = 0; j < tube; ++j) {
      const double theta = 2.0 * std::numbers::pi * (j + 0.17) / tube;
      const double rho = major_radius + r * std::cos(theta);
      mesh.positions.emplace_back(rho * std::cos(phi), rho * std::sin(phi), r * std::sin(theta));
    }
  }
  auto index = [&](int i, int j) { return ((i + around) % around) * tube + (j + tube) % tube; };
  for (int i = 0; i < around; ++i) {
    for (int j = 0; j < tube; ++j) {
      // Counter-clockwise seen from outside: (i, j) -> (i+1, j) -> (i+1, j+1).
      mesh.triangles.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      mesh.triangles.push_back({index(i, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  }
  return mesh;
}

}  // namespace

std::vector<std::string_view> BuiltInSceneMeshNames() {
  return {"bottle", "plate", "banded_vase", "strip_block", "dotted_egg", "torus_handle"};
}

absl::StatusOr<ControlMesh> MakeBuiltInSceneMesh(std::string_view name) {
  // The bottle's level 0 is as coarse as keeps the shape, with body rings
  // spaced so that each sandpaper patch holds a control vertex: the planner
  // starts from 82 sites and refines only at the patches' edges.
  if (name == "bottle") {
    return MakeBottle(BottleShape{.segments = 8, .max_ring_spacing_mm = 32.0, .minimal_rings = true});
  }
  if (name == "plate") return MakeGridPlate(200.0, 150.0, 10, 8);
  if (name == "banded_vase") return BandedVase();
  if (name == "strip_block") return StripBlock();
  if (name == "dotted_egg") return DottedEgg();
  if (name == "torus_handle") return Torus(45.0, 15.0, 18, 9);
  return absl::NotFoundError(absl::StrCat("no built-in scene mesh '", std::string(name),
                                          "' (bottle, plate, banded_vase, strip_block, dotted_egg, torus_handle)"));
}

}  // namespace surfmap
