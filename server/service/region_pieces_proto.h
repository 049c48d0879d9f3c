// The pieces behind each region of a map (MapRegion.pieces): which drag and
// which of its fit's pieces, the stretch, and how the map weighed it. A
// researcher checking a region's mu against the drags needs exactly this;
// the map's regions alone say only how many pieces there were.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "proto/surfmap/v1/surfmap.pb.h"
#include "server/map/region_map.h"
#include "storage/records.h"

namespace surfmap {

// The trace id of each drag the map numbers (MapPiece::drag, as
// SamplingPlan::MeasuredPieces numbers them): a leased trace's drag is its
// site's vertex (a coarser level's vertex numbers are a prefix of the
// finest's), an imported trace's is `first_import_drag` plus its place
// among the imports (a job's writes commit in the order its plan changed,
// so that place is its order by trace id).
absl::flat_hash_map<int, int64_t> DragTraceIds(const std::vector<SampleRecord>& samples, int first_import_drag);

// Fills out->regions(r).pieces for every region r of `map`; out->regions
// must already hold the map's regions in order (FillMapLevel). A drag not
// among `samples` gets trace_id 0: the plan records a drag before its write
// commits, so a map can hold a trace that was not stored yet when the
// samples were read.
void FillRegionPieces(const RegionMap& map, int first_import_drag, const std::vector<SampleRecord>& samples,
                      v1::MapLevel* out);

}  // namespace surfmap
