// The input of the map renderers: a triangle mesh with a scalar per vertex.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>
#include "absl/status/status.h"

namespace surfmap {

struct MapMesh {
  std::vector<Eigen::Vector3d> positions;       // mm
  std::vector<Eigen::Vector3d> normals;         // unit, per vertex; empty = computed from the faces
  std::vector<std::array<int, 3>> triangles;    // counter-clockwise seen from outside
  std::vector<double> values;                   // per vertex (e.g. mu); NaN = not known
  std::vector<double> uncertainties;            // per vertex (e.g. mu std); optional (empty)
};

// INVALID_ARGUMENT naming the first problem: no vertices or triangles,
// non-finite positions or normals, per-vertex arrays of the wrong length,
// triangle indices out of range. Values may be NaN (unknown), not infinite.
absl::Status ValidateMapMesh(const MapMesh& mesh);

// Area-weighted vertex normals of `mesh` (unit; zero-area fans give +z).
std::vector<Eigen::Vector3d> ComputeVertexNormals(const MapMesh& mesh);

// The value range over the finite values: [min, max], or [0, 1] if none.
std::array<double, 2> FiniteValueRange(const std::vector<double>& values);

}  // namespace surfmap
