#include "server/mesh/mesh_repair.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>

#include <Eigen/Geometry>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/mesh/obj_reader.h"
#include "server/mesh/parsed_mesh.h"
#include "server/mesh/parsed_mesh.h"
#include "server/mesh/ply_reader.h"
#include "server/mesh/stl_reader.h"

namespace surfmap {
namespace {

absl::StatusOr<ParsedMesh> Read(std::string_view bytes, MeshFormat format, std::string_view source) {
  switch (format) {
    case MeshFormat::kPly: return ReadPly(bytes, source);
    case MeshFormat::kStl: return ReadStl(bytes, source);
    case MeshFormat::kObj: return ReadObj(bytes, source);
  }
  return absl::InvalidArgumentError("unknown mesh format");
}

// Welds vertices within `tolerance` (grid hashing: each vertex is compared
// with the earlier vertices in its own and the 26 neighbouring cells of side
// `tolerance`). Returns the old -> new index map and the number merged.
int WeldVertices(ControlMesh& mesh, double tolerance, std::vector<int>& remap) {
  const int n = static_cast<int>(mesh.positions.size());
  remap.assign(n, -1);
  if (!(tolerance > 0)) {
    for (int v = 0; v < n; ++v) remap[v] = v;
    return 0;
  }
  struct CellHash {
    std::size_t operator()(const std::array<std::int64_t, 3>& c) const {
      return static_cast<std::size_t>(c[0] * 73856093 ^ c[1] * 19349663 ^ c[2] * 83492791);
    }
  };
  std::unordered_map<std::array<std::int64_t, 3>, std::vector<int>, CellHash> cells;
  cells.reserve(n);
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(n);
  int merged = 0;
  const double tolerance2 = tolerance * tolerance;
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector3d& p = mesh.positions[v];
    const std::array<std::int64_t, 3> cell{static_cast<std::int64_t>(std::floor(p.x() / tolerance)),
                                           static_cast<std::int64_t>(std::floor(p.y() / tolerance)),
                                           static_cast<std::int64_t>(std::floor(p.z() / tolerance))};
    int found = -1;
    for (int dx = -1; dx <= 1 && found < 0; ++dx) {
      for (int dy = -1; dy <= 1 && found < 0; ++dy) {
        for (int dz = -1; dz <= 1 && found < 0; ++dz) {
          auto it = cells.find({cell[0] + dx, cell[1] + dy, cell[2] + dz});
          if (it == cells.end()) continue;
          for (const int k : it->second) {
            if ((kept[k] - p).squaredNorm() <= tolerance2) {
              found = k;
              break;
            }
          }
        }
      }
    }
    if (found >= 0) {
      remap[v] = found;
      ++merged;
    } else {
      remap[v] = static_cast<int>(kept.size());
      cells[cell].push_back(remap[v]);
      kept.push_back(p);
    }
  }
  mesh.positions = std::move(kept);
  return merged;
}

}  // namespace

absl::StatusOr<RepairedMesh> ParseAndRepairMesh(std::string_view bytes, MeshFormat format, std::string_view source,
                                                double mm_per_unit) {
  if (!(mm_per_unit > 0) || !std::isfinite(mm_per_unit)) {
    return absl::InvalidArgumentError(absl::StrFormat("scale must be a finite number > 0 mm per unit, got %g",
                                                      mm_per_unit));
  }
  absl::StatusOr<ParsedMesh> read = Read(bytes, format, source);
  if (!read.ok()) return read.status();
  ParsedMesh& parsed = *read;
  ControlMesh& mesh = parsed.mesh;
  RepairedMesh out;
  auto note = [&out](std::string kind, int count, std::string detail) {
    if (count > 0) out.repairs.push_back({std::move(kind), count, std::move(detail)});
  };
  note("repeated_vertex_polygons_fixed", parsed.polygons_with_repeated_vertex,
       absl::StrCat("polygons listing a vertex twice in a row (first: ", parsed.first_repeated_vertex_polygon,
                    "); the repeat was dropped",
                    parsed.polygons_dropped > 0
                        ? absl::StrCat(", ", parsed.polygons_dropped, " left with < 3 vertices were dropped")
                        : ""));
  if (mesh.positions.empty()) return absl::InvalidArgumentError(absl::StrFormat("%s: empty mesh: no vertices", source));
  for (Eigen::Vector3d& p : mesh.positions) p *= mm_per_unit;

  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = Eigen::Vector3d::Constant(-INFINITY);
  for (const Eigen::Vector3d& p : mesh.positions) {
    if (!p.allFinite()) return absl::InvalidArgumentError(absl::StrFormat("%s: a coordinate is not finite after scaling", source));
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double diagonal = (hi - lo).norm();

  // Indices are checked before they are used to look up positions.
  const int num_read = static_cast<int>(mesh.positions.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (const int v : mesh.triangles[t]) {
      if (v < 0 || v >= num_read) {
        return absl::InvalidArgumentError(absl::StrFormat("%s: triangle %d (%s) references vertex %d, out of range",
                                                          source, t, parsed.triangle_origin[t], v));
      }
    }
  }

  const double tolerance = kWeldRelativeTolerance * diagonal;
  std::vector<int> remap;
  const int welded = WeldVertices(mesh, tolerance, remap);
  note("duplicate_vertices_welded", welded,
       absl::StrFormat("vertices within %.3g mm (1e-6 of the bounding-box diagonal) of an earlier one were merged",
                       tolerance));

  const double min_area = kRelativeZeroFaceArea * diagonal * diagonal;
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::string> origins;
  triangles.reserve(mesh.triangles.size());
  origins.reserve(mesh.triangles.size());
  int collapsed = 0, zero_area = 0, duplicates = 0;
  struct TriHash {
    std::size_t operator()(const std::array<int, 3>& t) const {
      return static_cast<std::size_t>(t[0]) * 73856093u ^ static_cast<std::size_t>(t[1]) * 19349663u ^
             static_cast<std::size_t>(t[2]) * 83492791u;
    }
  };
  std::unordered_set<std::array<int, 3>, TriHash> seen;
  seen.reserve(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    std::array<int, 3> tri = mesh.triangles[t];
    for (int& v : tri) v = remap[v];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
      ++collapsed;
      continue;
    }
    const Eigen::Vector3d& a = mesh.positions[tri[0]];
    const double area = 0.5 * (mesh.positions[tri[1]] - a).cross(mesh.positions[tri[2]] - a).norm();
    if (!(area > min_area)) {
      ++zero_area;
      continue;
    }
    std::array<int, 3> key = tri;
    std::sort(key.begin(), key.end());
    if (!seen.insert(key).second) {
      ++duplicates;
      continue;
    }
    triangles.push_back(tri);
    origins.push_back(std::move(parsed.triangle_origin[t]));
  }
  note("degenerate_faces_removed", collapsed + zero_area,
       absl::StrFormat("%d faces repeating a vertex (after welding), %d of zero area (below %.3g mm^2)", collapsed,
                       zero_area, min_area));
  note("duplicate_faces_removed", duplicates, "faces with the same three vertices as an earlier face (either winding)");

  std::vector<int> compact(mesh.positions.size(), -1);
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(mesh.positions.size());
  for (auto& tri : triangles) {
    for (int& v : tri) {
      if (compact[v] < 0) {
        compact[v] = static_cast<int>(positions.size());
        positions.push_back(mesh.positions[v]);
      }
      v = compact[v];
    }
  }
  note("unreferenced_vertices_removed", static_cast<int>(mesh.positions.size() - positions.size()),
       "vertices used by no face (they would be sampling sites with no surface)");
  // Vertices keep their file order where they survive: the compaction above
  // numbers them by first use, so renumber back to file order.
  {
    std::vector<int> order;  // new index -> old index
    order.reserve(positions.size());
    for (std::size_t v = 0; v < compact.size(); ++v) {
      if (compact[v] >= 0) order.push_back(static_cast<int>(v));
    }
    std::vector<int> renumber(positions.size());
    for (std::size_t k = 0; k < order.size(); ++k) {
      renumber[compact[order[k]]] = static_cast<int>(k);
      positions[k] = mesh.positions[order[k]];
    }
    for (auto& tri : triangles)
      for (int& v : tri) v = renumber[v];
  }

  out.mesh.positions = std::move(positions);
  out.mesh.triangles = std::move(triangles);
  if (out.mesh.triangles.empty()) {
    return absl::InvalidArgumentError(absl::StrFormat("%s: no faces left after removing degenerate ones", source));
  }
  const absl::Status valid = ValidateTriangleMesh(
      out.mesh, [&](int t) { return absl::StrCat("triangle ", t, " (", origins[t], ")"); });
  if (!valid.ok()) return absl::InvalidArgumentError(absl::StrFormat("%s: %s", source, valid.message()));
  return out;
}

}  // namespace surfmap
