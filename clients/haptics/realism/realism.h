// The realism figure: how much a drag over the MODEL (the texture renderer
// on the mapped model) feels like a drag over the TRUTH (the simulated rig
// on the scene), per material, along the same paths; and the same figures
// for a deliberately WRONG model (the map with its regions' materials
// swapped) to show that the measures discriminate.
//
// Per scene: the default mapping job in-process (clients/mapsim: boundary
// plan, region map, roughness fitted); the region map rebuilt from its
// drags at the map level becomes the model. Test drags (20 mm, 10 mm/s,
// 5 N, seeded sites stratified by true material and seeded directions)
// run on a rig with exact physics (DragSimOptions::Ideal: the normal force
// is the commanded one and there is no sensor noise, since the renderer
// plays the model without a rig's disturbances), and then through the
// renderer over the same executed paths. On each forward pass, the
// tangential force t = sqrt(|F|^2 - Fn^2) of the cruise samples, split into
// runs of one true material less 1 mm at each end (boundary placement is
// the map score's business; this is about the textures); per material:
//   mu        mean t / Fn
//   std       robust std (1.4826 x median absolute deviation) of the force
//             variation t - (its run's mean), N
//   acf       RMS difference of the variation's autocorrelation at lags
//             1..10 (0.1 mm each), model vs truth
//   ks, p     two-sample Kolmogorov-Smirnov statistic on the variation
//             (p from the asymptotic distribution: the samples are
//             autocorrelated, so p is optimistic; D is the measure)
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace surfmap::haptics {

struct RealismOptions {
  int drags_per_material = 8;
  double drag_length_mm = 20.0;
  std::uint64_t seed = 1;
  int map_budget = 0;  // 0: the default job's budget
};

struct Figures {
  double mu = 0.0;
  double rms_n = 0.0;         // the robust std above, N
  double acf_distance = 0.0;  // vs truth (0 for the truth itself)
  double ks = 0.0;            // vs truth
  double ks_p = 1.0;
};

struct MaterialRealism {
  std::string material;
  int samples = 0;            // truth samples of this material
  Figures truth, model, wrong;
};

struct SceneRealism {
  std::string scene;
  int map_samples = 0;        // drags of the mapping job
  int regions = 0;            // regions of the model
  int test_drags = 0;
  std::vector<MaterialRealism> materials;
  std::vector<std::string> region_summary;  // the model's regions, one line each
  double elapsed_s = 0.0;
};

absl::StatusOr<SceneRealism> RunRealism(const std::string& scene_name, const RealismOptions& options);

// Two-sample Kolmogorov-Smirnov: statistic D and its asymptotic p-value.
void KolmogorovSmirnov(std::vector<double> a, std::vector<double> b, double* d, double* p);

// The markdown table of several scenes (one row per scene and material).
std::string RealismTable(const std::vector<SceneRealism>& scenes);

}  // namespace surfmap::haptics
