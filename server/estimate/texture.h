// Texture parameters of one site and the distance between two sites, used by
// the sampling planner to decide where to refine.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace surfmap {

// What the planner and the map need from a fit: friction and roughness.
struct TextureParams {
  double mu = 0.0;
  double mu_std = 0.0;             // spread of the per-point mu (not used by TextureDistance)
  std::vector<double> reflection;  // AR reflection coefficients k1..kp
  double sigma = 0.0;              // AR innovation standard deviation, N
};

enum class TextureProperty { kFriction, kRoughness, kBoth };
// "friction", "roughness", "both": the one spelling of a property in stored
// JSON (job parameters, plan state) and on command lines.
std::string_view TexturePropertyName(TextureProperty property);
// The inverse; nullopt for any other text (the caller names the field).
std::optional<TextureProperty> ParseTextureProperty(std::string_view name);

struct TextureDistanceOptions {
  TextureProperty property = TextureProperty::kBoth;
  double mu_scale = 0.05;          // a mu difference of this size counts 1
  double reflection_scale = 0.3;   // a reflection coefficient difference of this size counts 1
  double log_sigma_scale = 0.5;    // a |log(sigma_a / sigma_b)| of this size counts 1
  // False (with a reason in *why, if given) unless every scale is finite and > 0.
  bool IsValid(std::string* why) const;
};

// Smallest sigma TextureDistance takes a log of (N): a sigma of 0 (a perfectly
// smooth fit) is treated as this, so the distance stays finite.
inline constexpr double kTextureSigmaFloor = 1e-6;

// The texture distance between two sites:
//
//   d = sqrt( [friction terms]^2 + [roughness terms]^2 )
//   friction terms  (kFriction, kBoth):  (mu_a - mu_b) / mu_scale
//   roughness terms (kRoughness, kBoth): (k_a,i - k_b,i) / reflection_scale
//                                          for i = 1..max(p_a, p_b),
//                                        |ln(s_a / s_b)| / log_sigma_scale
//   with s = max(sigma, kTextureSigmaFloor), and a missing reflection
//   coefficient taken as 0 (an AR(p) model is an AR(p+1) model with k_(p+1) = 0).
//
// Reflection coefficients rather than a1..ap because they are bounded (|k| < 1
// for any stable model) and vary smoothly with the texture; sigma enters as a
// log ratio because roughness amplitudes differ by factors, not offsets.
// Symmetric, 0 for identical textures, 1 for a difference of exactly one scale
// in one parameter; it is a metric (Euclidean norm of scaled coordinates).
// mu_std is not used: weighing differences by their uncertainty is the
// planner's job. Invalid options (see IsValid) or non-finite parameters give NaN.
double TextureDistance(const TextureParams& a, const TextureParams& b,
                       const TextureDistanceOptions& options = {});

}  // namespace surfmap
