#include "server/estimate/drag_pieces.h"

#include <cmath>

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
