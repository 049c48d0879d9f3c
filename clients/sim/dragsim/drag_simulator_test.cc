#include "clients/sim/dragsim/drag_simulator.h"

#include <cmath>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include "clients/sim/dragsim/drag_geometry.h"
#include "clients/sim/dragsim/roughness_field.h"

namespace surfmap {
namespace {

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

TEST(DragGeometryTest, BuildersGiveValidGeometryWithTheStatedTurn) {
  const DragGeometry plane = TiltedPlaneGeometry(23.0, 20.0);
  const DragGeometry cylinder = CylinderGeometry(40.0, 20.0);
  const DragGeometry sphere = SphereGeometry(30.0, 45.0, 20.0);
  for (const DragGeometry* g : {&plane, &cylinder, &sphere}) {
    EXPECT_TRUE(ValidateDragGeometry(*g).ok()) << ValidateDragGeometry(*g);
    EXPECT_NEAR(GeometryPath(*g).length_mm(), 20.0, 1e-3);
  }
  EXPECT_NEAR(AngleDeg(plane.normals.front(), Eigen::Vector3d::UnitZ()), 23.0, 1e-9);
  EXPECT_NEAR(AngleDeg(cylinder.normals.front(), cylinder.normals.back()), 20.0 / 40.0 * 180.0 / M_PI,
              1e-9);
  EXPECT_NEAR(AngleDeg(sphere.normals.front(), sphere.normals.back()),
              // chord angle of the latitude circle seen from the centre
              2.0 * std::asin(std::sin(45.0 * M_PI / 180.0) *
                              std::sin(0.5 * 20.0 / (30.0 * std::sin(45.0 * M_PI / 180.0)))) *
                  180.0 / M_PI,
              1e-6);
  for (std::size_t i = 0; i < sphere.points.size(); i += 97) {
    EXPECT_NEAR(sphere.points[i].norm(), 30.0, 1e-9);
    EXPECT_NEAR((sphere.points[i] / 30.0 - sphere.normals[i]).norm(), 0.0, 1e-12);
  }
}

TEST(DragGeometryTest, ValidationNamesTheProblem) {
  DragGeometry g = TiltedPlaneGeometry(0.0, 1.0);
  g.normals.pop_back();
  EXPECT_NE(std::string(ValidateDragGeometry(g).message()).find("points but"), std::string::npos);
  g = TiltedPlaneGeometry(0.0, 1.0);
  g.normals[3] = Eigen::Vector3d(1, 0, 0);  // along the path
  EXPECT_NE(std::string(ValidateDragGeometry(g).message()).find("normal 3 is not perpendicular"),
            std::string::npos);
  g = TiltedPlaneGeometry(0.0, 1.0);
  g.points[5] = g.points[4];
  EXPECT_NE(std::string(ValidateDragGeometry(g).message()).find("points 4 and 5 coincide"),
            std::string::npos);
}

TEST(DragSimulatorTest, IdealPhysicsIsExactCoulombPlusTexture) {
  DragSimOptions options = DragSimOptions::Ideal();
  options.seed = 3;
  absl::StatusOr<DragSimResult> sim =
      SimulateDrag(CylinderGeometry(40.0, 20.0), UniformMaterial(kRubber), options);
  ASSERT_TRUE(sim.ok()) << sim.status();
  const auto& samples = sim->trace.samples;
  const DragTruth& truth = sim->truth;
  ASSERT_EQ(truth.s_mm.size(), samples.size());
  int counts[3] = {0, 0, 0};
  for (std::size_t i = 0; i < samples.size(); ++i) {
    ++counts[static_cast<int>(samples[i].phase)];
    const Eigen::Vector3d& n = truth.normal[i];
    // Normal part = commanded force, tangential part = friction + texture.
    EXPECT_NEAR(samples[i].force.dot(n), 5.0, 1e-9) << i;
    if (samples[i].phase != DragPhase::kPause) {
      EXPECT_NEAR((samples[i].force - samples[i].force.dot(n) * n).norm(),
                  std::abs(0.305 * 5.0 + truth.roughness_n[i]), 1e-9)
          << i;
    }
    EXPECT_NEAR(samples[i].position.norm(), 40.0, 1e-3) << i;  // on the cylinder
  }
  // 20 mm at 10 mm/s with 0.3 s ramps: 2.3 s per pass at 100 Hz.
  EXPECT_NEAR(counts[0], 231, 1);
  EXPECT_EQ(counts[1], 50);
  EXPECT_NEAR(counts[2], 231, 1);
  EXPECT_NEAR(truth.s_mm[counts[0] - 1], 20.0, 1e-3);
  EXPECT_NEAR(truth.s_mm.back(), 0.0, 1e-3);
}

TEST(DragSimulatorTest, DisturbancesScaleTogether) {
  const DragSimOptions base;
  // Zero is Ideal()'s physics: the same trace, sample for sample.
  DragSimOptions none = base.WithDisturbancesScaled(0.0);
  DragSimOptions ideal = DragSimOptions::Ideal();
  none.seed = ideal.seed = 7;
  absl::StatusOr<DragSimResult> a = SimulateDrag(TiltedPlaneGeometry(10.0, 20.0), UniformMaterial(kRubber), none);
  absl::StatusOr<DragSimResult> b = SimulateDrag(TiltedPlaneGeometry(10.0, 20.0), UniformMaterial(kRubber), ideal);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->trace.samples.size(), b->trace.samples.size());
  for (std::size_t i = 0; i < a->trace.samples.size(); ++i) {
    ASSERT_TRUE(a->trace.samples[i].force == b->trace.samples[i].force) << i;
  }
  // Two: every amplitude doubled, nothing else touched.
  const DragSimOptions twice = base.WithDisturbancesScaled(2.0);
  EXPECT_EQ(twice.force_noise_n, 2.0 * base.force_noise_n);
  EXPECT_EQ(twice.speed_jitter, 2.0 * base.speed_jitter);
  EXPECT_EQ(twice.stick_slip, 2.0 * base.stick_slip);
  EXPECT_EQ(twice.contact_decay_s, base.contact_decay_s);
  EXPECT_EQ(twice.sample_rate_hz, base.sample_rate_hz);
  EXPECT_TRUE(twice.IsValid(nullptr));
  // Four takes the contact overshoot past its range: IsValid says so.
  std::string why;
  EXPECT_FALSE(base.WithDisturbancesScaled(4.0).IsValid(&why));
  EXPECT_NE(why.find("contact_overshoot"), std::string::npos) << why;
}

TEST(DragSimulatorTest, BothPassesFeelTheSameTexture) {
  DragSimOptions options;
  options.seed = 4;
  absl::StatusOr<DragSimResult> sim =
      SimulateDrag(TiltedPlaneGeometry(23.0, 20.0), UniformMaterial(kMasonite), options);
  ASSERT_TRUE(sim.ok()) << sim.status();
  const DragTruth& t = sim->truth;
  // For every reverse sample, the forward sample nearest in arc length (within
  // half a grid cell, the same cell) felt the same texture value.
  int compared = 0;
  for (std::size_t j = 0; j < t.s_mm.size(); ++j) {
    if (sim->trace.samples[j].phase != DragPhase::kReverse) continue;
    for (std::size_t i = 0; i < t.s_mm.size(); ++i) {
      if (sim->trace.samples[i].phase != DragPhase::kForward) break;
      if (std::lround(t.s_mm[i] / 0.1) == std::lround(t.s_mm[j] / 0.1)) {
        EXPECT_EQ(t.roughness_n[i], t.roughness_n[j]);
        ++compared;
        break;
      }
    }
  }
  EXPECT_GT(compared, 150);
}

TEST(DragSimulatorTest, SameSeedSameTraceOtherSeedOtherTrace) {
  DragSimOptions options;
  options.seed = 9;
  const DragGeometry g = SphereGeometry(30.0, 45.0, 20.0);
  absl::StatusOr<DragSimResult> a = SimulateDrag(g, UniformMaterial(kSandpaper), options);
  absl::StatusOr<DragSimResult> b = SimulateDrag(g, UniformMaterial(kSandpaper), options);
  options.seed = 10;
  absl::StatusOr<DragSimResult> c = SimulateDrag(g, UniformMaterial(kSandpaper), options);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  ASSERT_EQ(a->trace.samples.size(), b->trace.samples.size());
  for (std::size_t i = 0; i < a->trace.samples.size(); ++i) {
    ASSERT_TRUE(a->trace.samples[i].force == b->trace.samples[i].force) << i;
    ASSERT_EQ(a->trace.samples[i].position, b->trace.samples[i].position) << i;
  }
  EXPECT_NE(a->trace.samples[100].force, c->trace.samples[100].force);
}

TEST(DragSimulatorTest, CrossesAMaterialBoundary) {
  const DragGeometry g = TiltedPlaneGeometry(0.0, 20.0);  // x from -10 to 10
  const MaterialField field =
      SplitMaterial(kGlass, kSandpaper, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
  absl::StatusOr<DragSimResult> sim = SimulateDrag(g, field, DragSimOptions{});
  ASSERT_TRUE(sim.ok());
  for (std::size_t i = 0; i < sim->truth.s_mm.size(); ++i) {
    EXPECT_EQ(sim->truth.material_mu[i], sim->truth.s_mm[i] < 10.0 ? 0.106 : 0.5) << i;
  }
}

TEST(DragSimulatorTest, DisturbancesShowWhereTheyShould) {
  DragSimOptions options;
  options.seed = 5;
  absl::StatusOr<DragSimResult> sim =
      SimulateDrag(TiltedPlaneGeometry(0.0, 20.0), UniformMaterial(kGlass), options);
  ASSERT_TRUE(sim.ok());
  const DragTruth& t = sim->truth;
  // Contact overshoot: the normal force peaks well above 5 N right at contact.
  EXPECT_GT(t.normal_force_n[0], 5.0 * 1.2);
  // Stick-slip: at the start (slow) the friction coefficient departs from mu,
  // in the middle (cruise) it does not (up to texture).
  double start_dev = 0.0, mid_dev = 0.0;
  for (int i = 0; i < 5; ++i) start_dev = std::max(start_dev, std::abs(t.friction_coefficient[i] - 0.106));
  for (int i = 100; i < 120; ++i) mid_dev = std::max(mid_dev, std::abs(t.friction_coefficient[i] - 0.106));
  EXPECT_GT(start_dev, 0.01);
  EXPECT_LT(mid_dev, 0.005);
}

TEST(DragSimulatorTest, RejectsBadInput) {
  DragSimOptions options;
  options.speed_mm_s = 0.0;
  EXPECT_EQ(SimulateDrag(TiltedPlaneGeometry(0.0, 20.0), UniformMaterial(kGlass), options)
                .status()
                .message(),
            "DragSimOptions: speed_mm_s must be > 0");
  EXPECT_NE(std::string(SimulateDrag(TiltedPlaneGeometry(0.0, 10.0), UniformMaterial(kGlass),
                                     DragSimOptions{})
                            .status()
                            .message())
                .find("drag geometry is 10.000 mm long; the drag needs 20.000 mm"),
            std::string::npos);
  EXPECT_FALSE(SimulateDrag(TiltedPlaneGeometry(0.0, 20.0), MaterialField{}, DragSimOptions{}).ok());
}

TEST(MaterialTest, ProcessVarianceOfAr2) {
  // Rubber: sigma^2 (1 - a2) / ((1 + a2) ((1 - a2)^2 - a1^2)).
  EXPECT_NEAR(ArProcessVariance(kRubber), 0.0121 * 0.75 / (1.25 * (0.5625 - 0.36)), 1e-12);
  EXPECT_EQ(ArProcessVariance(Material{0.1, 1.0, 0.5, 0.1}), 0.0);  // not stationary
}

}  // namespace
}  // namespace surfmap
