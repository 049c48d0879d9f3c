#include "server/map/texture_assignment.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace surfmap {

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
        double log_likelihood = 0.0;
        for (int i : region_pieces[r]) log_likelihood += SeriesLogLikelihood(pieces[i].pair_mu, *material_texture[m]);
        if (m == own) own_log_likelihood = log_likelihood;
        if (log_likelihood > best) best = log_likelihood, best_material = m;
      }
      if (best_material != own && best - own_log_likelihood > critical) {
        material[r] = best_material;
        ++out.moved;
      }
    }
  }
  // Renumber: materials in order of their first region, none left empty.
  std::vector<int> renumbered(std::max(materials, 0), -1);
  int next = 0;
  out.material.resize(regions);
  for (int r = 0; r < regions; ++r) {
    const int m = material[r];
    if (m < 0) {
      out.material[r] = -1;
      continue;
    }
    if (m >= static_cast<int>(renumbered.size())) renumbered.resize(m + 1, -1);
    if (renumbered[m] < 0) renumbered[m] = next++;
    out.material[r] = renumbered[m];
  }
  return out;
}

}  // namespace surfmap
