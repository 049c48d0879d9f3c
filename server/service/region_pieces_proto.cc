#include "server/service/region_pieces_proto.h"

#include <algorithm>
#include <utility>
#include <vector>

namespace surfmap {

absl::flat_hash_map<int, int64_t> DragTraceIds(const std::vector<SampleRecord>& samples, int first_import_drag) {
  absl::flat_hash_map<int, int64_t> out;
  std::vector<int64_t> imports;
  for (const SampleRecord& s : samples) {
    if (!s.trace.import_sha256.empty()) {
      imports.push_back(s.trace.id);
    } else {
      out.try_emplace(static_cast<int>(s.command.site_vertex), s.trace.id);
    }
  }
  std::sort(imports.begin(), imports.end());
  for (std::size_t k = 0; k < imports.size(); ++k) out[first_import_drag + static_cast<int>(k)] = imports[k];
  return out;
}

void FillRegionPieces(const RegionMap& map, int first_import_drag, const std::vector<SampleRecord>& samples,
                      v1::MapLevel* out) {
  const absl::flat_hash_map<int, int64_t> traces = DragTraceIds(samples, first_import_drag);
  const std::vector<PieceStatistics>& statistics = map.piece_statistics();
  const int region_count = std::min<int>(static_cast<int>(map.regions().size()), out->regions_size());
  // Flags of the region's counted pieces, set and cleared per region: one
  // pass over its mu_pieces, not the map's pieces, since every moved misfit
  // piece is a region of its own (RegionMapOptions::move_misfit_pieces).
  std::vector<bool> counted(map.pieces().size(), false);
  for (int r = 0; r < region_count; ++r) {
    const TextureRegion& region = map.regions()[r];
    double total_weight = 0.0;
    for (int i : region.mu_pieces) {
      total_weight += 1.0 / (statistics[i].mu_se * statistics[i].mu_se);
      counted[i] = true;
    }
    v1::MapRegion* o = out->mutable_regions(r);
    for (int i : region.pieces) {
      const MapPiece& piece = map.pieces()[i];
      const PieceStatistics& s = statistics[i];
      v1::MapRegionPiece* p = o->add_pieces();
      auto trace = traces.find(piece.drag);
      p->set_trace_id(trace == traces.end() ? 0 : trace->second);
      p->set_fit_piece(piece.line_piece);
      p->set_start_mm(piece.piece.start_mm);
      p->set_end_mm(piece.piece.end_mm);
      p->set_split_by_map(piece.split_by_map);
      p->set_mu(s.mu);
      p->set_mu_se(s.mu_se);
      p->set_effective_pairs(s.effective_pairs);
      p->set_in_mu(counted[i]);
      p->set_mu_weight(counted[i] && total_weight > 0.0 ? 1.0 / (s.mu_se * s.mu_se) / total_weight : 0.0);
    }
    for (int i : region.mu_pieces) counted[i] = false;
  }
}

}  // namespace surfmap
