#include "server/estimate/texture.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"

namespace surfmap {

std::string_view TexturePropertyName(TextureProperty property) {
  switch (property) {
    case TextureProperty::kFriction:
      return "friction";
    case TextureProperty::kRoughness:
      return "roughness";
    case TextureProperty::kBoth:
      return "both";
  }
  return "both";  // unreachable: every enumerator is named above
}

std::optional<TextureProperty> ParseTextureProperty(std::string_view name) {
  for (TextureProperty p : {TextureProperty::kFriction, TextureProperty::kRoughness, TextureProperty::kBoth}) {
    if (TexturePropertyName(p) == name) return p;
  }
  return std::nullopt;
}
namespace {

bool IsPositiveScale(double scale) { return std::isfinite(scale) && scale > 0.0; }

}  // namespace

bool TextureDistanceOptions::IsValid(std::string* why) const {
  std::string reason;
  if (!IsPositiveScale(mu_scale)) {
    reason = absl::StrCat("mu_scale ", mu_scale, " must be finite and > 0");
  } else if (!IsPositiveScale(reflection_scale)) {
    reason = absl::StrCat("reflection_scale ", reflection_scale, " must be finite and > 0");
  } else if (!IsPositiveScale(log_sigma_scale)) {
    reason = absl::StrCat("log_sigma_scale ", log_sigma_scale, " must be finite and > 0");
  }
  if (reason.empty()) return true;
  if (why != nullptr) *why = std::move(reason);
  return false;
}

double TextureDistance(const TextureParams& a, const TextureParams& b,
                       const TextureDistanceOptions& options) {
  if (!options.IsValid(nullptr)) return std::numeric_limits<double>::quiet_NaN();
  double sum_of_squares = 0.0;
  if (options.property != TextureProperty::kRoughness) {
    const double d = (a.mu - b.mu) / options.mu_scale;
    sum_of_squares += d * d;
  }
  if (options.property != TextureProperty::kFriction) {
    const std::size_t p = std::max(a.reflection.size(), b.reflection.size());
    for (std::size_t i = 0; i < p; ++i) {
      const double ka = i < a.reflection.size() ? a.reflection[i] : 0.0;
      const double kb = i < b.reflection.size() ? b.reflection[i] : 0.0;
      const double d = (ka - kb) / options.reflection_scale;
      sum_of_squares += d * d;
    }
    // std::max would turn a NaN sigma into the floor; keep NaN visible.
    if (std::isnan(a.sigma) || std::isnan(b.sigma)) return std::numeric_limits<double>::quiet_NaN();
    const double sa = std::max(a.sigma, kTextureSigmaFloor);
    const double sb = std::max(b.sigma, kTextureSigmaFloor);
    const double d = std::log(sa / sb) / options.log_sigma_scale;
    sum_of_squares += d * d;
  }
  return std::sqrt(sum_of_squares);
}

}  // namespace surfmap
