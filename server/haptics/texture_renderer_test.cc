#include "server/haptics/texture_renderer.h"

#include <atomic>
#include <cstdlib>
#include <new>

#include <gtest/gtest.h>
#include "server/haptics/test_meshes.h"

// Counting global allocation functions for this test binary: the renderer's
// per-sample call must not allocate (a haptic loop cannot wait on malloc).
namespace {
std::atomic<long> g_allocations{0};
}
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, std::align_val_t align) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  const std::size_t a = static_cast<std::size_t>(align);
  if (void* p = std::aligned_alloc(a, (size + a - 1) / a * a)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size, std::align_val_t align) { return operator new(size, align); }
// GCC (-O1 and up) inlines gtest's `new TestClass` into the sized delete
// below and warns that free() meets operator new; both are the replacements
// above, which do pair malloc with free.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

namespace surfmap::haptics {
namespace {

std::unique_ptr<TextureRenderer> SplitPlate() {
  TextureMap map = testing::FlatPlate(40, 40.0);  // 1 mm cells
  testing::PaintSplit(map, 20.0, testing::kRubber, testing::kMasonite);
  absl::StatusOr<std::unique_ptr<TextureRenderer>> r = TextureRenderer::Create(std::move(map));
  EXPECT_TRUE(r.ok()) << r.status();
  return *std::move(r);
}

// Coulomb friction of the local material, against the tangential velocity;
// the roughness force on the same line.
TEST(TextureRendererTest, FrictionOpposesTheVelocityWithTheLocalMu) {
  auto renderer = SplitPlate();
  ProbeState state;
  const Eigen::Vector3d v(3.0, 4.0, 2.0);  // the normal part (z) is ignored
  ContactSample left = renderer->Sample(state, {10.0, 10.0, 0.05}, v, 5.0);
  ASSERT_TRUE(left.in_contact);
  EXPECT_DOUBLE_EQ(left.mu, testing::kRubber.mu);
  const Eigen::Vector3d u = Eigen::Vector3d(3, 4, 0).normalized();
  EXPECT_NEAR((left.friction_force + testing::kRubber.mu * 5.0 * u).norm(), 0.0, 1e-12);
  EXPECT_NEAR((left.roughness_force + left.roughness_n * u).norm(), 0.0, 1e-12);
  EXPECT_EQ(left.region, 0);
  state.Reset();
  ContactSample right = renderer->Sample(state, {30.0, 10.0, -0.05}, v, 5.0);
  EXPECT_DOUBLE_EQ(right.mu, testing::kMasonite.mu);
  EXPECT_EQ(right.region, 1);
  EXPECT_NEAR(right.sigma, testing::kMasonite.sigma, 1e-12);
  // No sliding, no direction: no tangential force.
  ContactSample still = renderer->Sample(state, {30.0, 10.0, -0.05}, Eigen::Vector3d::Zero(), 5.0);
  EXPECT_EQ(still.tangential_force.norm(), 0.0);
  // Lifted off: out of contact.
  ContactSample lifted = renderer->Sample(state, {30.0, 10.0, 5.0}, v, 5.0);
  EXPECT_FALSE(lifted.in_contact);
  EXPECT_EQ(lifted.tangential_force.norm(), 0.0);
}

// Materials do not blend: across the boundary triangles (vertices at x = 19
// are rubber, at x = 20 masonite) the friction jumps from one material's to
// the other's where the nearest vertex changes; plain interpolation blends.
TEST(TextureRendererTest, SharpRegionsDoNotBlendMaterials) {
  auto renderer = SplitPlate();
  ProbeState state;
  EXPECT_DOUBLE_EQ(renderer->Sample(state, {19.4, 10.2, 0}, {1, 0, 0}, 5.0).mu, testing::kRubber.mu);
  state.Reset();
  EXPECT_DOUBLE_EQ(renderer->Sample(state, {19.6, 10.2, 0}, {1, 0, 0}, 5.0).mu, testing::kMasonite.mu);
  TextureMap map = testing::FlatPlate(40, 40.0);
  testing::PaintSplit(map, 20.0, testing::kRubber, testing::kMasonite);
  TextureRendererOptions blend;
  blend.sharp_regions = false;
  auto blended = *TextureRenderer::Create(std::move(map), blend);
  state.Reset();
  const double mu = blended->Sample(state, {19.5, 10.5, 0}, {1, 0, 0}, 5.0).mu;
  EXPECT_GT(mu, testing::kMasonite.mu + 0.01);
  EXPECT_LT(mu, testing::kRubber.mu - 0.01);
}

// The texture belongs to the place: slide 10 mm, stop, slide back; each
// place gives the same roughness force both ways, and standing still keeps it.
TEST(TextureRendererTest, GoingBackFeelsTheSameTexture) {
  auto renderer = SplitPlate();
  ProbeState state;
  const double step = 0.04;  // mm per sample: s / 0.1 mm is never a rounding tie
  std::vector<double> forward;
  for (int i = 0; i <= 250; ++i) {
    forward.push_back(renderer->Sample(state, {5.0 + i * step, 12.0, 0.0}, {10, 0, 0}, 5.0).roughness_n);
  }
  const double at_end = forward.back();
  for (int i = 0; i < 50; ++i) {
    EXPECT_EQ(renderer->Sample(state, {15.0, 12.0, 0.0}, {0, 0, 0}, 5.0).roughness_n, at_end);
  }
  for (int i = 250; i >= 0; --i) {
    // Positions repeat exactly, so do the arc lengths up to rounding: the same cell.
    EXPECT_EQ(renderer->Sample(state, {5.0 + i * step, 12.0, 0.0}, {-10, 0, 0}, 5.0).roughness_n, forward[i])
        << "sample " << i;
  }
  // The texture is not constant (sigma 0.11 N): it does vary along the stroke.
  double lo = forward[0], hi = forward[0];
  for (double r : forward) {
    lo = std::min(lo, r);
    hi = std::max(hi, r);
  }
  EXPECT_GT(hi - lo, 0.1);
}

// Arc length follows a curved stroke on a curved surface: a quarter of the
// equator of a 20 mm sphere is 31.4 mm.
TEST(TextureRendererTest, ArcLengthFollowsTheSurface) {
  TextureMap sphere = testing::Sphere(20.0, 48, 96);
  testing::PaintSplit(sphere, 1e9, testing::kRubber, testing::kRubber);
  auto renderer = TextureRenderer::Create(std::move(sphere));
  ASSERT_TRUE(renderer.ok());
  ProbeState state;
  ContactSample c;
  for (int i = 0; i <= 1000; ++i) {
    const double ph = std::numbers::pi / 2 * i / 1000;
    c = (*renderer)->Sample(state, {20.2 * std::cos(ph), 20.2 * std::sin(ph), 0.0}, {-std::sin(ph), std::cos(ph), 0}, 1.0);
  }
  // The mesh's chords are shorter than the arc: 96 segments on the circle
  // give 2 pi r * (sin(pi/96) / (pi/96)) = 0.99982 of it.
  EXPECT_NEAR(c.arc_length_mm, 20.0 * std::numbers::pi / 2, 0.02);
}

// Sample() allocates nothing: 10^5 samples sliding back and forth across the
// material boundary (the model changes, the impulse is recomputed in place).
TEST(TextureRendererTest, SampleDoesNotAllocate) {
  auto renderer = SplitPlate();
  ProbeState state;
  double sum = 0.0;
  const long before = g_allocations.load();
  for (int i = 0; i < 100000; ++i) {
    const double x = 20.0 + 8.0 * std::sin(i * 1e-3);
    const ContactSample c = renderer->Sample(state, {x, 15.0 + 1e-5 * i, 0.01}, {8.0 * std::cos(i * 1e-3), 0, 0}, 4.0);
    sum += c.tangential_force.x();
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_TRUE(std::isfinite(sum));
  // The counter does count: creating a renderer allocates.
  const long before_create = g_allocations.load();
  auto another = SplitPlate();
  EXPECT_GT(g_allocations.load() - before_create, 0);
}

TEST(TextureRendererTest, RejectsAnInvalidMap) {
  TextureMap map = testing::FlatPlate(2, 1.0);
  map.mu.pop_back();
  EXPECT_EQ(TextureRenderer::Create(map).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace surfmap::haptics
