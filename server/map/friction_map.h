// The friction/roughness map: measured texture parameters at some vertices of
// the finest surface level, interpolated across the surface (not through 3D
// space), with a per-vertex uncertainty.
//
// Interpolation. Every field is harmonic away from the samples: the samples are
// Dirichlet constraints of the Laplace equation on the finest-level mesh
// (cotangent weights by default, see mesh_laplacian.h), solved once per sample
// set with a sparse LDLT factorisation shared by all fields. Harmonic
// interpolation reproduces linear fields on flat meshes and keeps boundaries as
// sharp as the sample density allows; every field is clamped to the range of
// its samples (cotangent weights can overshoot slightly on obtuse triangles). Fields: mu; the roughness
// in a stable parameterisation: reflection coefficients k1..kp (any |k| < 1
// gives a stationary AR model; convex combinations stay inside) and log sigma.
// Samples without roughness (sigma <= 0 or no reflection coefficients) are
// left out of the roughness fields only. A connected part of the surface with
// no sample gets the mean of the samples and the prior uncertainty.
//
// Uncertainty (standard deviation of mu, per vertex). A Gaussian-process-like
// model with an exponential covariance over surface distance d (graph distance
// along finest edges, graph_distance.h) and correlation length l:
//
//   var(v) = s^2 (1 - exp(-2 d / l))   kriging variance given the nearest sample
//          + (g(v) d)^2                the local spread: the field changes by g
//                                      per mm here, and a boundary may lie
//                                      anywhere in the d mm to the nearest sample
//          + n^2                       the nearest sample's own mu_std (the mean
//                                      mu_std if the nearest site is pending)
//
// where s is the prior standard deviation (the spread of the measured mu,
// at least `prior_mu_std_floor`), d the distance to the nearest sample or
// pending site, and g the largest |mu difference| / edge length over the
// vertex's edges. Pending sites (to be measured, value unknown) lower the
// distance term but add no value, as in kriging where the variance does not
// depend on the observed values. It is 0 + n^2 at a sample and grows away from it.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "server/estimate/texture.h"
#include "server/map/mesh_laplacian.h"
#include "server/mesh/loop_surface.h"

namespace surfmap {

// One measured site: finest-level vertex index and its fit.
struct MapSample {
  int vertex = -1;
  TextureParams params;
};

struct FrictionMapOptions {
  LaplacianWeights weights = LaplacianWeights::kCotangent;
  // l above; 0 = a tenth of the finest level's bounding-box diagonal.
  double correlation_length_mm = 0.0;
  // Lower bound on s above, so that a few identical samples do not make the
  // whole map look certain.
  double prior_mu_std_floor = 0.02;
  bool IsValid(std::string* why) const;
};

// The map at one vertex or surface point.
struct MapValue {
  double mu = 0.0;
  double mu_std = 0.0;
  bool has_roughness = false;      // false when no sample has roughness
  std::vector<double> reflection;  // k1..kp (p = the highest order among the samples)
  double sigma = 0.0;              // exp of the interpolated log sigma
  int region = -1;                 // RegionMap: the material region; -1 for FrictionMap or no data
};

class FrictionMap {
 public:
  // Precomputes the Laplacian and connectivity of `finest`, which must outlive
  // the map. Errors (INVALID_ARGUMENT): invalid options, an empty level, sizes
  // of positions/neighbors/triangles that disagree.
  static absl::StatusOr<FrictionMap> Create(const SurfaceLevel& finest, const FrictionMapOptions& options = {});

  // Replaces the samples and recomputes every field. Errors (INVALID_ARGUMENT,
  // naming the sample index): no samples, a vertex out of range or repeated,
  // non-finite values, mu_std < 0, |reflection| >= 1, sigma < 0. On error the
  // map keeps its previous state. Pending vertices set before are kept.
  absl::Status SetSamples(std::vector<MapSample> samples);

  // Sites that will be measured (their values unknown): they lower the
  // uncertainty near them but not the values. Recomputes the uncertainty only.
  // Errors: a vertex out of range. Allowed before any sample is set.
  absl::Status SetPendingVertices(std::vector<int> vertices);

  bool has_samples() const { return !samples_.empty(); }
  int vertex_count() const { return static_cast<int>(finest_->limit_positions.size()); }
  const std::vector<MapSample>& samples() const { return samples_; }

  // Per finest-level vertex (empty before the first SetSamples).
  const std::vector<double>& mu() const { return mu_; }
  const std::vector<double>& mu_std() const { return mu_std_; }
  const std::vector<double>& mu_gradient() const { return mu_gradient_; }           // per mm
  const std::vector<double>& distance_to_sample_mm() const { return distance_mm_; }  // incl. pending
  const std::vector<double>& log_sigma() const { return log_sigma_; }                 // empty without roughness
  // reflection()[j] is k_(j+1) per vertex; roughness_order() == reflection().size().
  const std::vector<std::vector<double>>& reflection() const { return reflection_; }
  int roughness_order() const { return static_cast<int>(reflection_.size()); }

  double prior_mu_std() const { return prior_mu_std_; }
  double correlation_length_mm() const { return correlation_length_mm_; }

  // Values at vertex v (0 <= v < vertex_count(), after SetSamples).
  MapValue VertexValue(int v) const;
  // Barycentric interpolation of the finest vertices of point.triangle.
  // Errors: no samples yet (FAILED_PRECONDITION), triangle out of range or
  // non-finite barycentrics (INVALID_ARGUMENT).
  absl::StatusOr<MapValue> ValueAt(const SurfacePoint& point) const;

 private:
  FrictionMap() = default;
  absl::Status Solve(const std::vector<int>& fixed, const std::vector<std::vector<double>>& fixed_values,
                     std::vector<std::vector<double>>* fields) const;
  void RecomputeUncertainty();

  const SurfaceLevel* finest_ = nullptr;
  FrictionMapOptions options_;
  GraphLaplacian laplacian_;
  std::vector<int> component_;  // connected component id per vertex
  double correlation_length_mm_ = 0.0;

  std::vector<MapSample> samples_;
  std::vector<int> pending_;
  double prior_mu_std_ = 0.0;
  std::vector<double> mu_, mu_std_, mu_gradient_, distance_mm_, log_sigma_;
  std::vector<std::vector<double>> reflection_;
};

}  // namespace surfmap
