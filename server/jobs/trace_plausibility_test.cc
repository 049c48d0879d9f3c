#include "server/jobs/trace_plausibility.h"

#include <cmath>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "server/base/testing/status_matchers.h"
#include "server/estimate/fit_trace.h"

namespace surfmap {
namespace {

using ::testing::ContainsRegex;
using ::testing::HasSubstr;
using status_matchers::IsOk;
using status_matchers::StatusIs;

constexpr double kPi = 3.14159265358979323846;

// A point of a CAD part's cross-section in the xz-plane: the top face z = 0
// up to the edge at x = 0, rounded by the probe tip's radius r, then the side
// face x = 0 downwards. s is the arc length from the edge's start (x = -r).
struct EdgePoint {
  Eigen::Vector3d position, normal, tangent;
};
EdgePoint OverTheEdge(double s, double r) {
  if (s <= 0) return {{-r + s, 0, 0}, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()};
  const double arc = 0.5 * kPi * r;
  if (s >= arc) return {{0, 0, -r - (s - arc)}, Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitZ()};
  const double a = s / r;  // turned this far from +z towards +x
  const Eigen::Vector3d n(std::sin(a), 0, std::cos(a));
  return {Eigen::Vector3d(-r, 0, -r) + r * n, n, Eigen::Vector3d(std::cos(a), 0, -std::sin(a))};
}

// A 20 mm drag starting `top_mm` before the edge on the top face, over it and
// down the side, forward, pause, back; 5 N along the local normal, mu 0.3
// against the motion, seeded sensor noise; 0.1 mm per sample.
DragTrace EdgeDrag(double top_mm, const Eigen::Matrix3d& frame = Eigen::Matrix3d::Identity()) {
  constexpr double kTip = 1.0;
  std::mt19937 rng(23);
  std::normal_distribution<double> noise(0.0, 0.015);
  DragTrace trace;
  double t = 0;
  auto add = [&](double s, double direction, DragPhase phase) {
    const EdgePoint p = OverTheEdge(s, kTip);
    Eigen::Vector3d force = 5.0 * p.normal - (phase == DragPhase::kPause ? 0.0 : 0.3 * 5.0 * direction) * p.tangent;
    force += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    trace.samples.push_back({t, frame * p.position, frame * force, phase});
    t += 0.01;
  };
  const double start = -top_mm + kTip;
  for (int i = 0; i <= 200; ++i) add(start + 0.1 * i, 1.0, DragPhase::kForward);
  for (int i = 0; i < 50; ++i) add(start + 20.0, 0.0, DragPhase::kPause);
  for (int i = 0; i <= 200; ++i) add(start + 20.0 - 0.1 * i, -1.0, DragPhase::kReverse);
  return trace;
}

// The command of a site `before_mm` before the edge on the top face.
ProbeCommand TopCommand(double before_mm) {
  ProbeCommand c;
  c.position = {-before_mm, 0, 0};
  c.normal = Eigen::Vector3d::UnitZ();
  c.drag_direction = Eigen::Vector3d::UnitX();
  return c;
}

absl::Status Checked(const DragTrace& trace, const ProbeCommand& command) {
  if (absl::Status s = CheckTraceAgainstCommand(trace, command, TraceLimits{}); !s.ok()) return s;
  absl::StatusOr<TraceFit> fit = FitTrace(trace, FitOptions{});
  if (!fit.ok()) return fit.status();
  return CheckFitAgainstCommand(trace, *fit, command, TraceLimits{});
}

// A drag over a CAD part's sharp edge is a measurement, not a trace in
// another frame: 8 mm on the top, 12 down the side. Its chord runs 56
// degrees off the commanded direction and its mean normal ~50 degrees off the
// site's, past both limits (45 and 30); seen along the site's normal the
// chord is on the commanded line, and the normal where it passed the site is
// the site's.
TEST(TracePlausibility, ADragOverASharpEdgeIsAccepted) {
  const DragTrace trace = EdgeDrag(8.0);
  absl::StatusOr<TraceFit> fit = FitTrace(trace, FitOptions{});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_GT(std::acos(fit->friction.normal.z()) * 180 / kPi, 30.0);  // the drag's mean normal
  EXPECT_NEAR(fit->friction.mu, 0.3, 0.01);
  EXPECT_THAT(Checked(trace, TopCommand(4.0)), IsOk());
}

TEST(TracePlausibility, ADragOverAnEdgeInAnotherFrameIsStillRefused) {
  // The same drag read 40 degrees turned about the edge: the normal at the
  // site is 40 degrees off (the closest of the pairs near it, with noise).
  const Eigen::Matrix3d turned = Eigen::AngleAxisd(40.0 * kPi / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_THAT(Checked(EdgeDrag(8.0, turned), TopCommand(4.0)),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       ContainsRegex("implausible trace: normal: the estimated surface normal at the site is "
                                     "(39|40)\\.[0-9] deg")));
  // Turned 60 degrees about the site's normal: the drag ran aside.
  const Eigen::Matrix3d aside = Eigen::AngleAxisd(60.0 * kPi / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_THAT(CheckTraceAgainstCommand(EdgeDrag(8.0, aside), TopCommand(4.0), TraceLimits{}),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       HasSubstr("implausible trace: direction: the forward pass runs 60.0 deg off")));
}

}  // namespace
}  // namespace surfmap
