#include "clients/haptics/scene/scene_texture_map.h"

#include <random>

#include <gtest/gtest.h>
#include "server/haptics/texture_renderer.h"

namespace surfmap::haptics {
namespace {

class BottleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    absl::StatusOr<Scene> scene = LoadSceneByName("bottle");
    ASSERT_TRUE(scene.ok()) << scene.status();
    scene_ = *std::move(scene);
    auto surface = LoopSurface::Create(scene_.mesh, 3);
    ASSERT_TRUE(surface.ok()) << surface.status();
    surface_ = *std::move(surface);
  }
  Scene scene_;
  std::unique_ptr<LoopSurface> surface_;
};

// The grid lookup is exact on a real map mesh: the same distance as the mesh
// module's BVH over the same (finest, limit) triangles.
TEST_F(BottleTest, LookupAgreesWithTheMeshModule) {
  auto renderer = TextureRenderer::Create(SceneTruthTextureMap(scene_, *surface_, 3));
  ASSERT_TRUE(renderer.ok()) << renderer.status();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-60.0, 60.0), h(-10.0, 150.0);
  ProbeState state;
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d q(u(rng), u(rng), h(rng));
    const SurfaceLookup ours = (*renderer)->Locate(q, state);
    const SurfacePoint theirs = surface_->ClosestPoint(q);
    // 1e-9 mm: both are exact closest points on the same triangles.
    EXPECT_NEAR(ours.distance_mm, theirs.distance, 1e-9) << q.transpose();
  }
}

// The renderer feels the scene's materials: sandpaper in the middle of the
// first patch (angle 0, height 45 mm on the 40 mm body), glass opposite.
TEST_F(BottleTest, FrictionIsTheTrueMaterial) {
  auto renderer = TextureRenderer::Create(SceneTruthTextureMap(scene_, *surface_, 3));
  ASSERT_TRUE(renderer.ok());
  ProbeState state;
  const ContactSample patch = (*renderer)->Sample(state, {40.0, 0.0, 45.0}, {0, 10, 0}, 2.0);
  const Material& sandpaper = scene_.materials[scene_.FindMaterial("sandpaper")];
  EXPECT_DOUBLE_EQ(patch.mu, sandpaper.mu);
  EXPECT_NEAR(patch.sigma, sandpaper.sigma, 1e-12);
  EXPECT_NEAR(patch.friction_force.norm(), sandpaper.mu * 2.0, 1e-12);
  state.Reset();
  const ContactSample glass = (*renderer)->Sample(state, {-40.0, 0.0, 45.0}, {0, 10, 0}, 2.0);
  EXPECT_DOUBLE_EQ(glass.mu, scene_.materials[scene_.FindMaterial("glass")].mu);
}

}  // namespace
}  // namespace surfmap::haptics
