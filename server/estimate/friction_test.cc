// FitFriction / FitTrace on exact physics (DragSimOptions::Ideal, no texture):
// the differential method must be exact up to rounding.
#include "server/estimate/friction.h"

#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include "clients/sim/dragsim/drag_geometry.h"
#include "clients/sim/dragsim/drag_simulator.h"
#include "server/estimate/fit_trace.h"

namespace surfmap {
namespace {

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

Eigen::Vector3d TrueMeanNormal(const DragSimResult& sim, const FrictionFit& fit) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i = 0; i < fit.n_pairs; ++i) sum += sim.truth.normal[fit.first_forward_sample + i];
  return sum.normalized();
}

TEST(FrictionTest, ExactMuAndNormalOnATiltedPlaneWithoutTexture) {
  const Material smooth{0.3, 0.0, 0.0, 0.0};
  DragSimOptions options = DragSimOptions::Ideal();
  absl::StatusOr<DragSimResult> sim =
      SimulateDrag(TiltedPlaneGeometry(23.0, 20.0), UniformMaterial(smooth), options);
  ASSERT_TRUE(sim.ok()) << sim.status();
  absl::StatusOr<TraceFit> fit = FitTrace(sim->trace, FitOptions{});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR(fit->friction.mu, 0.3, 1e-12);
  EXPECT_NEAR(fit->friction.mu_median, 0.3, 1e-12);
  EXPECT_LT(fit->friction.mu_std, 1e-12);
  const Eigen::Vector3d n(std::sin(23.0 * M_PI / 180.0), 0.0, std::cos(23.0 * M_PI / 180.0));
  EXPECT_LT(AngleDeg(fit->friction.normal, n), 1e-9);
  // The window excludes the ramps: it starts after the acceleration (1.5 mm
  // at 10 mm/s over 0.3 s) and ends before the deceleration.
  EXPECT_GT(fit->friction.window_start_mm, 1.0);
  EXPECT_LT(fit->friction.window_end_mm, 19.0);
  EXPECT_GT(fit->friction.window_end_mm - fit->friction.window_start_mm, 12.0);
}

TEST(FrictionTest, ExactMuAndNormalOnACylinderWithFaintTexture) {
  // A faint texture (1e-4 N) keeps the roughness fit defined while changing
  // the per-point mu by at most ~1e-4 / 5 N.
  const Material faint{0.25, 0.5, 0.0, 1e-4};
  DragSimOptions options = DragSimOptions::Ideal();
  absl::StatusOr<DragSimResult> sim =
      SimulateDrag(CylinderGeometry(40.0, 20.0), UniformMaterial(faint), options);
  ASSERT_TRUE(sim.ok()) << sim.status();
  absl::StatusOr<TraceFit> fit = FitTrace(sim->trace, FitOptions{});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR(fit->friction.mu, 0.25, 2e-4);
  EXPECT_NEAR(fit->friction.mu_median, 0.25, 2e-4);
  EXPECT_LT(fit->friction.mu_std, 1e-4);
  EXPECT_LT(AngleDeg(fit->friction.normal, TrueMeanNormal(*sim, fit->friction)), 0.01);
  for (int i = 0; i < fit->friction.n_pairs; ++i) {
    EXPECT_LT(AngleDeg(fit->friction.pair_normal[i],
                       sim->truth.normal[fit->friction.first_forward_sample + i]),
              0.05)
        << i;
  }
  EXPECT_NEAR(fit->path_length_mm, 20.0, 0.01);
  EXPECT_LT(fit->noise_std, 1e-12);
}

TEST(FrictionTest, NegativePointFrictionKeepsItsSign) {
  // Forward and reverse forces that both lean along the forward motion (+x):
  // the pair is "negative friction" and must not count as positive.
  std::vector<DragSample> forward, reverse;
  const double mu = -0.1;
  for (int i = 0; i <= 20; ++i) {
    DragSample s;
    s.t = 0.01 * i;
    s.position = Eigen::Vector3d(0.1 * i, 0, 0);
    s.force = Eigen::Vector3d(-mu * 5.0, 0, 5.0);  // friction against +x is -mu*5
    forward.push_back(s);
  }
  for (int j = 0; j <= 20; ++j) {
    DragSample s;
    s.t = 1.0 + 0.01 * j;
    s.position = Eigen::Vector3d(2.0 - 0.1 * j, 0, 0);
    s.force = Eigen::Vector3d(mu * 5.0, 0, 5.0);
    s.phase = DragPhase::kReverse;
    reverse.push_back(s);
  }
  absl::StatusOr<PathPairing> pairing = PairPasses(forward, reverse);
  ASSERT_TRUE(pairing.ok());
  absl::StatusOr<FrictionFit> fit = FitFriction(forward, reverse, *pairing, DataWindow{0.0, 2.0});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR(fit->mu, -0.1, 1e-12);
  EXPECT_EQ(fit->n_pairs, 21);
  EXPECT_NEAR(fit->normal.z(), 1.0, 1e-12);
}

TEST(FrictionTest, RejectsZeroForceNamingTheSample) {
  std::vector<DragSample> forward, reverse;
  for (int i = 0; i <= 20; ++i) {
    DragSample s;
    s.t = 0.01 * i;
    s.position = Eigen::Vector3d(0.1 * i, 0, 0);
    s.force = i == 7 ? Eigen::Vector3d(0, 0, 0.01) : Eigen::Vector3d(-1, 0, 5);
    forward.push_back(s);
  }
  for (int j = 0; j <= 20; ++j) {
    DragSample s;
    s.t = 1.0 + 0.01 * j;
    s.position = Eigen::Vector3d(2.0 - 0.1 * j, 0, 0);
    s.force = Eigen::Vector3d(1, 0, 5);
    s.phase = DragPhase::kReverse;
    reverse.push_back(s);
  }
  absl::StatusOr<PathPairing> pairing = PairPasses(forward, reverse);
  ASSERT_TRUE(pairing.ok());
  absl::StatusOr<FrictionFit> fit = FitFriction(forward, reverse, *pairing, DataWindow{0.0, 2.0});
  ASSERT_FALSE(fit.ok());
  EXPECT_NE(std::string(fit.status().message())
                .find("forward sample 7 (t=0.070 s): contact force 0.01 N is below 0.1 N"),
            std::string::npos)
      << fit.status();
  absl::StatusOr<FrictionFit> few = FitFriction(forward, reverse, *pairing, DataWindow{0.0, 0.45});
  ASSERT_FALSE(few.ok());
  EXPECT_NE(std::string(few.status().message()).find("holds 5 forward sample(s)"), std::string::npos)
      << few.status();
}

}  // namespace
}  // namespace surfmap
