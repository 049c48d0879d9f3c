// Accuracy of FitTrace against the drag simulator's ground truth, over 20
// seeds per case: tilted plane (23 deg), cylinder (r 40 mm, the normal turns
// 28.6 deg), sphere (r 30 mm, latitude 45 deg: the normal turns 38 deg and the
// path curves in the tangent plane) x glass, rubber, masonite, with every
// simulated disturbance on. Prints the accuracy table.
//
// Two references for mu: the material's nominal mu, and the friction
// coefficient the surface actually showed over the window (texture included:
// mean of (mu Fn + r) / Fn over the paired forward samples). Texture adds to
// friction in both passes, so its mean over the window is indistinguishable
// from friction; on masonite (process std 0.64 N at 5 N, correlated over
// ~2 mm) that mean alone scatters mu by ~0.02 around the nominal value.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include "server/base/testing/status_matchers.h"
#include "clients/sim/dragsim/drag_geometry.h"
#include "clients/sim/dragsim/drag_simulator.h"
#include "server/estimate/fit_trace.h"

namespace surfmap {
namespace {

struct Stats {
  double median = 0.0;
  double worst = 0.0;
};

Stats Summarise(std::vector<double> errors) {
  for (double& e : errors) e = std::abs(e);
  std::sort(errors.begin(), errors.end());
  const std::size_t n = errors.size();
  return {n % 2 ? errors[n / 2] : 0.5 * (errors[n / 2 - 1] + errors[n / 2]), errors.back()};
}

struct CaseResult {
  Stats mu_nominal, mu_realised, normal_deg, a1, a2;
  Stats sigma_relative;  // |fit sigma / material sigma - 1|
  int failures = 0;
};

CaseResult RunCase(const DragGeometry& geometry, const Material& material, int seeds) {
  std::vector<double> mu_nominal, mu_realised, normal_deg, a1, a2, sigma_relative;
  CaseResult result;
  for (int seed = 1; seed <= seeds; ++seed) {
    DragSimOptions options;
    options.seed = 1000 + seed;
    absl::StatusOr<DragSimResult> sim =
        SimulateDrag(geometry, UniformMaterial(material), options);
    // A failed seed is counted and the loop goes on (the case's statistics
    // need the others), so these are EXPECTs, each followed by a skip before
    // any dereference.
    EXPECT_THAT(sim, status_matchers::IsOk()) << "seed " << seed;
    if (!sim.ok()) {
      ++result.failures;
      continue;
    }
    absl::StatusOr<TraceFit> fit = FitTrace(sim->trace, FitOptions{});
    EXPECT_THAT(fit, status_matchers::IsOk()) << "seed " << seed;
    if (!fit.ok()) {
      ++result.failures;
      continue;
    }
    const FrictionFit& f = fit->friction;
    double realised = 0.0;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (int i = f.first_forward_sample; i < f.first_forward_sample + f.n_pairs; ++i) {
      realised += sim->truth.friction_coefficient[i];
      normal += sim->truth.normal[i];
    }
    realised /= f.n_pairs;
    normal.normalize();
    mu_nominal.push_back(f.mu - material.mu);
    mu_realised.push_back(f.mu - realised);
    normal_deg.push_back(std::atan2(f.normal.cross(normal).norm(), f.normal.dot(normal)) * 180.0 /
                         M_PI);
    a1.push_back(fit->roughness.a[0] - material.a1);
    a2.push_back(fit->roughness.a[1] - material.a2);
    sigma_relative.push_back(fit->roughness.sigma / material.sigma - 1.0);
  }
  result.mu_nominal = Summarise(mu_nominal);
  result.mu_realised = Summarise(mu_realised);
  result.normal_deg = Summarise(normal_deg);
  result.a1 = Summarise(a1);
  result.a2 = Summarise(a2);
  result.sigma_relative = Summarise(sigma_relative);
  return result;
}

TEST(FitAccuracyTest, TwentySeedsPerShapeAndMaterial) {
  struct Shape {
    const char* name;
    DragGeometry geometry;
  };
  const Shape shapes[] = {{"plane 23deg", TiltedPlaneGeometry(23.0, 20.0)},
                          {"cylinder r40", CylinderGeometry(40.0, 20.0)},
                          {"sphere r30", SphereGeometry(30.0, 45.0, 20.0)}};
  struct Named {
    const char* name;
    Material material;
  };
  const Named materials[] = {{"glass", kGlass}, {"rubber", kRubber}, {"masonite", kMasonite}};
  std::printf(
      "| case | mu err vs nominal (median / worst) | mu err vs realised (median / worst) | normal "
      "err deg (median / worst) | a1 err (median / worst) | a2 err (median / worst) | sigma rel. err "
      "(median / worst) |\n"
      "|---|---|---|---|---|---|---|\n");
  for (const Shape& shape : shapes) {
    for (const Named& m : materials) {
      const CaseResult r = RunCase(shape.geometry, m.material, 20);
      const bool textured = m.material.sigma >= 0.1;
      std::printf("| %s, %s | %.4f / %.4f | %.4f / %.4f | %.3f / %.3f | %s | %s | %s |\n", shape.name,
                  m.name, r.mu_nominal.median, r.mu_nominal.worst, r.mu_realised.median,
                  r.mu_realised.worst, r.normal_deg.median, r.normal_deg.worst,
                  textured ? (std::to_string(r.a1.median).substr(0, 5) + " / " +
                              std::to_string(r.a1.worst).substr(0, 5)).c_str()
                           : "-",
                  textured ? (std::to_string(r.a2.median).substr(0, 5) + " / " +
                              std::to_string(r.a2.worst).substr(0, 5)).c_str()
                           : "-",
                  textured ? (std::to_string(r.sigma_relative.median).substr(0, 5) + " / " +
                              std::to_string(r.sigma_relative.worst).substr(0, 5)).c_str()
                           : "-");
      const std::string label = std::string(shape.name) + ", " + m.name;
      EXPECT_EQ(r.failures, 0) << label;
      // Against what the surface did over the window: the method itself.
      EXPECT_LE(r.mu_realised.median, 0.01) << label;
      EXPECT_LE(r.mu_realised.worst, 0.03) << label;
      EXPECT_LE(r.normal_deg.worst, 2.0) << label;
      if (m.material.sigma < 0.2) {
        // Against the nominal mu: glass and rubber meet the target; masonite's
        // window-mean texture is larger (see the file comment).
        const bool masonite = m.material.a1 > 1.0;
        EXPECT_LE(r.mu_nominal.median, masonite ? 0.03 : 0.01) << label;
        EXPECT_LE(r.mu_nominal.worst, masonite ? 0.08 : 0.03) << label;
      }
      if (textured) {
        EXPECT_LE(r.a1.median, 0.15) << label;
        EXPECT_LE(r.a2.median, 0.15) << label;
        EXPECT_LE(r.a1.worst, 0.35) << label;
        EXPECT_LE(r.a2.worst, 0.35) << label;
        // The texture's amplitude: the map goal's 15 % on the median (the
        // simulator's speed jitter alone takes ~6 % off rubber's, measured
        // with DragSimOptions::Ideal() plus jitter), 30 % on the worst of 20.
        EXPECT_LE(r.sigma_relative.median, 0.15) << label;
        EXPECT_LE(r.sigma_relative.worst, 0.30) << label;
      }
    }
  }
}

// A weak texture, the weakest any scene scores (ABS: process std 0.052 N,
// ten times the sensor noise's variance), where the noise correction decides
// the answer. Until the noise was propagated through the pair normals
// (series_noise.h), the fit subtracted the white model sigma^2 (1 + mu^2),
// twice the noise the series carries, and over-corrected: medians a1 1.07,
// a2 -0.41, sigma 0.029 over 60 such drags, outside the map goal's 0.15
// and 15 %. Measured now: medians 0.93, -0.28, 0.033 (the rest is the
// simulator's speed jitter: without it 0.89, -0.25, 0.034); here the median
// |error| over 40 drags is 0.074 (a1), 0.056 (a2), 8.4 % (sigma), against
// ~0.16, ~0.15 and ~17 % before.
TEST(FitAccuracyTest, AWeakTextureIsNotOverCorrectedForNoise) {
  constexpr Material kAbs{0.30, 0.9, -0.25, 0.035};
  const CaseResult r = RunCase(TiltedPlaneGeometry(0.0, 20.0), kAbs, 40);
  std::printf("ABS, flat, 40 drags: median |error| a1 %.3f a2 %.3f sigma %.3f\n", r.a1.median, r.a2.median,
              r.sigma_relative.median);
  EXPECT_EQ(r.failures, 0);
  EXPECT_LE(r.a1.median, 0.10);
  EXPECT_LE(r.a2.median, 0.10);
  EXPECT_LE(r.sigma_relative.median, 0.12);
}

// Mean a1 and median sigma of `drags` flat drags of `material` (every rig
// disturbance on), fitted with `options`.
struct TextureReading {
  double mean_a1 = 0.0;
  double median_sigma = 0.0;
};

TextureReading ReadTexture(const Material& material, int drags, const FitOptions& options) {
  std::vector<double> a1, sigma;
  for (int seed = 1; seed <= drags; ++seed) {
    DragSimOptions sim_options;
    sim_options.seed = 5000 + seed;
    absl::StatusOr<DragSimResult> sim =
        SimulateDrag(TiltedPlaneGeometry(23.0, 20.0), UniformMaterial(material), sim_options);
    EXPECT_THAT(sim, status_matchers::IsOk()) << "seed " << seed;
    if (!sim.ok()) continue;
    absl::StatusOr<TraceFit> fit = FitTrace(sim->trace, options);
    EXPECT_THAT(fit, status_matchers::IsOk()) << "seed " << seed;
    if (!fit.ok()) continue;
    a1.push_back(fit->roughness.a[0]);
    sigma.push_back(fit->roughness.sigma);
  }
  TextureReading out;
  if (a1.empty()) return out;
  for (double v : a1) out.mean_a1 += v / static_cast<double>(a1.size());
  std::sort(sigma.begin(), sigma.end());
  out.median_sigma = sigma[sigma.size() / 2];
  return out;
}

// The two passes' samples never fall at the same places (the rig's speed
// wanders by ~3 %), so the reverse force at a forward sample is interpolated
// between two samples of a texture that changes every 0.1 mm. Read against
// its own pair's bisector (estimator version 8), a sample kept about half its
// own texture and half that interpolated reverse: every texture read
// smoother than it is. Sandpaper over these 60 flat drags: mean a1 0.352
// for 0.30, median sigma 7.8 % low. Read against the pair normals averaged
// over +-0.5 mm: 0.292 and 2.9 % low. (surfmap-simtrace's 60 drags, seeds
// 1-60, own normals and a fixed grid as in version 8: 0.348; averaged
// normals: 0.287, and 0.280 with the samples followed; only the speed jitter
// switched on, --only speed-jitter, version 8: 0.342; an ideal rig, whose
// passes sample the same places: 0.275.)
TEST(FitAccuracyTest, ATextureIsNotSmoothedByWhereTheReverseSamplesFell) {
  constexpr Material kSandpaper{0.50, 0.30, 0.10, 0.25};
  const TextureReading averaged = ReadTexture(kSandpaper, 60, FitOptions{});
  FitOptions own_normals;
  own_normals.series.halfwidth_mm = 0.0;
  const TextureReading own = ReadTexture(kSandpaper, 60, own_normals);
  std::printf("sandpaper, 60 flat drags: mean a1 %.3f (own pair normals %.3f), median sigma %.4f (%.4f), truth "
              "0.30, 0.25\n",
              averaged.mean_a1, own.mean_a1, averaged.median_sigma, own.median_sigma);
  EXPECT_NEAR(averaged.mean_a1, kSandpaper.a1, 0.03);
  EXPECT_NEAR(averaged.median_sigma, kSandpaper.sigma, 0.04 * kSandpaper.sigma);
  // The comparison is the one this test is about: if both read alike, the
  // averaging no longer does what it is for.
  EXPECT_GT(own.mean_a1, averaged.mean_a1 + 0.03);
}

// Where the rig's speed wanders, a fixed grid drifts across the samples and,
// halfway between two, takes one twice and skips the next; a resonant
// texture (masonite, a1 1.61, a2 -0.73) then reads rougher and less resonant.
// Each pass's own samples one step apart (SeriesOptions::follow_samples)
// take each once. Masonite over these 60 flat drags: mean a1 1.576 against
// 1.559 from the fixed grid, median sigma 0.159 against 0.164 (surfmap-simtrace
// seeds 1-60: 1.546 against 1.528; an ideal rig 1.561).
TEST(FitAccuracyTest, AResonantTextureIsReadFromEachSampleOnce) {
  constexpr Material kMasonite{0.36, 1.61, -0.73, 0.16};
  const TextureReading followed = ReadTexture(kMasonite, 60, FitOptions{});
  FitOptions grid;
  grid.series.follow_samples = false;
  const TextureReading gridded = ReadTexture(kMasonite, 60, grid);
  std::printf("masonite, 60 flat drags: mean a1 %.3f (fixed grid %.3f), median sigma %.4f (%.4f), truth 1.61, "
              "0.16\n",
              followed.mean_a1, gridded.mean_a1, followed.median_sigma, gridded.median_sigma);
  EXPECT_NEAR(followed.mean_a1, kMasonite.a1, 0.08);
  EXPECT_NEAR(followed.median_sigma, kMasonite.sigma, 0.04 * kMasonite.sigma);
  EXPECT_GT(followed.mean_a1, gridded.mean_a1 + 0.01);
  EXPECT_LT(followed.median_sigma, gridded.median_sigma);
}

// The other side of the noise: textures the sensor cannot resolve stay
// flagged below the noise floor (ArFit::below_noise_floor), so a map does not
// compare roughness fitted to noise. Glass (sigma 0.003 and the bottle's
// 0.005 N) and steel (0.006 N: a process variance a third of the noise's)
// on a plane and a cylinder, 30 drags each. With the propagated noise and a
// floor ratio of 1.5 (version 7's ratio, which it applied to the white
// model's twice-too-large noise) 2-7 % of the glass drags and a fifth of the
// steel ones were fitted, measured over 60 drags per case; with 3.0 none.
TEST(FitAccuracyTest, TexturesBelowTheNoiseStayFlagged) {
  const Material materials[] = {kGlass, Material{0.13, 0.0, 0.0, 0.005}, Material{0.15, 0.4, 0.0, 0.006}};
  const DragGeometry geometries[] = {TiltedPlaneGeometry(0.0, 20.0), CylinderGeometry(15.0, 20.0)};
  for (const Material& material : materials) {
    for (const DragGeometry& geometry : geometries) {
      int fitted = 0;
      for (int seed = 1; seed <= 30; ++seed) {
        DragSimOptions options;
        options.seed = 9000 + seed;
        absl::StatusOr<DragSimResult> sim = SimulateDrag(geometry, UniformMaterial(material), options);
        ASSERT_TRUE(sim.ok()) << sim.status();
        absl::StatusOr<TraceFit> fit = FitTrace(sim->trace, FitOptions{});
        ASSERT_TRUE(fit.ok()) << fit.status();
        if (!fit->roughness.below_noise_floor) ++fitted;
      }
      EXPECT_EQ(fitted, 0) << "sigma " << material.sigma;
    }
  }
}

}  // namespace
}  // namespace surfmap
