#include "server/mesh/control_simplify.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <meshoptimizer.h>
#include "absl/strings/str_format.h"
#include "server/mesh/flat_coarsen.h"
#include "server/mesh/flat_refine.h"
#include "server/mesh/mesh_units.h"

namespace surfmap {
namespace {

// A mesh within this factor of the target is taken as a designed control mesh
// and used as is: its sites are at most sqrt(3) = 1.7x closer than asked. The
// bundled scenes' hand-made meshes (162 vertices, ~14 mm apart, on objects of
// 28,000-38,000 mm^2) stay as they were planned at the default 20 mm; a scan
// (thousands of vertices) is far beyond it. CreateJob warns when sites end up
// closer than 3/4 of the drag.
constexpr double kKeepFactor = 3.0;

// meshopt_simplify's target_error is relative to the mesh extent. Sites must
// cover the object at the spacing whatever the shape error of the coarse
// mesh (the dense mesh stays the geometry), so the vertex count decides.
constexpr float kUnboundedError = 1.0f;

absl::StatusOr<ControlMesh> Simplify(const ControlMesh& dense, int target_vertices) {
  std::vector<float> positions;
  positions.reserve(dense.positions.size() * 3);
  // meshoptimizer works in float: centre first so large offsets lose no precision.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : dense.positions) centre += p;
  centre /= static_cast<double>(dense.positions.size());
  for (const Eigen::Vector3d& p : dense.positions) {
    for (int i = 0; i < 3; ++i) positions.push_back(static_cast<float>(p[i] - centre[i]));
  }
  std::vector<unsigned int> indices;
  indices.reserve(dense.triangles.size() * 3);
  for (const auto& t : dense.triangles) {
    for (int v : t) indices.push_back(static_cast<unsigned int>(v));
  }
  // Faces per vertex of this mesh (2 for a closed genus-0 mesh, fewer when
  // open) turns the vertex target into meshoptimizer's index target.
  const double faces_per_vertex = static_cast<double>(dense.triangles.size()) / dense.positions.size();
  const std::size_t target_indices = 3 * static_cast<std::size_t>(std::lround(target_vertices * faces_per_vertex));
  std::vector<unsigned int> out(indices.size());
  const std::size_t count =
      meshopt_simplify(out.data(), indices.data(), indices.size(), positions.data(), dense.positions.size(),
                       3 * sizeof(float), target_indices, kUnboundedError, /*options=*/0, nullptr);
  out.resize(count);

  // Compact: keep the dense positions (double) of the vertices still used.
  ControlMesh result;
  std::vector<int> remap(dense.positions.size(), -1);
  for (std::size_t i = 0; i + 2 < out.size(); i += 3) {
    std::array<int, 3> tri;
    for (int c = 0; c < 3; ++c) {
      const int v = static_cast<int>(out[i + c]);
      if (remap[v] < 0) {
        remap[v] = static_cast<int>(result.positions.size());
        result.positions.push_back(dense.positions[v]);
      }
      tri[c] = remap[v];
    }
    result.triangles.push_back(tri);
  }
  if (absl::Status valid = ValidateControlMesh(result); !valid.ok()) return valid;
  return result;
}

// `mesh` simplified to about choice.target_vertices into choice.mesh. A
// collapse that would pinch the mesh is sometimes taken near the end of an
// aggressive simplification; stopping earlier avoids it. The last failure
// when no target gives a valid mesh.
absl::Status SimplifyToTarget(const ControlMesh& mesh, ControlMeshChoice& choice) {
  absl::Status last = absl::FailedPreconditionError("the mesh is not finer than the target");
  for (const double factor : {1.0, 1.25, 1.6, 2.0}) {
    const int target = static_cast<int>(std::lround(choice.target_vertices * factor));
    if (target >= static_cast<int>(mesh.positions.size())) break;
    absl::StatusOr<ControlMesh> simplified = Simplify(mesh, target);
    if (simplified.ok()) {
      choice.mesh = std::move(*simplified);
      choice.simplified = true;
      return absl::OkStatus();
    }
    last = simplified.status();
  }
  return last;
}

}  // namespace

absl::StatusOr<ControlMeshChoice> ControlMeshForSpacing(const ControlMesh& dense, double spacing_mm) {
  if (!(spacing_mm > 0) || !std::isfinite(spacing_mm)) {
    return absl::InvalidArgumentError(absl::StrFormat("site spacing must be > 0 mm, got %g", spacing_mm));
  }
  if (absl::Status valid = ValidateControlMesh(dense); !valid.ok()) return valid;
  ControlMeshChoice choice;
  const double area = SurfaceArea(dense);
  choice.target_vertices =
      std::max(kMinControlVertices, static_cast<int>(std::lround(area / (spacing_mm * spacing_mm))));
  if (static_cast<double>(dense.positions.size()) <= kKeepFactor * choice.target_vertices) {
    choice.mesh = dense;
    return choice;
  }
  absl::Status last = SimplifyToTarget(dense, choice);
  if (last.ok()) return choice;
  // A faceted part (a CAD export) finer than the spacing: meshoptimizer
  // leaves zero-area triangles along its straight sharp edges (flat_coarsen.h).
  // Coarsened without changing its shape and refined flat to the spacing it
  // is the same surface with sites about the spacing apart; what is still
  // too fine there (a curved rim) is simplified as before.
  const ControlMesh coarse = CoarsenFlat(dense);
  if (coarse.positions.size() < dense.positions.size()) {
    const int cap = std::max(static_cast<int>(dense.positions.size()), 4 * choice.target_vertices);
    absl::StatusOr<ControlMesh> refined = RefineFlat(coarse, std::sqrt(2.0) * spacing_mm, cap);
    if (refined.ok() && static_cast<double>(refined->positions.size()) <= kKeepFactor * choice.target_vertices) {
      choice.mesh = std::move(*refined);
      choice.simplified = true;
      return choice;
    }
    if (refined.ok()) {
      const absl::Status again = SimplifyToTarget(*refined, choice);
      if (again.ok()) return choice;
    }
  }
  return absl::FailedPreconditionError(absl::StrFormat(
      "could not simplify the %d-vertex mesh to a valid control mesh for %g mm site spacing (~%d vertices): %s; "
      "try another site_spacing_mm",
      dense.positions.size(), spacing_mm, choice.target_vertices, last.message()));
}

}  // namespace surfmap
