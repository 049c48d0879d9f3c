#include "server/codec/fit_json.h"

#include <gtest/gtest.h>
#include "clients/sim/dragsim/drag_geometry.h"
#include "clients/sim/dragsim/drag_simulator.h"

namespace surfmap {
namespace {

TraceFit SplitDragFit() {
  DragSimOptions options;
  options.seed = 7;
  auto sim = SimulateDrag(CylinderGeometry(40.0, 20.0),
                          SplitMaterial(kGlass, kRubber, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()), options);
  EXPECT_TRUE(sim.ok());
  auto fit = FitTrace(sim->trace, FitOptions{});
  EXPECT_TRUE(fit.ok()) << fit.status();
  return *fit;
}

TEST(FitJsonTest, PiecesChangesAndPathRoundTrip) {
  const TraceFit fit = SplitDragFit();
  ASSERT_EQ(fit.pieces.size(), 2u);
  // Through text, as the store keeps it.
  const std::string text = TraceFitToJson(fit).dump();
  auto back = TraceFitFromJson(nlohmann::json::parse(text));
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->changes.size(), fit.changes.size());
  EXPECT_EQ(back->changes[0].index, fit.changes[0].index);
  EXPECT_EQ(back->changes[0].s_mm, fit.changes[0].s_mm);  // round-trip precision
  EXPECT_EQ(back->changes[0].critical_value, fit.changes[0].critical_value);
  ASSERT_EQ(back->pieces.size(), 2u);
  for (int p = 0; p < 2; ++p) {
    const DragPiece& a = fit.pieces[p];
    const DragPiece& b = back->pieces[p];
    EXPECT_EQ(b.start_mm, a.start_mm);
    EXPECT_EQ(b.end_mm, a.end_mm);
    EXPECT_EQ(b.first_pair, a.first_pair);
    EXPECT_EQ(b.pair_count, a.pair_count);
    EXPECT_EQ(b.starts_at_change, a.starts_at_change);
    EXPECT_EQ(b.ends_at_change, a.ends_at_change);
    EXPECT_EQ(b.mu, a.mu);
    EXPECT_EQ(b.mu_se, a.mu_se);
    EXPECT_EQ(b.effective_pairs, a.effective_pairs);
    EXPECT_EQ(b.roughness_state, a.roughness_state);
    EXPECT_EQ(b.roughness.a, a.roughness.a);
    EXPECT_EQ(b.roughness.reflection, a.roughness.reflection);
    EXPECT_EQ(b.roughness.sigma, a.roughness.sigma);
    EXPECT_EQ(b.roughness.stationary, a.roughness.stationary);
  }
  EXPECT_EQ(back->roughness_piece, fit.roughness_piece);
  EXPECT_EQ(back->path.s_mm, fit.path.s_mm);
  ASSERT_EQ(back->path.points.size(), fit.path.points.size());
  EXPECT_EQ(back->path.points.back(), fit.path.points.back());
  // What the plan and the map take from it is the same either way.
  const LineSample a = LineSampleOf(fit), b = LineSampleOf(*back);
  ASSERT_EQ(a.pieces.size(), b.pieces.size());
  EXPECT_EQ(a.pieces[1].texture.reflection, b.pieces[1].texture.reflection);
}

TEST(FitJsonTest, AVersion1FitReadsBackWithoutPieces) {
  TraceFit fit = SplitDragFit();
  nlohmann::json j = TraceFitToJson(fit);
  j.erase("changes");
  j.erase("pieces");
  j.erase("path");
  j.erase("roughness_piece");
  auto back = TraceFitFromJson(j);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_TRUE(back->pieces.empty());
  EXPECT_TRUE(back->changes.empty());
  EXPECT_TRUE(back->path.s_mm.empty());
  EXPECT_EQ(back->friction.mu, fit.friction.mu);
}

TEST(FitJsonTest, MalformedPiecesAreNamed) {
  nlohmann::json j = TraceFitToJson(SplitDragFit());
  j["pieces"][1]["roughness"] = "maybe";
  EXPECT_EQ(TraceFitFromJson(j).status().message(),
            "pieces[1].roughness 'maybe' is not fitted, too_short or fit_failed");
  j = TraceFitToJson(SplitDragFit());
  j["pieces"][0]["mu"] = "high";
  EXPECT_NE(TraceFitFromJson(j).status().message().find("pieces[0]: key 'mu'"), std::string::npos);
  j = TraceFitToJson(SplitDragFit());
  j["path"]["points"].erase(0);
  EXPECT_NE(TraceFitFromJson(j).status().message().find("path: "), std::string::npos);
}

TEST(FitJsonTest, ChangeOptionsRoundTripAndAreValidated) {
  FitOptions options;
  options.changes.false_alarm_probability = 1e-4;
  options.min_roughness_piece_mm = 6.0;
  auto back = FitOptionsFromJson(FitOptionsToJson(options));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->changes.false_alarm_probability, 1e-4);
  EXPECT_EQ(back->min_roughness_piece_mm, 6.0);
  // Options stored before these keys existed read with the defaults.
  auto old = FitOptionsFromJson(nlohmann::json{{"step_mm", 0.1}});
  ASSERT_TRUE(old.ok());
  EXPECT_EQ(old->changes.false_alarm_probability, ChangePointOptions{}.false_alarm_probability);
  EXPECT_EQ(FitOptionsFromJson(nlohmann::json{{"change_false_alarm", 2.0}}).status().message(),
            "changes: false_alarm_probability 2 must be in (0, 1)");
  options.changes.group_spacing_mm = 0.25;
  back = FitOptionsFromJson(FitOptionsToJson(options));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->changes.group_spacing_mm, 0.25);
  EXPECT_EQ(old->changes.group_spacing_mm, ChangePointOptions{}.group_spacing_mm);
  EXPECT_EQ(FitOptionsFromJson(nlohmann::json{{"change_group_spacing_mm", -1.0}}).status().message(),
            "changes: group_spacing_mm -1 must be a finite length >= 0");
}

TEST(FitJsonTest, NoiseReplicatesRoundTripAndAreValidated) {
  FitOptions options;
  options.noise_replicates = 0;  // the white model of estimator version 7
  auto back = FitOptionsFromJson(FitOptionsToJson(options));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->noise_replicates, 0);
  auto old = FitOptionsFromJson(nlohmann::json{{"step_mm", 0.1}});
  ASSERT_TRUE(old.ok());
  EXPECT_EQ(old->noise_replicates, FitOptions{}.noise_replicates);
  EXPECT_EQ(FitOptionsFromJson(nlohmann::json{{"noise_replicates", 65}}).status().message(),
            "noise_replicates must be in 0..64");
}

TEST(FitJsonTest, PairsPerGroupIsKeptWhereThePairsWereGrouped) {
  TraceFit fit = SplitDragFit();  // 100 Hz: not grouped, and no key written
  ASSERT_EQ(fit.pairs_per_group, 1);
  EXPECT_FALSE(TraceFitToJson(fit).contains("pairs_per_group"));
  fit.pairs_per_group = 5;
  auto back = TraceFitFromJson(TraceFitToJson(fit));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->pairs_per_group, 5);
  nlohmann::json j = TraceFitToJson(fit);
  j["pairs_per_group"] = 0;
  EXPECT_EQ(TraceFitFromJson(j).status().message(), "key 'pairs_per_group': 0 must be >= 1");
}

}  // namespace
}  // namespace surfmap
