#include "server/service/region_pieces_proto.h"

#include <gtest/gtest.h>

namespace surfmap {
namespace {

SampleRecord Leased(int64_t trace, int64_t vertex) {
  SampleRecord s;
  s.trace.id = trace;
  s.command.site_vertex = vertex;
  return s;
}

SampleRecord Imported(int64_t trace, int64_t nearest_vertex) {
  SampleRecord s = Leased(trace, nearest_vertex);
  s.trace.import_sha256 = "ab" + std::to_string(trace);
  return s;
}

TEST(DragTraceIdsTest, SitesByVertexImportsByTheirOrderOfArrival) {
  // The plan numbers imports from 100 in the order it recorded them, which
  // is the order their traces were stored; a list may come in any order,
  // and an import's nearest vertex may be a measured site's.
  const std::vector<SampleRecord> samples = {Leased(5, 7), Imported(9, 7), Leased(6, 3), Imported(8, 40)};
  const absl::flat_hash_map<int, int64_t> ids = DragTraceIds(samples, 100);
  EXPECT_EQ(ids.size(), 4u);
  EXPECT_EQ(ids.at(7), 5);
  EXPECT_EQ(ids.at(3), 6);
  EXPECT_EQ(ids.at(100), 8);
  EXPECT_EQ(ids.at(101), 9);
}

}  // namespace
}  // namespace surfmap
