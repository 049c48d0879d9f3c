#include "clients/sim/rig/simulated_rig.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include "server/estimate/fit_trace.h"

namespace surfmap {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// One bottle rig for the whole suite: refining the surface is the slow part.
class BottleRigTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto scene = LoadSceneByName("bottle");
    ASSERT_TRUE(scene.ok()) << scene.status();
    auto rig = SimulatedRig::Create(*std::move(scene));
    ASSERT_TRUE(rig.ok()) << rig.status();
    rig_ = rig->release();
  }
  void SetUp() override { ASSERT_NE(rig_, nullptr) << "the bottle rig could not be built"; }
  static void TearDownTestSuite() {
    delete rig_;
    rig_ = nullptr;
  }

  // A point on the body at `deg` about the axis and height z, with a
  // horizontal (counter-clockwise) or vertical (upward) drag direction.
  static ProbeRequest BodyProbe(double deg, double z, bool horizontal, std::int64_t id) {
    ProbeRequest r;
    const Eigen::Vector3d radial(std::cos(deg * kDeg), std::sin(deg * kDeg), 0);
    r.position = 40.0 * radial + Eigen::Vector3d(0, 0, z);
    r.normal = radial;
    r.drag_direction = horizontal ? Eigen::Vector3d(-radial.y(), radial.x(), 0) : Eigen::Vector3d::UnitZ();
    r.command_id = id;
    return r;
  }

  static TraceFit Fit(const DragTrace& trace) {
    absl::StatusOr<TraceFit> fit = FitTrace(trace, FitOptions{});
    EXPECT_TRUE(fit.ok()) << fit.status();
    return fit.ok() ? *fit : TraceFit{};
  }

  static SimulatedRig* rig_;
};
SimulatedRig* BottleRigTest::rig_ = nullptr;

TEST_F(BottleRigTest, GlassAroundTheCurvedBodyFitsMu013) {
  // 20 mm around a 40 mm radius: the normal turns by ~29 degrees.
  for (std::int64_t id : {1, 2, 3}) {
    auto execution = rig_->ExecuteDetailed(BodyProbe(195.0, 100.0, /*horizontal=*/true, id));
    ASSERT_TRUE(execution.ok()) << execution.status();
    EXPECT_FALSE(execution->reversed);
    EXPECT_FALSE(execution->shortened);
    EXPECT_TRUE(execution->note.empty());
    EXPECT_NEAR(execution->length_mm, 20.0, 1e-6);
    EXPECT_LT(execution->approach_distance_mm, 1.0);
    const TraceFit fit = Fit(execution->trace);
    EXPECT_NEAR(fit.friction.mu, 0.13, 0.02) << "command " << id;
  }
}

TEST_F(BottleRigTest, SandpaperPatchFitsMuAbout05) {
  for (std::int64_t id : {11, 12}) {
    const TraceFit vertical = Fit(*rig_->Execute(BodyProbe(0.0, 35.0, /*horizontal=*/false, id)));
    EXPECT_NEAR(vertical.friction.mu, 0.5, 0.05) << "command " << id;
  }
  // Across patch B (centre 120 deg, z 75..115), around the body.
  const TraceFit across = Fit(*rig_->Execute(BodyProbe(106.0, 95.0, /*horizontal=*/true, 13)));
  EXPECT_NEAR(across.friction.mu, 0.5, 0.05);
  // Sandpaper is rough: its AR innovation is far above glass's.
  const TraceFit glass = Fit(*rig_->Execute(BodyProbe(195.0, 100.0, true, 14)));
  EXPECT_GT(across.roughness.sigma, 5.0 * glass.roughness.sigma);
}

TEST_F(BottleRigTest, SameCommandGivesTheSameTrace) {
  const ProbeRequest request = BodyProbe(0.0, 35.0, false, 42);
  auto a = rig_->Execute(request);
  auto b = rig_->Execute(request);
  ASSERT_TRUE(a.ok());
  ASSERT_TRUE(b.ok());
  ASSERT_EQ(a->samples.size(), b->samples.size());
  for (size_t i = 0; i < a->samples.size(); ++i) {
    ASSERT_EQ(a->samples[i].force, b->samples[i].force) << i;
    ASSERT_EQ(a->samples[i].position, b->samples[i].position) << i;
  }
  // Another command id: another realisation (noise, texture).
  ProbeRequest other = request;
  other.command_id = 43;
  auto c = rig_->Execute(other);
  ASSERT_TRUE(c.ok());
  EXPECT_NE(a->samples[a->samples.size() / 4].force, c->samples[c->samples.size() / 4].force);
  EXPECT_NE(rig_->SeedFor(42), rig_->SeedFor(43));
}

TEST_F(BottleRigTest, TraceFollowsTheRequest) {
  ProbeRequest request = BodyProbe(195.0, 100.0, true, 5);
  request.segment_length_mm = 15.0;
  request.speed_mm_s = 5.0;
  request.normal_force_n = 3.0;
  auto execution = rig_->ExecuteDetailed(request);
  ASSERT_TRUE(execution.ok()) << execution.status();
  EXPECT_NEAR(execution->length_mm, 15.0, 1e-6);
  // The segment is centred on the requested site.
  EXPECT_TRUE(execution->centred);
  double closest = 1e9;
  for (const Eigen::Vector3d& p : execution->path.points) closest = std::min(closest, (p - request.position).norm());
  EXPECT_LT(closest, 1.0);
  EXPECT_NEAR((execution->path.points.front() - request.position).norm(), 7.5, 1.0);
  EXPECT_NEAR((execution->path.points.back() - request.position).norm(), 7.5, 1.0);
  // Mean normal force over the forward pass ~ the commanded 3 N.
  double fn = 0.0;
  int n = 0;
  for (const auto& s : execution->trace.samples) {
    if (s.phase != DragPhase::kForward) continue;
    const Eigen::Vector3d radial(s.position.x(), s.position.y(), 0);
    fn += s.force.dot(radial.normalized());
    ++n;
  }
  ASSERT_GT(n, 100);  // 15 mm at 5 mm/s at 100 Hz: > 300 samples
  EXPECT_NEAR(fn / n, 3.0, 0.3);
}

TEST_F(BottleRigTest, RejectsUnreachableAndInvalidProbes) {
  ProbeRequest far = BodyProbe(0.0, 100.0, true, 1);
  far.position *= 2.0;  // 40+ mm off the surface
  auto r = rig_->Execute(far);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kFailedPrecondition) << r.status();
  EXPECT_NE(r.status().message().find("from the surface"), std::string::npos);

  ProbeRequest along_normal = BodyProbe(0.0, 100.0, true, 1);
  along_normal.drag_direction = along_normal.normal;
  EXPECT_EQ(rig_->Execute(along_normal).status().code(), absl::StatusCode::kInvalidArgument);

  ProbeRequest bad = BodyProbe(0.0, 100.0, true, 1);
  bad.speed_mm_s = 0.0;
  r = rig_->Execute(bad);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("speed_mm_s"), std::string::npos);
}

TEST_F(BottleRigTest, TruthOfVerticesMatchesThePatches) {
  const SceneTruth truth = rig_->Truth();
  const SurfaceLevel& finest = rig_->surface().finest();
  ASSERT_EQ(truth.material_index.size(), finest.limit_positions.size());
  const int sand = rig_->scene().FindMaterial("sandpaper");
  // The patches, recomputed independently: (centre angle, z range).
  const double patches[3][3] = {{0.0, 25.0, 65.0}, {120.0, 75.0, 115.0}, {240.0, 45.0, 85.0}};
  int sand_count = 0;
  for (size_t i = 0; i < finest.limit_positions.size(); ++i) {
    const Eigen::Vector3d& p = finest.limit_positions[i];
    const double deg = std::atan2(p.y(), p.x()) / kDeg;
    bool expected = false;
    for (const auto& patch : patches) {
      const double off = std::remainder(deg - patch[0], 360.0);
      if (std::abs(off) <= 28.65 && p.z() >= patch[1] && p.z() <= patch[2]) expected = true;
    }
    ASSERT_EQ(truth.material_index[i] == sand, expected) << "vertex " << i << " at " << p.transpose();
    EXPECT_DOUBLE_EQ(truth.mu[i], expected ? 0.5 : 0.13);
    sand_count += expected;
  }
  // Three 40 x 40 mm patches on a ~ (2 pi 40 x 200 + caps) mm^2 bottle: a few percent of the vertices.
  const double share = static_cast<double>(sand_count) / finest.limit_positions.size();
  EXPECT_GT(share, 0.03);
  EXPECT_LT(share, 0.15);
  // Coarser levels are prefixes of the finest (vertex numbering contract).
  const SceneTruth level1 = SceneTruthAtVertices(rig_->scene(), rig_->surface(), 1);
  ASSERT_LT(level1.mu.size(), truth.mu.size());
  for (size_t i = 0; i < level1.mu.size(); ++i) EXPECT_EQ(level1.material_index[i], truth.material_index[i]);
}

TEST(SimulatedRigPlateTest, OpenBoundaryReversesOrShortensTheDrag) {
  auto scene = LoadSceneByName("plate");
  ASSERT_TRUE(scene.ok()) << scene.status();
  auto rig = SimulatedRig::Create(*std::move(scene));
  ASSERT_TRUE(rig.ok()) << rig.status();

  ProbeRequest request;
  request.position = {-30, 0, 0};  // wood, far from every edge
  request.drag_direction = {1, 0, 0};
  auto inside = (*rig)->ExecuteDetailed(request);
  ASSERT_TRUE(inside.ok()) << inside.status();
  EXPECT_FALSE(inside->reversed);
  EXPECT_NEAR(FitTrace(inside->trace, FitOptions{})->friction.mu, 0.42, 0.03);

  request.position = {92, 0, 0};  // 8 mm from the x = 100 edge
  auto near_edge = (*rig)->ExecuteDetailed(request);
  ASSERT_TRUE(near_edge.ok()) << near_edge.status();
  EXPECT_TRUE(near_edge->reversed);
  EXPECT_FALSE(near_edge->shortened);
  EXPECT_NE(near_edge->note.find("reversed"), std::string::npos);
  EXPECT_LT(near_edge->path.points.back().x(), 92.0 - 19.0);

  request.position = {20, 0, 0};
  request.drag_direction = {0, 1, 0};
  request.segment_length_mm = 160.0;  // longer than the plate is wide: 75 mm to the edge either way
  auto too_long = (*rig)->ExecuteDetailed(request);
  ASSERT_TRUE(too_long.ok()) << too_long.status();
  EXPECT_TRUE(too_long->shortened);
  EXPECT_GT(too_long->length_mm, 70.0);
  EXPECT_LE(too_long->length_mm, 75.0);
  EXPECT_NE(too_long->note.find("shortened"), std::string::npos);

  request.position = {98, 72, 0};  // a corner; the drag is along the diagonal out of the plate
  request.drag_direction = {1, 1, 0};
  request.segment_length_mm = 20.0;
  auto corner = (*rig)->ExecuteDetailed(request);
  ASSERT_TRUE(corner.ok()) << corner.status();
  EXPECT_TRUE(corner->reversed);
}

TEST(SimulatedRigOptionsTest, RejectsInvalidOptions) {
  SimulatedRigOptions options;
  options.surface_level = 9;
  std::string why;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("surface_level"), std::string::npos);
  options = {};
  options.simulation.speed_jitter = 0.9;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("simulation"), std::string::npos);
}

}  // namespace
}  // namespace surfmap
