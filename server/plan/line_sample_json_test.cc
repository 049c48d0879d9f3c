#include "server/plan/line_sample_json.h"

#include <gtest/gtest.h>

namespace surfmap {
namespace {

LineSample RoughLine() {
  LineSample line;
  line.path_s_mm = {0.0, 10.0};
  line.path_points = {{0, 0, 0}, {10, 0, 0}};
  LinePiece piece;
  piece.end_mm = 10.0;
  piece.texture.mu = 0.305;
  piece.texture.mu_std = 0.04;
  piece.texture.reflection = {0.8, 0.25};
  piece.texture.sigma = 0.11;
  piece.mu_se = 0.01;
  piece.effective_pairs = 12.0;
  piece.roughness_rows = 96;
  line.pieces = {piece};
  return line;
}

TEST(LineSampleJsonTest, RoundTripsThePiecesWithTheRowsBehindTheirRoughness) {
  const absl::StatusOr<LineSample> back = LineSampleFromJson(LineSampleToJson(RoughLine()), "line");
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->pieces.size(), 1u);
  EXPECT_EQ(back->pieces[0].roughness_rows, 96);
  EXPECT_EQ(back->pieces[0].texture.reflection, (std::vector<double>{0.8, 0.25}));
  EXPECT_EQ(back->pieces[0].texture.mu, 0.305);
}

TEST(LineSampleJsonTest, RoundTripsThePairSeriesExactlyAndReadsPlansWithoutIt) {
  LineSample line = RoughLine();
  line.pair_s_mm = {0.05, 0.1 + 1e-13, 9.95};
  line.pair_mu = {0.30512345678901234, 0.31, 1.0 / 3.0};
  const absl::StatusOr<LineSample> back = LineSampleFromJson(LineSampleToJson(line), "line");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->pair_s_mm, line.pair_s_mm);  // bit-exact: a replayed plan decides as the original did
  EXPECT_EQ(back->pair_mu, line.pair_mu);
  const nlohmann::json without = LineSampleToJson(RoughLine());
  EXPECT_FALSE(without.contains("ps"));
  const absl::StatusOr<LineSample> old = LineSampleFromJson(without, "line");
  ASSERT_TRUE(old.ok());
  EXPECT_TRUE(old->pair_mu.empty());
  nlohmann::json bad = LineSampleToJson(line);
  bad["pmu"] = {0.3, "x", 0.3};
  EXPECT_NE(LineSampleFromJson(bad, "line").status().message().find("\"pmu\" holds a non-number"), std::string::npos);
  bad = LineSampleToJson(line);
  bad.erase("ps");
  EXPECT_NE(LineSampleFromJson(bad, "line").status().message().find("\"ps\" is missing"), std::string::npos);
  bad = LineSampleToJson(line);
  bad["pmu"] = {0.3};
  EXPECT_NE(LineSampleFromJson(bad, "line").status().message().find("3 pair positions but 1 pair values"),
            std::string::npos);
}

TEST(LineSampleJsonTest, APieceSavedBeforeRowsExistedHasNoRoughnessSignature) {
  nlohmann::json j = LineSampleToJson(RoughLine());
  j["pieces"][0].erase("rows");
  const absl::StatusOr<LineSample> back = LineSampleFromJson(j, "line");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->pieces[0].roughness_rows, 0);
  EXPECT_TRUE(back->pieces[0].has_roughness());  // its roughness is kept for the map's values
}

TEST(LineSampleJsonTest, BadRowsAreRefusedByName) {
  for (const nlohmann::json& bad : {nlohmann::json(-1), nlohmann::json(2.5), nlohmann::json("96")}) {
    nlohmann::json j = LineSampleToJson(RoughLine());
    j["pieces"][0]["rows"] = bad;
    const absl::StatusOr<LineSample> back = LineSampleFromJson(j, "line");
    ASSERT_FALSE(back.ok()) << bad;
    EXPECT_NE(back.status().message().find("line.pieces[0]: \"rows\""), std::string::npos) << back.status();
  }
  // Rows without the roughness fit they would count.
  nlohmann::json j = LineSampleToJson(RoughLine());
  j["pieces"][0]["k"] = nlohmann::json::array();
  j["pieces"][0]["sigma"] = 0.0;
  const absl::StatusOr<LineSample> back = LineSampleFromJson(j, "line");
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.status().message().find("roughness_rows is 96 without a roughness fit"), std::string::npos)
      << back.status();
}

}  // namespace
}  // namespace surfmap
