#include "server/mesh/primitive_meshes.h"

#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include "absl/strings/str_format.h"

namespace surfmap {
namespace {

ControlMesh Scaled(ControlMesh mesh, double radius) {
  for (Eigen::Vector3d& p : mesh.positions) p = radius * p.normalized();
  return mesh;
}

}  // namespace

ControlMesh MakeTetrahedron(double radius) {
  ControlMesh mesh;
  mesh.positions = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  mesh.triangles = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  return Scaled(std::move(mesh), radius);
}

ControlMesh MakeOctahedron(double radius) {
  ControlMesh mesh;
  mesh.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  mesh.triangles = {{4, 0, 2}, {4, 2, 1}, {4, 1, 3}, {4, 3, 0}, {5, 2, 0}, {5, 1, 2}, {5, 3, 1}, {5, 0, 3}};
  return Scaled(std::move(mesh), radius);
}

ControlMesh MakeCadBox(double half) {
  ControlMesh mesh;
  for (int i = 0; i < 8; ++i) {
    mesh.positions.emplace_back(i & 1 ? half : -half, i & 2 ? half : -half, i & 4 ? half : -half);
  }
  mesh.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                    {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return mesh;
}

ControlMesh MakeIcosahedron(double radius) {
  const double g = std::numbers::phi;
  ControlMesh mesh;
  mesh.positions = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                    {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  mesh.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                    {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  return Scaled(std::move(mesh), radius);
}

absl::StatusOr<ControlMesh> MakeIcosphere(double radius, int subdivisions) {
  if (subdivisions < 0 || subdivisions > 6) {
    return absl::InvalidArgumentError(absl::StrFormat("icosphere subdivisions %d out of range 0..6", subdivisions));
  }
  if (!(radius > 0) || !std::isfinite(radius)) {
    return absl::InvalidArgumentError(absl::StrFormat("icosphere radius %g must be positive", radius));
  }
  ControlMesh mesh = MakeIcosahedron(1.0);
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> midpoint;
    auto split = [&](int a, int b) {
      const std::pair<int, int> key(std::min(a, b), std::max(a, b));
      auto [it, inserted] = midpoint.try_emplace(key, static_cast<int>(mesh.positions.size()));
      if (inserted) mesh.positions.push_back((mesh.positions[a] + mesh.positions[b]).normalized());
      return it->second;
    };
    std::vector<std::array<int, 3>> finer;
    finer.reserve(mesh.triangles.size() * 4);
    for (const auto& t : mesh.triangles) {
      const int ab = split(t[0], t[1]);
      const int bc = split(t[1], t[2]);
      const int ca = split(t[2], t[0]);
      finer.push_back({t[0], ab, ca});
      finer.push_back({t[1], bc, ab});
      finer.push_back({t[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    mesh.triangles = std::move(finer);
  }
  return Scaled(std::move(mesh), radius);
}

absl::StatusOr<ControlMesh> MakeGridPlate(double width_mm, double height_mm, int nx, int ny) {
  if (!(width_mm > 0) || !(height_mm > 0) || !std::isfinite(width_mm) || !std::isfinite(height_mm)) {
    return absl::InvalidArgumentError(absl::StrFormat("plate size %g x %g mm must be positive", width_mm, height_mm));
  }
  if (nx < 1 || ny < 1 || nx > 4096 || ny > 4096) {
    return absl::InvalidArgumentError(absl::StrFormat("plate grid %d x %d must be 1..4096 per side", nx, ny));
  }
  ControlMesh mesh;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      mesh.positions.emplace_back(width_mm * (2 * i - nx) / (2.0 * nx), height_mm * (2 * j - ny) / (2.0 * ny), 0.0);
    }
  }
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      // Diagonals mirrored about the plate's centre lines, so each corner
      // vertex has a single face: with EDGE_AND_CORNER boundary rules only
      // such vertices stay put, and the limit surface keeps the corners.
      // Counter-clockwise seen from +z.
      const bool left = 2 * i + 1 < nx;
      const bool bottom = 2 * j + 1 < ny;
      if (left == bottom) {
        mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
        mesh.triangles.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  }
  return mesh;
}

absl::StatusOr<ControlMesh> MakeSurfaceOfRevolution(const std::vector<Eigen::Vector2d>& profile, int segments) {
  if (profile.size() < 3) {
    return absl::InvalidArgumentError(
        absl::StrFormat("a profile needs at least 3 points (two poles and a ring), got %d", profile.size()));
  }
  if (segments < 3 || segments > 4096) {
    return absl::InvalidArgumentError(absl::StrFormat("segments %d must be 3..4096", segments));
  }
  for (std::size_t i = 0; i < profile.size(); ++i) {
    if (!profile[i].allFinite()) return absl::InvalidArgumentError(absl::StrFormat("profile point %d is not finite", i));
    const bool pole = i == 0 || i + 1 == profile.size();
    if (pole && profile[i].x() != 0.0) {
      return absl::InvalidArgumentError(absl::StrFormat("profile point %d is a pole but has radius %g, not 0", i,
                                                        profile[i].x()));
    }
    if (!pole && !(profile[i].x() > 0.0)) {
      return absl::InvalidArgumentError(absl::StrFormat("profile point %d has radius %g; ring radii must be positive",
                                                        i, profile[i].x()));
    }
  }
  const int rings = static_cast<int>(profile.size()) - 2;
  ControlMesh mesh;
  mesh.positions.emplace_back(0.0, 0.0, profile.front().y());  // bottom pole: vertex 0
  for (int r = 0; r < rings; ++r) {
    const Eigen::Vector2d& p = profile[r + 1];
    for (int s = 0; s < segments; ++s) {
      const double angle = 2.0 * std::numbers::pi * s / segments;
      mesh.positions.emplace_back(p.x() * std::cos(angle), p.x() * std::sin(angle), p.y());
    }
  }
  const int top = static_cast<int>(mesh.positions.size());
  mesh.positions.emplace_back(0.0, 0.0, profile.back().y());
  auto ring = [&](int r, int s) { return 1 + r * segments + (s % segments); };
  // Outward = away from the axis for a profile that goes up; bottom fan seen
  // from below, top fan seen from above.
  for (int s = 0; s < segments; ++s) mesh.triangles.push_back({0, ring(0, s + 1), ring(0, s)});
  for (int r = 0; r + 1 < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      mesh.triangles.push_back({ring(r, s), ring(r, s + 1), ring(r + 1, s + 1)});
      mesh.triangles.push_back({ring(r, s), ring(r + 1, s + 1), ring(r + 1, s)});
    }
  }
  for (int s = 0; s < segments; ++s) mesh.triangles.push_back({top, ring(rings - 1, s), ring(rings - 1, s + 1)});
  return mesh;
}

absl::StatusOr<ControlMesh> MakeCylinder(double radius_mm, double height_mm, int segments, int rings) {
  if (!(radius_mm > 0) || !(height_mm > 0) || !std::isfinite(radius_mm) || !std::isfinite(height_mm)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("cylinder radius %g and height %g mm must be positive", radius_mm, height_mm));
  }
  if (rings < 1 || rings > 4096) return absl::InvalidArgumentError(absl::StrFormat("rings %d must be 1..4096", rings));
  std::vector<Eigen::Vector2d> profile = {{0.0, 0.0}};
  for (int r = 0; r <= rings; ++r) profile.emplace_back(radius_mm, height_mm * r / rings);
  profile.emplace_back(0.0, height_mm);
  return MakeSurfaceOfRevolution(profile, segments);
}

absl::StatusOr<ControlMesh> MakeBottle(const BottleShape& shape) {
  const double radius = shape.body_radius_mm;
  const double height = shape.height_mm;
  const double neck_radius = shape.neck_radius_mm;
  const double neck_start = height - shape.neck_length_mm;
  const double heel = 0.1 * radius;
  if (!(radius > 0) || !(neck_radius > 0) || !(neck_radius < radius) || !(heel < shape.body_top_mm) ||
      !(shape.body_top_mm < neck_start) || !(neck_start < height) || !std::isfinite(height)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "bottle shape must satisfy 0 < neck radius (%g) < body radius (%g) and 0 < %g < body top (%g) < neck "
        "start (%g) < height (%g) mm",
        neck_radius, radius, heel, shape.body_top_mm, neck_start, height));
  }
  if (!(shape.max_ring_spacing_mm > 0)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("bottle ring spacing %g mm must be positive", shape.max_ring_spacing_mm));
  }
  if (shape.segments < 3 || shape.segments > 4096) {
    return absl::InvalidArgumentError(absl::StrFormat("bottle segments %d must be 3..4096", shape.segments));
  }
  // Undo the Loop limit's shrinkage of a regular polygon ring.
  const double widen = 6.0 / (4.0 + 2.0 * std::cos(2.0 * std::numbers::pi / shape.segments));
  std::vector<Eigen::Vector2d> profile;
  auto add = [&](double r, double z) { profile.emplace_back(r * widen, z); };
  profile.emplace_back(0.0, 0.0);
  if (!shape.minimal_rings) add(0.5 * radius, 0.0);
  add(0.9 * radius, 0.0);
  // Body: rings at most max_ring_spacing_mm apart from the heel to the shoulder.
  const int body_intervals =
      std::max(1, static_cast<int>(std::ceil((shape.body_top_mm - heel) / shape.max_ring_spacing_mm)));
  for (int i = 0; i <= body_intervals; ++i) add(radius, heel + (shape.body_top_mm - heel) * i / body_intervals);
  // Shoulder: a cosine blend from the body radius down to the neck.
  const std::vector<double> shoulder =
      shape.minimal_rings ? std::vector<double>{1.0 / 3.0, 2.0 / 3.0} : std::vector<double>{0.25, 0.5, 0.75};
  for (double t : shoulder) {
    add(neck_radius + (radius - neck_radius) * 0.5 * (1.0 + std::cos(std::numbers::pi * t)),
        shape.body_top_mm + (neck_start - shape.body_top_mm) * t);
  }
  add(neck_radius, neck_start);
  if (!shape.minimal_rings) add(neck_radius, 0.5 * (neck_start + height));
  add(neck_radius, height);
  if (!shape.minimal_rings) add(0.5 * neck_radius, height);
  profile.emplace_back(0.0, height);
  return MakeSurfaceOfRevolution(profile, shape.segments);
}

}  // namespace surfmap
