#include "server/estimate/line_sample.h"

#include <cmath>

#include <gtest/gtest.h>
#include "clients/sim/dragsim/drag_geometry.h"
#include "clients/sim/dragsim/drag_simulator.h"

namespace surfmap {
namespace {

LineSample TwoPieceLine() {
  LineSample line;
  line.path_s_mm = {2.0, 3.0, 4.0, 4.5};
  line.path_points = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2.5, 0, 0}};
  LinePiece a, b;
  a.start_mm = 2.0;
  a.end_mm = 3.4;
  a.texture.mu = 0.1;
  b.start_mm = 3.4;
  b.end_mm = 4.5;
  b.texture.mu = 0.5;
  line.pieces = {a, b};
  return line;
}

TEST(LineSampleTest, PointsAlongThePath) {
  const LineSample line = TwoPieceLine();
  EXPECT_TRUE(line.PointAt(3.5).isApprox(Eigen::Vector3d(1.5, 0, 0)));
  EXPECT_TRUE(line.PointAt(-1.0).isApprox(Eigen::Vector3d(0, 0, 0)));   // clamped
  EXPECT_TRUE(line.PointAt(9.0).isApprox(Eigen::Vector3d(2.5, 0, 0)));
  const std::vector<Eigen::Vector3d> between = line.PointsBetween(2.5, 4.2);
  ASSERT_EQ(between.size(), 4u);  // 2.5, the path points at 3 and 4, 4.2
  EXPECT_NEAR(between.front().x(), 0.5, 1e-12);
  EXPECT_NEAR(between[1].x(), 1.0, 1e-12);
  EXPECT_NEAR(between.back().x(), 2.2, 1e-12);
  EXPECT_TRUE(line.PointsBetween(4.0, 3.0).empty());
  EXPECT_TRUE(line.Validate().ok()) << line.Validate();
}

TEST(LineSampleTest, ValidateNamesWhatIsWrong) {
  LineSample line = TwoPieceLine();
  line.pieces[1].start_mm = 3.0;
  EXPECT_EQ(line.Validate().message(), "line sample: piece 1: starts before piece 0 ends");
  line = TwoPieceLine();
  line.pieces[0].texture.reflection = {1.2};
  EXPECT_EQ(line.Validate().message(),
            "line sample: piece 0: reflection coefficient k1 is 1.2 (a stationary model needs |k| < 1)");
  line = TwoPieceLine();
  line.pieces[1].end_mm = 7.0;
  EXPECT_EQ(line.Validate().code(), absl::StatusCode::kInvalidArgument);
  line = TwoPieceLine();
  line.path_points.pop_back();
  EXPECT_EQ(line.Validate().message(), "line sample: 4 path positions but 3 points");
  EXPECT_EQ(LineSample{}.Validate().message(), "line sample: the path has no point");
  line = TwoPieceLine();
  line.pieces[0].roughness_rows = 40;
  EXPECT_EQ(line.Validate().message(), "line sample: piece 0: roughness_rows is 40 without a roughness fit");
  line.pieces[0].roughness_rows = -1;
  EXPECT_EQ(line.Validate().message(), "line sample: piece 0: roughness_rows is -1");
  line = TwoPieceLine();
  line.pair_s_mm = {1.0, 2.0};
  line.pair_mu = {0.3};
  EXPECT_EQ(line.Validate().message(), "line sample: 2 pair positions but 1 pair values");
  line.pair_mu = {0.3, std::nan("")};
  EXPECT_EQ(line.Validate().message(), "line sample: pair 1 is not finite");
  line.pair_s_mm = {2.0, 1.0};
  line.pair_mu = {0.3, 0.3};
  EXPECT_EQ(line.Validate().message(), "line sample: pair position 1 (1 mm) is before the previous one");
}

TEST(LineSampleTest, OfAFitCarriesItsPathAndPieces) {
  DragSimOptions options;
  options.seed = 4;
  auto sim = SimulateDrag(PlaneGeometry({-10, 0, 0}, {1, 0, 0}, {0, 0, 1}, 20.0),
                          SplitMaterial(kGlass, kRubber, {1, 0, 0}, {1, 0, 0}), options);
  ASSERT_TRUE(sim.ok());
  auto fit = FitTrace(sim->trace, FitOptions{});
  ASSERT_TRUE(fit.ok());
  const LineSample line = LineSampleOf(*fit);
  ASSERT_TRUE(line.Validate().ok()) << line.Validate();
  ASSERT_EQ(line.pieces.size(), 2u);
  EXPECT_TRUE(line.pieces[0].ends_at_change);
  EXPECT_TRUE(line.pieces[1].starts_at_change);
  // The change on the object: at x = 1 mm, to ~0.15 mm (pair spacing 0.1 mm,
  // position noise 0.005 mm).
  EXPECT_NEAR(line.PointAt(line.pieces[0].end_mm).x(), 1.0, 0.15);
  EXPECT_TRUE(line.pieces[1].has_roughness());  // rubber, ~7 mm: fitted
  // The per-pair series behind the pieces, as the fit has it.
  EXPECT_EQ(line.pair_mu, fit->friction.pair_mu);
  EXPECT_EQ(line.pair_s_mm, fit->friction.pair_s_mm);
  EXPECT_NEAR(line.pieces[0].texture.mu, kGlass.mu, 0.003);
  // The rows behind a roughness fit are one pass's values; a fit below the
  // noise floor (glass) has none, its shape being the sensor's.
  const DragPiece& rubber = fit->pieces[1];
  ASSERT_FALSE(rubber.roughness.below_noise_floor);
  EXPECT_EQ(line.pieces[1].roughness_rows, rubber.roughness.n / 2);
  EXPECT_GT(line.pieces[1].roughness_rows, 30);  // ~7 mm at 0.1 mm
  if (fit->pieces[0].roughness.below_noise_floor) {
    EXPECT_EQ(line.pieces[0].roughness_rows, 0);
  }
}

TEST(LineSampleTest, AFitWithoutPiecesIsOnePieceOverTheWindow) {
  TraceFit fit;
  fit.friction.mu = 0.2;
  fit.friction.mu_std = 0.04;
  fit.friction.n_pairs = 100;
  fit.friction.window_start_mm = 2.0;
  fit.friction.window_end_mm = 18.0;
  const LineSample line = LineSampleOf(fit);
  ASSERT_EQ(line.pieces.size(), 1u);
  EXPECT_DOUBLE_EQ(line.pieces[0].start_mm, 2.0);
  EXPECT_DOUBLE_EQ(line.pieces[0].mu_se, 0.004);
  EXPECT_TRUE(line.path_s_mm.empty());
  const LineSample point = PointLineSample({1, 2, 3}, fit.pieces.empty() ? TextureOf(fit) : TextureParams{});
  ASSERT_TRUE(point.Validate().ok()) << point.Validate();
  EXPECT_NEAR(point.pieces[0].mu_se, 0.04 / std::sqrt(kPointSampleEffectivePairs), 1e-15);
}

}  // namespace
}  // namespace surfmap
