#include "server/map/mixture_materials.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

#include "absl/strings/str_cat.h"

namespace surfmap {

absl::StatusOr<MixtureScore> ScoreMixture(const std::vector<MapPiece>& pieces, const std::vector<int>& piece_material,
                                          int m, const std::vector<std::optional<SeriesTexture>>& textures,
                                          const std::vector<int>& others, const KnownTextureSplitOptions& split) {
  if (pieces.size() != piece_material.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("mixture test: ", pieces.size(), " pieces but ", piece_material.size(), " piece materials"));
  }
  auto fitted = [&](int k) { return k >= 0 && k < static_cast<int>(textures.size()) && textures[k].has_value(); };
  if (!fitted(m)) return absl::InvalidArgumentError(absl::StrCat("mixture test: material ", m, " has no texture"));
  MixtureScore score;
  std::vector<SeriesTexture> explaining;
  for (int o : others) {
    if (!fitted(o) || o == m) {
      return absl::InvalidArgumentError(absl::StrCat("mixture test: explaining material ", o, " has no texture or is ", m));
    }
    explaining.push_back(*textures[o]);
  }
  long rows = 0;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const std::vector<double>& x = pieces[i].pair_mu;
    if (piece_material[i] != m || x.size() < 3) continue;
    const int n = static_cast<int>(x.size());
    rows += n - 2;
    std::vector<ChangePoint> cuts;
    if (explaining.size() >= 2) {
      absl::StatusOr<std::vector<ChangePoint>> found = FindKnownTextureChanges(x, pieces[i].pair_s_mm, explaining, split);
      if (!found.ok()) {
        return absl::Status(found.status().code(), absl::StrCat("mixture test, piece ", i, ": ", found.status().message()));
      }
      cuts = *std::move(found);
    }
    // The parts as the split scores them: the transitional pair on each
    // side of a cut belongs to neither.
    int from = 0;
    auto score_part = [&](int begin, int end) {
      if (end - begin < 3) return;
      const std::span<const double> part(x.data() + begin, end - begin);
      score.with += SeriesLogLikelihood(part, *textures[m]);
      double best = -std::numeric_limits<double>::infinity();
      for (const SeriesTexture& t : explaining) best = std::max(best, SeriesLogLikelihood(part, t));
      score.without += best;
    };
    for (const ChangePoint& cut : cuts) {
      score_part(from, cut.index - 1);
      from = cut.index + 1;
      score.without -= cut.critical_value;
    }
    score_part(from, n);
    score.cuts += static_cast<int>(cuts.size());
  }
  constexpr double kTextureParameters = 4.0;
  if (rows > 0) score.with -= 0.5 * kTextureParameters * std::log(static_cast<double>(rows));
  return score;
}

absl::StatusOr<std::vector<int>> MixtureMaterials(const std::vector<MapPiece>& pieces,
                                                  const std::vector<int>& piece_material,
                                                  const std::vector<std::optional<SeriesTexture>>& textures,
                                                  const KnownTextureSplitOptions& split) {
  const int materials = static_cast<int>(textures.size());
  std::vector<bool> explains(materials);
  for (int m = 0; m < materials; ++m) explains[m] = textures[m].has_value();
  std::vector<int> dissolved;
  while (true) {
    int worst = -1;
    double largest = 0.0;
    for (int m = 0; m < materials; ++m) {
      if (!explains[m]) continue;
      std::vector<int> others;
      for (int o = 0; o < materials; ++o) {
        if (o != m && explains[o]) others.push_back(o);
      }
      if (others.size() < 2) continue;
      absl::StatusOr<MixtureScore> score = ScoreMixture(pieces, piece_material, m, textures, others, split);
      if (!score.ok()) return score.status();
      if (score->margin() > largest) largest = score->margin(), worst = m;
    }
    if (worst < 0) return dissolved;
    dissolved.push_back(worst);
    explains[worst] = false;
  }
}

}  // namespace surfmap
