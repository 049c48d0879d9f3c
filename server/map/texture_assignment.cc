#include "server/map/texture_assignment.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace surfmap {

double RegionLogLikelihood(const std::vector<MapPiece>& pieces, const std::vector<int>& region_pieces,
                           const SeriesTexture& texture) {
  double log_likelihood = 0.0;
  for (int i : region_pieces) log_likelihood += SeriesLogLikelihood(pieces[i].pair_mu, texture);
  return log_likelihood;
}

std::vector<int> RenumberInOrderOfFirstRegion(std::vector<int>* material) {
  std::vector<int> renumbered, old_of_new;
  for (int& m : *material) {
    if (m < 0) continue;
    if (m >= static_cast<int>(renumbered.size())) renumbered.resize(m + 1, -1);
    if (renumbered[m] < 0) {
      renumbered[m] = static_cast<int>(old_of_new.size());
      old_of_new.push_back(m);
    }
    m = renumbered[m];
  }
  return old_of_new;
}

TextureAssignment AssignRegionsByTexture(const std::vector<MapPiece>& pieces,
                                         const std::vector<std::vector<int>>& region_pieces,
                                         const std::vector<int>& region_material,
                                         const std::vector<std::optional<SeriesTexture>>& material_texture,
                                         const std::function<bool(int, int)>& may_join,
                                         double false_alarm_probability) {
  const int regions = static_cast<int>(region_material.size());
  const int materials = static_cast<int>(material_texture.size());
  std::vector<int> textured;
  for (int m = 0; m < materials; ++m) {
    if (material_texture[m].has_value()) textured.push_back(m);
  }
  TextureAssignment out;
  std::vector<int> material = region_material;
  if (textured.size() >= 2) {
    const double critical = std::log(static_cast<double>(textured.size() - 1) / false_alarm_probability);
    for (int r = 0; r < regions && r < static_cast<int>(region_pieces.size()); ++r) {
      const int own = material[r];
      if (own < 0 || own >= materials || !material_texture[own].has_value()) continue;
      double own_log_likelihood = 0.0;
      double best = -std::numeric_limits<double>::infinity();
      int best_material = own;
      for (int m : textured) {
        if (m != own && !may_join(r, m)) continue;
        const double log_likelihood = RegionLogLikelihood(pieces, region_pieces[r], *material_texture[m]);
        if (m == own) own_log_likelihood = log_likelihood;
        if (log_likelihood > best) best = log_likelihood, best_material = m;
      }
      if (best_material != own && best - own_log_likelihood > critical) {
        material[r] = best_material;
        ++out.moved;
      }
    }
  }
  RenumberInOrderOfFirstRegion(&material);
  out.material = std::move(material);
  return out;
}

}  // namespace surfmap
