// Texture parameters of one site and the distance between two sites, used by
// the sampling planner to decide where to refine.
#pragma once

#include <string>
#include <vector>

namespace surfmap {

// What the planner and the map need from a fit: friction and roughness.
struct TextureParams {
  double mu = 0.0;
  double mu_std = 0.0;
  std::vector<double> reflection;  // AR reflection coefficients k1..kp
  double sigma = 0.0;              // AR innovation standard deviation, N
};

enum class TextureProperty { kFriction, kRoughness, kBoth };

struct TextureDistanceOptions {
  TextureProperty property = TextureProperty::kBoth;
  double mu_scale = 0.05;          // a mu difference of this size counts 1
  double reflection_scale = 0.3;   // a reflection coefficient difference of this size counts 1
  double log_sigma_scale = 0.5;    // a |log(sigma_a / sigma_b)| of this size counts 1
};

// Euclidean norm of the scaled parameter differences (see texture.cc for the
// definition); 0 for identical textures, ~1 at the scales above.
double TextureDistance(const TextureParams& a, const TextureParams& b,
                       const TextureDistanceOptions& options = {});

}  // namespace surfmap
