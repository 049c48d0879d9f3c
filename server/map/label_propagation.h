// Labels spread over a surface from seeds on it: the random walker of Grady
// (2006). For each label, the probability that a random walk from a vertex
// reaches a seed of that label first is the harmonic function that is 1 at
// that label's seeds and 0 at the others; a vertex takes the label of the
// largest. Between the data of two regions the boundary falls where their
// fields cross: it passes through the places where a drag found a change
// (both labels' seeds side by side) and runs smoothly from one crossing to
// the next, instead of following the perpendicular bisectors of the data
// (the nearest-data diagram draws a star round a patch crossed obliquely).
//
// Seeds are points inside triangles, not vertices: each adds
// stiffness * (sum_i b_i f_i - target)^2 to the Dirichlet energy of f (b its
// barycentric weights), so a change point keeps its sub-vertex position. One
// sparse LDLT factorisation of L + stiffness * B'B serves every label; the
// clamped cotangent Laplacian keeps every field in [0, 1] (a maximum
// principle). A part of the surface without seeds gets zero everywhere.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include "absl/status/statusor.h"
#include "server/map/mesh_laplacian.h"
#include "server/mesh/loop_surface.h"

namespace surfmap {

struct SurfaceSeed {
  int triangle = -1;                                     // of the level
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();  // weights of its corners
  int label = -1;                                        // 0..labels-1
};

class LabelPropagation {
 public:
  // The level must outlive the propagation. Errors (INVALID_ARGUMENT): an
  // empty level, triangle indices out of range.
  static absl::StatusOr<LabelPropagation> Create(const SurfaceLevel& level);

  // fields[c][v]: the probability of label c at vertex v. Seeds with a
  // triangle or label out of range are ignored. Errors: INTERNAL when the
  // factorisation fails.
  absl::StatusOr<std::vector<std::vector<double>>> Propagate(std::span<const SurfaceSeed> seeds, int labels);

 private:
  LabelPropagation() = default;
  const SurfaceLevel* level_ = nullptr;
  std::vector<Eigen::Triplet<double>> laplacian_;  // lower triangle, with the regularising diagonal
  double stiffness_ = 0.0;
  bool analysed_ = false;
  // Eigen's solvers are neither copyable nor movable: held by pointer so the
  // propagation (and the map holding it) can move.
  std::unique_ptr<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower>> ldlt_;
};

}  // namespace surfmap
