#include "server/haptics/map_quantity.h"

#include <array>
#include <cmath>
#include <string>

#include "absl/strings/str_cat.h"

namespace surfmap::haptics {
namespace {

struct Entry {
  MapQuantity quantity;
  std::string_view name;
  std::string_view title;
};
constexpr std::array<Entry, 7> kEntries = {{
    {MapQuantity::kMu, "mu", "MU"},
    {MapQuantity::kMuStd, "mu_std", "MU STD"},
    {MapQuantity::kSigma, "sigma", "SIGMA (N)"},
    {MapQuantity::kA1, "a1", "A1"},
    {MapQuantity::kA2, "a2", "A2"},
    {MapQuantity::kRegion, "region", "REGION"},
    {MapQuantity::kBoundaryProbability, "boundary_probability", "BOUNDARY PROB"},
}};

}  // namespace

absl::StatusOr<MapQuantity> ParseMapQuantity(std::string_view name) {
  for (const Entry& e : kEntries) {
    if (e.name == name) return e.quantity;
  }
  return absl::InvalidArgumentError(absl::StrCat(
      "unknown quantity '", std::string(name), "' (mu, mu_std, sigma, a1, a2, region or boundary_probability)"));
}

std::string_view MapQuantityName(MapQuantity quantity) { return kEntries[static_cast<int>(quantity)].name; }
std::string_view MapQuantityTitle(MapQuantity quantity) { return kEntries[static_cast<int>(quantity)].title; }

absl::StatusOr<std::vector<double>> MapQuantityValues(const TextureMap& map, MapQuantity quantity) {
  const std::vector<double>* source = nullptr;
  switch (quantity) {
    case MapQuantity::kMu: source = &map.mu; break;
    case MapQuantity::kMuStd: source = &map.mu_std; break;
    case MapQuantity::kSigma: source = &map.sigma; break;
    case MapQuantity::kA1: source = &map.a1; break;
    case MapQuantity::kA2: source = &map.a2; break;
    case MapQuantity::kBoundaryProbability: source = &map.boundary_probability; break;
    case MapQuantity::kRegion: {
      if (map.region.empty()) break;
      std::vector<double> out;
      out.reserve(map.region.size());
      for (int r : map.region) out.push_back(r >= 0 ? r : std::nan(""));
      return out;
    }
  }
  if (source == nullptr || source->empty()) {
    return absl::FailedPreconditionError(
        absl::StrCat("the map has no ", std::string(MapQuantityName(quantity)), " values"));
  }
  std::vector<double> out = *source;
  // Roughness where there is no fit (sigma 0) is not a value of a1/a2 but
  // their absence: show it as unknown rather than as 0.
  if ((quantity == MapQuantity::kA1 || quantity == MapQuantity::kA2) && map.sigma.size() == out.size()) {
    for (size_t v = 0; v < out.size(); ++v) {
      if (!(map.sigma[v] > 0)) out[v] = std::nan("");
    }
  }
  return out;
}

}  // namespace surfmap::haptics
