// The topology and geometry checks behind ValidateControlMesh.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/mesh/parsed_mesh.h"

namespace surfmap {
namespace {

std::uint64_t EdgeKey(int a, int b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}

// Per undirected edge: the triangles using it and in which direction.
struct EdgeUse {
  int count = 0;
  int first_triangle = -1;
  int second_triangle = -1;
  bool first_forward = false;  // first triangle traverses low -> high
};

}  // namespace

void AppendFanTriangles(const std::vector<int>& input, const std::string& origin, ParsedMesh& out) {
  std::vector<int> polygon;
  polygon.reserve(input.size());
  for (const int v : input) {
    if (polygon.empty() || polygon.back() != v) polygon.push_back(v);
  }
  while (polygon.size() > 1 && polygon.back() == polygon.front()) polygon.pop_back();
  if (polygon.size() != input.size()) {
    if (out.polygons_with_repeated_vertex++ == 0) {
      out.first_repeated_vertex_polygon = origin;
      out.first_repeated_vertex_triangle = static_cast<int>(out.mesh.triangles.size());
      out.first_repeated_vertex_indices = input;
    }
    if (polygon.size() < 3) {
      ++out.polygons_dropped;
      return;
    }
  }
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
    out.mesh.triangles.push_back({polygon[0], polygon[i], polygon[i + 1]});
    out.triangle_origin.push_back(origin);
  }
}

absl::Status ValidateTriangleMesh(const ControlMesh& mesh,
                                  absl::FunctionRef<std::string(int)> describe_triangle) {
  const int num_vertices = static_cast<int>(mesh.positions.size());
  const int num_triangles = static_cast<int>(mesh.triangles.size());
  if (num_vertices == 0) return absl::InvalidArgumentError("empty mesh: no vertices");
  if (num_triangles == 0) return absl::InvalidArgumentError("empty mesh: no faces");

  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY);
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-INFINITY);
  for (int v = 0; v < num_vertices; ++v) {
    const Eigen::Vector3d& p = mesh.positions[v];
    if (!p.allFinite()) {
      return absl::InvalidArgumentError(
          absl::StrFormat("vertex %d has a non-finite coordinate (%g, %g, %g)", v, p.x(), p.y(), p.z()));
    }
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }

  std::vector<char> referenced(num_vertices, 0);
  for (int t = 0; t < num_triangles; ++t) {
    const auto& tri = mesh.triangles[t];
    for (int i = 0; i < 3; ++i) {
      if (tri[i] < 0 || tri[i] >= num_vertices) {
        return absl::InvalidArgumentError(
            absl::StrFormat("%s references vertex %d, out of range (the mesh has %d vertices)",
                            describe_triangle(t), tri[i], num_vertices));
      }
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
      return absl::InvalidArgumentError(absl::StrFormat("%s repeats a vertex index (%d, %d, %d)",
                                                        describe_triangle(t), tri[0], tri[1], tri[2]));
    }
    for (int i = 0; i < 3; ++i) referenced[tri[i]] = 1;
  }
  for (int v = 0; v < num_vertices; ++v) {
    if (!referenced[v]) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "vertex %d is unreferenced (used by no face; it would be a sampling site with no surface)", v));
    }
  }

  const double diagonal = (hi - lo).norm();
  const double min_area = kRelativeZeroFaceArea * diagonal * diagonal;
  for (int t = 0; t < num_triangles; ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3d& a = mesh.positions[tri[0]];
    const double area = 0.5 * (mesh.positions[tri[1]] - a).cross(mesh.positions[tri[2]] - a).norm();
    if (!(area > min_area)) {
      return absl::InvalidArgumentError(
          absl::StrFormat("%s (vertices %d, %d, %d) has zero area: %g mm^2, below %g mm^2 (1e-10 of the "
                          "squared bounding-box diagonal)",
                          describe_triangle(t), tri[0], tri[1], tri[2], area, min_area));
    }
  }

  // Manifold edges and consistent orientation: every undirected edge has at
  // most two faces, and two faces sharing an edge traverse it in opposite
  // directions.
  std::unordered_map<std::uint64_t, EdgeUse> edges;
  edges.reserve(static_cast<std::size_t>(num_triangles) * 2);
  for (int t = 0; t < num_triangles; ++t) {
    const auto& tri = mesh.triangles[t];
    for (int i = 0; i < 3; ++i) {
      const int a = tri[i];
      const int b = tri[(i + 1) % 3];
      const bool forward = a < b;
      EdgeUse& use = edges[EdgeKey(std::min(a, b), std::max(a, b))];
      ++use.count;
      if (use.count == 1) {
        use.first_triangle = t;
        use.first_forward = forward;
      } else if (use.count == 2) {
        use.second_triangle = t;
        if (use.first_forward == forward) {
          return absl::InvalidArgumentError(absl::StrFormat(
              "inconsistent orientation: %s and %s both traverse edge %d->%d in the same direction "
              "(neighbouring faces must wind the same way, counter-clockwise seen from outside)",
              describe_triangle(use.first_triangle), describe_triangle(t), a, b));
        }
      } else {
        return absl::InvalidArgumentError(absl::StrFormat(
            "non-manifold edge (%d, %d): shared by more than two faces (%s, %s and %s)", std::min(a, b),
            std::max(a, b), describe_triangle(use.first_triangle), describe_triangle(use.second_triangle),
            describe_triangle(t)));
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace surfmap
