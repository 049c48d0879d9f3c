#include "server/haptics/model_drag.h"

#include <gtest/gtest.h>
#include "server/haptics/test_meshes.h"
#include "server/estimate/fit_trace.h"

namespace surfmap::haptics {
namespace {

std::unique_ptr<TextureRenderer> RubberPlate() {
  TextureMap map = testing::FlatPlate(60, 60.0);
  testing::PaintSplit(map, 1e9, testing::kRubber, testing::kRubber);  // all rubber
  return *TextureRenderer::Create(std::move(map));
}

// A drag rendered over the model reads back, through the same estimator as a
// measured trace, as the model's texture: the trace format and the texture
// are right. 40 mm at 0.1 mm per sample: ~320 roughness points per pass in
// the window; Burg's standard errors ~sqrt((1 - a2^2) / n) ~ 0.05, so 0.15 is
// 3 of them; mu's error comes from the texture riding on the friction
// (process std 0.2 N on 5 N, correlated over ~1 mm): ~0.01, tolerance 0.03.
TEST(ModelDragTest, EstimatorRecoversTheModel) {
  auto renderer = RubberPlate();
  absl::StatusOr<std::vector<Eigen::Vector3d>> path =
      TraceModelPath(*renderer, {10.0, 30.0, 0.5}, {1.0, 0.0, 0.3}, 40.0, 0.25);
  ASSERT_TRUE(path.ok()) << path.status();
  EXPECT_NEAR((path->back() - Eigen::Vector3d(50.0, 30.0, 0.0)).norm(), 0.0, 1e-6);
  ModelDragOptions options;
  absl::StatusOr<ModelDrag> drag = RenderDragAlongPath(*renderer, *path, options);
  ASSERT_TRUE(drag.ok()) << drag.status();
  // 401 forward, 50 pause, 401 reverse samples.
  EXPECT_EQ(drag->trace.samples.size(), 401u + 50u + 401u);
  absl::StatusOr<TraceFit> fit = FitTrace(drag->trace, FitOptions{});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR(fit->friction.mu, testing::kRubber.mu, 0.03);
  ASSERT_EQ(fit->roughness.a.size(), 2u);
  EXPECT_NEAR(fit->roughness.a[0], testing::kRubber.a1, 0.15);
  EXPECT_NEAR(fit->roughness.a[1], testing::kRubber.a2, 0.15);
  EXPECT_NEAR(fit->roughness.sigma / testing::kRubber.sigma, 1.0, 0.2);
}

// The reverse pass feels the forward pass's texture at the same places.
TEST(ModelDragTest, ReversePassRetracesTheTexture) {
  auto renderer = RubberPlate();
  std::vector<Eigen::Vector3d> path = {{10, 20, 0}, {30, 20, 0}};
  absl::StatusOr<ModelDrag> drag = RenderDragAlongPath(*renderer, path, ModelDragOptions{});
  ASSERT_TRUE(drag.ok());
  const size_t n = drag->trace.samples.size();
  const size_t pass = 201;  // 20 mm / 0.1 mm + 1
  ASSERT_EQ(n, 2 * pass + 50);
  for (size_t i = 0; i < pass; ++i) {
    const size_t back = n - 1 - i;
    EXPECT_EQ(drag->trace.samples[back].phase, DragPhase::kReverse);
    EXPECT_NEAR((drag->trace.samples[i].position - drag->trace.samples[back].position).norm(), 0.0, 1e-9);
    EXPECT_NEAR(drag->roughness_n[i], drag->roughness_n[back], 1e-12) << i;
  }
}

// The path is bounded by its step count as well as its distance: 10 mm at
// 1 mm steps on the plate is exactly 10 steps (11 points), so a cap of 10
// passes and a cap of 9 fails up front; on the curved sphere (radius 15 mm,
// coarse facets) the re-projected steps come out shorter than 1 mm, so 10 mm
// needs more than 10 of them and the cap stops the walk itself.
TEST(ModelDragTest, PathStepsAreBounded) {
  auto plate = RubberPlate();
  absl::StatusOr<std::vector<Eigen::Vector3d>> path = TraceModelPath(*plate, {10, 30, 0}, {1, 0, 0}, 10.0, 1.0, 10);
  ASSERT_TRUE(path.ok()) << path.status();
  EXPECT_EQ(path->size(), 11u);
  EXPECT_EQ(TraceModelPath(*plate, {10, 30, 0}, {1, 0, 0}, 10.0, 1.0, 9).status().code(),
            absl::StatusCode::kInvalidArgument);
  TextureMap sphere_map = testing::Sphere(15.0, 8, 12);
  testing::PaintSplit(sphere_map, 1e9, testing::kRubber, testing::kRubber);
  auto sphere = *TextureRenderer::Create(std::move(sphere_map));
  const absl::StatusOr<std::vector<Eigen::Vector3d>> capped =
      TraceModelPath(*sphere, {15, 0, 0}, {0, 1, 0.2}, 10.0, 1.0, 10);
  EXPECT_EQ(capped.status().code(), absl::StatusCode::kFailedPrecondition) << capped.status();
  EXPECT_TRUE(TraceModelPath(*sphere, {15, 0, 0}, {0, 1, 0.2}, 10.0, 1.0, 100).ok());
}

TEST(ModelDragTest, RejectsBadInput) {
  auto renderer = RubberPlate();
  EXPECT_EQ(RenderDragAlongPath(*renderer, {{1, 1, 0}}, {}).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(RenderDragAlongPath(*renderer, {{1, 1, 0}, {5, 1, 9}}, {}).status().code(),
            absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(TraceModelPath(*renderer, {1, 1, 0}, {0, 0, 1}, 5.0).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(TraceModelPath(*renderer, {1, 1, 30}, {1, 0, 0}, 5.0).status().code(),
            absl::StatusCode::kFailedPrecondition);
}

}  // namespace
}  // namespace surfmap::haptics
