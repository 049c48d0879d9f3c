// Stored metadata into the answer: a damaged row (a wrong type where a string
// or a time belongs, not JSON at all) is left out field by field, never thrown
// out of the handler (which would fail a whole ListSamples or GetMap).
#include "server/service/provenance_proto.h"

#include "gtest/gtest.h"

namespace surfmap {
namespace {

TEST(FillMetadataTest, ReadsWhatAnImportStored) {
  pb::Provenance provenance;
  pb::ImportInfo import;
  FillMetadata(R"({"provenance": {"operator": "A. Lloyd"},
                   "import": {"source": "arm-2", "file_name": "d.csv", "file_sha256": "ab",
                              "recorded_unix_ms": 1790000000000}})",
               1790000100000, &provenance, &import);
  EXPECT_EQ(provenance.operator_name(), "A. Lloyd");
  EXPECT_EQ(import.source(), "arm-2");
  EXPECT_EQ(import.file_name(), "d.csv");
  EXPECT_EQ(import.recorded().seconds(), 1790000000);
  EXPECT_EQ(import.imported().seconds(), 1790000100);
}

TEST(FillMetadataTest, WrongTypesAreLeftOutFieldByFieldWithoutThrowing) {
  pb::Provenance provenance;
  pb::ImportInfo import;
  EXPECT_NO_THROW(FillMetadata(R"({"import": {"source": 5, "file_name": "d.csv", "file_sha256": ["x"],
                                              "recorded_unix_ms": "yesterday"}})",
                               1790000100000, &provenance, &import));
  EXPECT_EQ(import.source(), "");
  EXPECT_EQ(import.file_name(), "d.csv");
  EXPECT_EQ(import.file_sha256(), "");
  EXPECT_FALSE(import.has_recorded());
  EXPECT_TRUE(import.has_imported());
  pb::ImportInfo far;
  EXPECT_NO_THROW(FillMetadata(R"({"import": {"source": "s", "recorded_unix_ms": 99999999999999999}})", 1, nullptr,
                               &far));
  EXPECT_FALSE(far.has_recorded());
  pb::ImportInfo none;
  EXPECT_NO_THROW(FillMetadata("not json", 1, &provenance, &none));
  EXPECT_EQ(none.source(), "");
}

}  // namespace
}  // namespace surfmap
