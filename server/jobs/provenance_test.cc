// Provenance: bounds named on refusal, and the JSON kept in metadata_json
// round-trips exactly (what a lab wrote is what it reads back).
#include "server/jobs/provenance.h"

#include "gtest/gtest.h"
#include "server/base/testing/status_matchers.h"

namespace surfmap {
namespace {

using ::surfmap::status_matchers::IsOk;
using ::surfmap::status_matchers::StatusIs;
using ::testing::HasSubstr;

Provenance Full() {
  Provenance p;
  p.operator_name = "Ana Łukasiewicz";
  p.specimen = "瓶 #3";
  p.probe_tip = "steel ball 3 mm";
  p.sensor = "Nano17 FT12345";
  p.notes = "cleaned with ethanol\nthen dried 10 min";
  p.extra = {{"humidity_pct", "41"}, {"room.temp-C", "21.5"}};
  return p;
}

TEST(ProvenanceTest, RoundTripsThroughTheStoredJson) {
  const Provenance p = Full();
  EXPECT_THAT(ValidateProvenance(p), IsOk());
  absl::StatusOr<Provenance> back = ProvenanceOfMetadata(MetadataJsonOf(p));
  ASSERT_THAT(back.status(), IsOk());
  EXPECT_EQ(*back, p);
  EXPECT_EQ(MetadataJsonOf(Provenance{}), "{}");
  absl::StatusOr<Provenance> none = ProvenanceOfMetadata("{}");
  ASSERT_THAT(none.status(), IsOk());
  EXPECT_TRUE(none->empty());
  // Other keys of the metadata (an import's) do not disturb it.
  absl::StatusOr<Provenance> beside = ProvenanceOfMetadata(R"({"import":{"source":"x"},"provenance":{"sensor":"s"}})");
  ASSERT_THAT(beside.status(), IsOk());
  EXPECT_EQ(beside->sensor, "s");
  EXPECT_THAT(ProvenanceOfMetadata("not json").status(), StatusIs(absl::StatusCode::kDataLoss));
  EXPECT_THAT(ProvenanceOfMetadata(R"({"provenance":{"operator":3}})").status(),
              StatusIs(absl::StatusCode::kDataLoss));
}

TEST(ProvenanceTest, OutOfBoundsIsRefusedNamingTheField) {
  const struct {
    void (*change)(Provenance&);
    const char* expected;
  } cases[] = {
      {[](Provenance& p) { p.operator_name = std::string(201, 'a'); }, "provenance operator"},
      {[](Provenance& p) { p.specimen = "two\nlines"; }, "provenance specimen"},
      {[](Provenance& p) { p.probe_tip = std::string("\xff"); }, "provenance probe_tip"},
      {[](Provenance& p) { p.sensor = std::string(300, 'x'); }, "provenance sensor"},
      {[](Provenance& p) { p.notes = std::string(4001, 'n'); }, "provenance notes: 4001 characters; the limit is 4000"},
      {[](Provenance& p) { p.notes = std::string("\xc3"); }, "provenance notes: not valid UTF-8"},
      {[](Provenance& p) { p.extra[""] = "v"; }, "must have 1..64 characters"},
      {[](Provenance& p) { p.extra[std::string(65, 'k')] = "v"; }, "must have 1..64 characters"},
      {[](Provenance& p) { p.extra["white space"] = "v"; }, "only letters, digits"},
      {[](Provenance& p) { p.extra["k"] = std::string(201, 'v'); }, "provenance extra 'k'"},
      {[](Provenance& p) {
         for (int i = 0; i < 33; ++i) p.extra["k" + std::to_string(i)] = "v";
       },
       "provenance extra: 33 keys; the limit is 32"},
  };
  for (const auto& c : cases) {
    Provenance p;
    c.change(p);
    EXPECT_THAT(ValidateProvenance(p), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr(c.expected)));
  }
  Provenance at_limits;
  at_limits.operator_name = std::string(200, 'a');
  at_limits.notes = std::string(4000, 'n');
  for (int i = 0; i < 32; ++i) at_limits.extra["k" + std::to_string(i)] = std::string(200, 'v');
  EXPECT_THAT(ValidateProvenance(at_limits), IsOk());
}

}  // namespace
}  // namespace surfmap
