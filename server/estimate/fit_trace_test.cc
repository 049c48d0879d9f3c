#include "server/estimate/fit_trace.h"

#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include "server/dragsim/drag_geometry.h"
#include "server/dragsim/drag_simulator.h"
#include "server/estimate/trace_csv.h"

namespace surfmap {
namespace {

DragSimResult Simulate(const DragGeometry& geometry, const Material& material, std::uint64_t seed) {
  DragSimOptions options;
  options.seed = seed;
  absl::StatusOr<DragSimResult> sim = SimulateDrag(geometry, UniformMaterial(material), options);
  EXPECT_TRUE(sim.ok()) << sim.status();
  return *std::move(sim);
}

std::string ErrorOf(const DragTrace& trace, const FitOptions& options = {}) {
  absl::StatusOr<TraceFit> fit = FitTrace(trace, options);
  EXPECT_FALSE(fit.ok());
  if (fit.ok()) return "";
  EXPECT_EQ(fit.status().code(), absl::StatusCode::kInvalidArgument);
  return std::string(fit.status().message());
}

TEST(FitTraceTest, FitsASimulatedRubberDrag) {
  const DragSimResult sim = Simulate(TiltedPlaneGeometry(23.0, 20.0), kRubber, 5);
  absl::StatusOr<TraceFit> fit = FitTrace(sim.trace, FitOptions{});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR(fit->friction.mu, 0.305, 0.05);
  EXPECT_NEAR(fit->path_length_mm, 20.0, 0.2);
  EXPECT_LT(fit->max_retrace_offset_mm, 0.05);
  // Pause noise: 0.015 N per axis simulated.
  EXPECT_NEAR(fit->noise_std, 0.015, 0.004);
  ASSERT_EQ(fit->roughness.a.size(), 2u);
  EXPECT_NEAR(fit->roughness.a[0], 0.60, 0.25);
  EXPECT_NEAR(fit->roughness.a[1], 0.25, 0.25);
  EXPECT_EQ(static_cast<int>(fit->friction.pair_mu.size()), fit->friction.n_pairs);
  EXPECT_EQ(fit->friction.pair_s_mm.front(), fit->friction.pair_s_mm[0]);
  EXPECT_GE(fit->friction.pair_s_mm.front(), fit->friction.window_start_mm);
  EXPECT_LE(fit->friction.pair_s_mm.back(), fit->friction.window_end_mm);
}

TEST(FitTraceTest, GlassTextureIsBelowTheNoiseFloor) {
  const DragSimResult sim = Simulate(TiltedPlaneGeometry(0.0, 20.0), kGlass, 2);
  absl::StatusOr<TraceFit> fit = FitTrace(sim.trace, FitOptions{});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR(fit->friction.mu, 0.106, 0.01);
  EXPECT_TRUE(fit->roughness.below_noise_floor);
}

TEST(FitTraceTest, RejectsInvalidOptions) {
  const DragSimResult sim = Simulate(TiltedPlaneGeometry(0.0, 20.0), kGlass, 2);
  FitOptions options;
  options.step_mm = 0.0;
  EXPECT_EQ(ErrorOf(sim.trace, options), "FitOptions: step_mm must be > 0");
  options = FitOptions{};
  options.window_trim_fraction = 0.6;
  EXPECT_EQ(ErrorOf(sim.trace, options), "FitOptions: trim_fraction must be in [0, 0.5)");
}

TEST(FitTraceTest, RejectsATraceWithoutReversePass) {
  DragSimResult sim = Simulate(TiltedPlaneGeometry(0.0, 20.0), kGlass, 2);
  std::erase_if(sim.trace.samples, [](const DragSample& s) { return s.phase == DragPhase::kReverse; });
  EXPECT_EQ(ErrorOf(sim.trace), "trace has no reverse (rev) samples");
}

TEST(FitTraceTest, RejectsTooFewSamples) {
  DragTrace trace;
  for (int i = 0; i < 6; ++i) {
    DragSample s;
    s.t = 0.01 * i;
    s.position = Eigen::Vector3d(i < 3 ? 0.1 * i : 0.1 * (5 - i), 0, 0);
    s.force = Eigen::Vector3d(0, 0, 5);
    s.phase = i < 3 ? DragPhase::kForward : DragPhase::kReverse;
    trace.samples.push_back(s);
  }
  EXPECT_EQ(ErrorOf(trace),
            "too few samples: forward pass 3, reverse pass 3; a fit needs at least 10 in each");
}

TEST(FitTraceTest, RejectsZeroForce) {
  DragSimResult sim = Simulate(TiltedPlaneGeometry(0.0, 20.0), kGlass, 2);
  for (DragSample& s : sim.trace.samples) s.force.setZero();
  EXPECT_NE(ErrorOf(sim.trace).find("contact force 0 N is below 0.1 N (probe not in contact?)"),
            std::string::npos);
}

TEST(FitTraceTest, RejectsAReversePassOnAnotherPath) {
  DragSimResult sim = Simulate(TiltedPlaneGeometry(0.0, 20.0), kGlass, 2);
  for (DragSample& s : sim.trace.samples) {
    if (s.phase == DragPhase::kReverse) s.position.y() += 2.0;
  }
  EXPECT_NE(ErrorOf(sim.trace).find("reverse pass does not retrace the forward path"),
            std::string::npos);
}

TEST(FitTraceTest, RejectsNonFiniteAndDisorderedSamples) {
  DragSimResult sim = Simulate(TiltedPlaneGeometry(0.0, 20.0), kGlass, 2);
  DragTrace nan = sim.trace;
  nan.samples[17].force.x() = std::nan("");
  EXPECT_EQ(ErrorOf(nan), "sample 17: time, position or force is not finite");
  DragTrace late = sim.trace;
  late.samples[3].t = late.samples[2].t;
  EXPECT_NE(ErrorOf(late).find("sample 3: time"), std::string::npos);
}

// Found by fuzzing (tests/fuzz): one coordinate of -1e200 mm made the forward
// path length overflow to inf, and one force of 1e200 N made mu NaN, both with
// an OK status (the fit would have been stored and mapped). Magnitudes beyond
// 1e9 are rejected before any arithmetic; up to it a trace still fits.
TEST(FitTraceTest, RejectsValuesWhoseArithmeticWouldOverflow) {
  const DragSimResult sim = Simulate(TiltedPlaneGeometry(0.0, 20.0), kGlass, 2);
  DragTrace far = sim.trace;
  far.samples[5].position.y() = -1e200;
  EXPECT_EQ(ErrorOf(far), "sample 5: position coordinate -1e+200 mm is outside -1e9..1e9 mm");
  DragTrace strong = sim.trace;
  strong.samples[200].force.z() = 1e200;
  EXPECT_EQ(ErrorOf(strong), "sample 200: force component 1e+200 N is outside -1e9..1e9 N");

  DragTrace shifted = sim.trace;  // the same drag 1e9 - 100 mm away: still fits
  for (DragSample& sample : shifted.samples) sample.position.x() += 1e9 - 100.0;
  const absl::StatusOr<TraceFit> fit = FitTrace(shifted, FitOptions{});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR(fit->friction.mu, FitTrace(sim.trace, FitOptions{})->friction.mu, 0.01);
}

// Found while fuzzing (read in ForceVariationSeries after the fix above, then
// confirmed by UBSan in the fuzz build on a hand-made trace): a 1.8e9 mm drag,
// or a 1e-12 mm grid step on an ordinary one, asked for ~1e10 roughness grid
// points; the count overflowed int (undefined behaviour), and a count just
// within int would have allocated gigabytes. Now a clear error.
TEST(FitTraceTest, RejectsARoughnessGridBeyondTheLimit) {
  DragTrace huge;
  double t = 0.0;
  auto add = [&](double x, double fx, DragPhase phase) {
    huge.samples.push_back({t, {x, 0.0, 0.0}, {fx, 0.0, 5.0}, phase});
    t += 0.01;
  };
  constexpr int kPerPass = 30;
  const auto x_at = [](int i) { return -9e8 + i * (1.8e9 / (kPerPass - 1)); };
  for (int i = 0; i < kPerPass; ++i) add(x_at(i), -0.5, DragPhase::kForward);
  for (int i = kPerPass - 1; i >= 0; --i) add(x_at(i), 0.5, DragPhase::kReverse);
  EXPECT_NE(ErrorOf(huge).find("points of the 0.1 mm roughness grid; the limit is 4194304"), std::string::npos)
      << ErrorOf(huge);

  const DragSimResult sim = Simulate(TiltedPlaneGeometry(0.0, 20.0), kGlass, 2);
  FitOptions fine;
  fine.step_mm = 1e-12;
  EXPECT_NE(ErrorOf(sim.trace, fine).find("the limit is 4194304"), std::string::npos) << ErrorOf(sim.trace, fine);
}

// Per-point mu along a curved path (the normal turns 28.6 deg on the
// cylinder) shows no trend: the slope of mu over the window is far below
// what a fixed-frame |f_t|/|f_n| would show.
TEST(FitTraceTest, PointMuIsFlatAlongACurvedPath) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const DragSimResult sim = Simulate(CylinderGeometry(40.0, 20.0), kGlass, seed);
    absl::StatusOr<TraceFit> fit = FitTrace(sim.trace, FitOptions{});
    ASSERT_TRUE(fit.ok()) << fit.status();
    const auto& s = fit->friction.pair_s_mm;
    const auto& mu = fit->friction.pair_mu;
    double ms = 0, mm = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      ms += s[i];
      mm += mu[i];
    }
    ms /= s.size();
    mm /= s.size();
    double sxy = 0, sxx = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      sxy += (s[i] - ms) * (mu[i] - mm);
      sxx += (s[i] - ms) * (s[i] - ms);
    }
    const double slope = sxy / sxx;  // per mm
    const double span = s.back() - s.front();
    EXPECT_LT(std::abs(slope) * span, 0.01) << "seed " << seed;
    EXPECT_LT(fit->friction.mu_std, 0.01) << "seed " << seed;
  }
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The example traces (CTest runs with the repository root as working directory).
TEST(FitTraceTest, ExampleTracesFitToTheirTrueParameters) {
  struct Example {
    const char* path;
    double mu;
    double tolerance;
  };
  const Example examples[] = {
      {"examples/traces/glass_plane.csv", 0.106, 0.01},
      {"examples/traces/rubber_tilted_plane.csv", 0.305, 0.04},
      {"examples/traces/masonite_cylinder.csv", 0.25, 0.08},
      {"examples/traces/sandpaper_sphere.csv", 0.5, 0.05},
  };
  for (const Example& e : examples) {
    const std::string text = ReadFile(e.path);
    ASSERT_FALSE(text.empty()) << e.path << " is missing or empty";
    absl::StatusOr<DragTrace> trace = ParseTraceCsv(text, e.path);
    ASSERT_TRUE(trace.ok()) << trace.status();
    absl::StatusOr<TraceFit> fit = FitTrace(*trace, FitOptions{});
    ASSERT_TRUE(fit.ok()) << e.path << ": " << fit.status();
    EXPECT_NEAR(fit->friction.mu, e.mu, e.tolerance) << e.path;
  }
}

TEST(FitTraceTest, BadExampleTracesAreRejectedWithClearMessages) {
  struct Bad {
    const char* path;
    const char* expected;
  };
  const Bad bad[] = {
      {"examples/traces/bad/missing_column.csv", "header: missing column 'fz'"},
      {"examples/traces/bad/nan_force.csv", "is not finite"},
      {"examples/traces/bad/no_reverse.csv", "no reverse (rev) samples"},
      {"examples/traces/bad/not_retracing.csv", "reverse pass does not retrace the forward path"},
  };
  for (const Bad& b : bad) {
    const std::string text = ReadFile(b.path);
    ASSERT_FALSE(text.empty()) << b.path << " is missing or empty";
    absl::StatusOr<DragTrace> trace = ParseTraceCsv(text, b.path);
    absl::Status status = trace.status();
    if (trace.ok()) status = FitTrace(*trace, FitOptions{}).status();
    ASSERT_FALSE(status.ok()) << b.path;
    EXPECT_NE(std::string(status.message()).find(b.expected), std::string::npos)
        << b.path << ": " << status;
  }
}

TEST(TextureOfTest, KeepsRoughnessOnlyWhenTheModelIsStationary) {
  TraceFit fit;
  fit.friction.mu = 0.3;
  fit.friction.mu_std = 0.02;
  fit.roughness.reflection = {0.5, -0.2};
  fit.roughness.sigma = 0.11;
  fit.roughness.stationary = true;
  TextureParams t = TextureOf(fit);
  EXPECT_EQ(t.mu, 0.3);
  EXPECT_EQ(t.mu_std, 0.02);
  EXPECT_EQ(t.reflection, (std::vector<double>{0.5, -0.2}));
  EXPECT_EQ(t.sigma, 0.11);
  fit.roughness.stationary = false;
  t = TextureOf(fit);
  EXPECT_EQ(t.mu, 0.3);
  EXPECT_TRUE(t.reflection.empty());
  EXPECT_EQ(t.sigma, 0.0);
}

}  // namespace
}  // namespace surfmap
