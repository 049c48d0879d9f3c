#include "server/estimate/drag_pieces.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace surfmap {
namespace {

// 100 pairs 0.1 mm apart from s = 2 mm: 0.1 for the first 40, 0.5 after,
// with an alternating +-0.01 ripple (spread 0.01, no serial correlation to
// model beyond it).
FrictionFit StepFit() {
  FrictionFit f;
  f.window_start_mm = 1.95;
  f.window_end_mm = 11.95;
  for (int i = 0; i < 100; ++i) {
    f.pair_s_mm.push_back(2.0 + 0.1 * i);
    f.pair_mu.push_back((i < 40 ? 0.1 : 0.5) + (i % 2 ? 0.01 : -0.01));
  }
  f.n_pairs = 100;
  return f;
}

TEST(DragPiecesTest, CutsAtTheChangesWithTheirExtentsAndStatistics) {
  const FrictionFit f = StepFit();
  auto pieces = CutDragPieces(f, {ChangePoint{40, 5.95, 100.0, 20.0}});
  ASSERT_TRUE(pieces.ok()) << pieces.status();
  ASSERT_EQ(pieces->size(), 2u);
  const DragPiece& a = (*pieces)[0];
  const DragPiece& b = (*pieces)[1];
  // The pair on each side of the change is transitional: left out.
  EXPECT_EQ(a.first_pair, 0);
  EXPECT_EQ(a.pair_count, 39);
  EXPECT_EQ(b.first_pair, 41);
  EXPECT_EQ(b.pair_count, 59);
  EXPECT_DOUBLE_EQ(a.start_mm, 1.95);  // the window's start
  EXPECT_DOUBLE_EQ(a.end_mm, 5.95);    // the change
  EXPECT_DOUBLE_EQ(b.start_mm, 5.95);
  EXPECT_DOUBLE_EQ(b.end_mm, 11.95);   // the window's end
  EXPECT_FALSE(a.starts_at_change);
  EXPECT_TRUE(a.ends_at_change);
  EXPECT_TRUE(b.starts_at_change);
  EXPECT_FALSE(b.ends_at_change);
  // 39 values of the ripple: 20 at -0.01, 19 at +0.01.
  EXPECT_NEAR(a.mu, 0.1 - 0.01 / 39.0, 1e-12);
  EXPECT_NEAR(b.mu, 0.5 + 0.01 / 59.0, 1e-12);
  EXPECT_NEAR(a.mu_median, 0.09, 1e-12);
  // A negatively correlated ripple is never credited with more than
  // independent pairs, and no piece with more than kMaxIndependentPairsPerMm
  // per mm of its pairs' extent (2.0 .. 5.8 mm here): se = spread / sqrt(n_eff).
  const double capped = kMaxIndependentPairsPerMm * (5.8 - 2.0);
  EXPECT_NEAR(a.effective_pairs, capped, 1e-9);
  EXPECT_NEAR(a.mu_se, a.mu_std / std::sqrt(capped), 1e-12);
  EXPECT_EQ(a.roughness_state, PieceRoughness::kTooShort);  // left for FitTrace
}

// Masonite's texture as the simulator makes it (AR(2) 1.6, -0.75 on the
// 0.1 mm grid, seeded) plus white sensor noise on every pair: sampled at
// 0.1 mm, or at 0.02 mm with each texture value held for five pairs, as a
// 500 Hz rig at 10 mm/s samples a 0.1 mm texture grid.
FrictionFit MasoniteLikeTexture(int repeat) {
  std::mt19937_64 texture_rng(7), noise_rng(11);
  std::normal_distribution<double> innovation(0.0, 0.04), noise(0.0, 0.005);
  FrictionFit f;
  f.window_start_mm = 0.0;
  f.window_end_mm = 16.0;
  double x1 = 0.0, x2 = 0.0;
  for (int i = 0; i < 160; ++i) {
    const double x = 1.6 * x1 - 0.75 * x2 + innovation(texture_rng);
    x2 = x1, x1 = x;
    for (int r = 0; r < repeat; ++r) {
      f.pair_s_mm.push_back(0.1 * i + 0.1 / repeat * r);
      f.pair_mu.push_back(0.36 + x + noise(noise_rng));
    }
  }
  f.n_pairs = static_cast<int>(f.pair_mu.size());
  return f;
}

TEST(DragPiecesTest, AFastRigsPieceIsCreditedWhatTheTextureGridHolds) {
  auto slow = CutDragPieces(MasoniteLikeTexture(1), {});
  auto fast = CutDragPieces(MasoniteLikeTexture(5), {}, kChangeGuardPairs, 5);
  auto fast_ungrouped = CutDragPieces(MasoniteLikeTexture(5), {});
  ASSERT_TRUE(slow.ok() && fast.ok() && fast_ungrouped.ok());
  const DragPiece& s = slow->front();
  const DragPiece& f = fast->front();
  const DragPiece& u = fast_ungrouped->front();
  // Grouped, each five held values are one texture value again: the piece
  // is credited what the 0.1 mm series holds (measured 9.99 against 9.94
  // independent pairs, se 0.0462 against 0.0464; 3 % allowed, the cap's
  // extent and the noise averaged in a group differ a little).
  EXPECT_NEAR(f.mu, s.mu, 0.002);
  EXPECT_NEAR(f.effective_pairs, s.effective_pairs, 0.03 * s.effective_pairs);
  EXPECT_NEAR(f.mu_se, s.mu_se, 0.03 * s.mu_se);
  // Ungrouped, an AR(2) on the held values overstates their dependence
  // (measured 8.0 independent pairs, se 1.11x): why the groups are used.
  EXPECT_LT(u.effective_pairs, 0.9 * s.effective_pairs);
  EXPECT_GT(u.mu_se, 1.05 * s.mu_se);
}

TEST(DragPiecesTest, NoChangeIsOnePieceOverTheWindow) {
  auto pieces = CutDragPieces(StepFit(), {});
  ASSERT_TRUE(pieces.ok());
  ASSERT_EQ(pieces->size(), 1u);
  EXPECT_EQ((*pieces)[0].pair_count, 100);
  EXPECT_DOUBLE_EQ((*pieces)[0].length_mm(), 10.0);
}

TEST(DragPiecesTest, RejectsChangesOutOfOrderOrRange) {
  const FrictionFit f = StepFit();
  EXPECT_EQ(CutDragPieces(f, {ChangePoint{40, 6, 1, 1}, ChangePoint{30, 5, 1, 1}}).status().message(),
            "drag pieces: change 1 at pair 30 is out of order or outside 1..99");
  EXPECT_EQ(CutDragPieces(f, {ChangePoint{100, 12, 1, 1}}).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(CutDragPieces(FrictionFit{}, {}).status().message(),
            "drag pieces: the friction fit has 0 per-pair values and 0 positions");
}

}  // namespace
}  // namespace surfmap
