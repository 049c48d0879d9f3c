#include "server/frames/rig_frames.h"

#include <cmath>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace surfmap {
namespace {

constexpr double kPi = 3.14159265358979323846;

RigRegistration RandomRegistration(std::mt19937& rng, double tip_radius_mm = 3.0) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> t(-800.0, 800.0);
  RigRegistration r;
  r.object_rotation = Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized();
  r.object_translation_mm = {t(rng), t(rng), t(rng)};
  r.tip_radius_mm = tip_radius_mm;
  r.sensor_rotation = Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized();
  return r;
}

DragTrace SomeTrace(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  DragTrace trace;
  for (int i = 0; i < 50; ++i) {
    DragSample s;
    s.t = 0.01 * i;
    s.position = {10.0 * g(rng), 10.0 * g(rng), 10.0 * g(rng)};
    s.force = {g(rng), g(rng), 5.0 + g(rng)};
    s.phase = i < 20 ? DragPhase::kForward : (i < 25 ? DragPhase::kPause : DragPhase::kReverse);
    trace.samples.push_back(s);
  }
  return trace;
}

TEST(RigFramesTest, KnownPose) {
  RigRegistration r;
  r.object_rotation = Eigen::Quaterniond(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()));
  r.object_translation_mm = {100, 0, 0};
  const Eigen::Vector3d p = ObjectPointToBase(r, {1, 0, 0});
  EXPECT_NEAR((p - Eigen::Vector3d(100, 1, 0)).norm(), 0.0, 1e-12);
  const Eigen::Vector3d v = ObjectVectorToBase(r, {1, 0, 0});
  EXPECT_NEAR((v - Eigen::Vector3d(0, 1, 0)).norm(), 0.0, 1e-12);  // no translation for directions
}

TEST(RigFramesTest, PointsAndVectorsRoundTrip) {
  std::mt19937 rng(7);
  for (int k = 0; k < 100; ++k) {
    const RigRegistration r = RandomRegistration(rng);
    const Eigen::Vector3d p(rng() % 200 - 100.0, rng() % 200 - 100.0, 0.37 * k);
    EXPECT_LT((BasePointToObject(r, ObjectPointToBase(r, p)) - p).norm(), 1e-9);
    EXPECT_LT((ObjectVectorToBase(r, BaseVectorToObject(r, p)) - p).norm(), 1e-9);
    // A rigid motion keeps distances.
    EXPECT_NEAR((ObjectPointToBase(r, p) - ObjectPointToBase(r, Eigen::Vector3d::Zero())).norm(), p.norm(), 1e-9);
  }
}

TEST(RigFramesTest, TracesRoundTripInEveryFrame) {
  std::mt19937 rng(11);
  const DragTrace trace = SomeTrace(rng);
  for (TraceFrame frame : {TraceFrame::kObject, TraceFrame::kRigBase, TraceFrame::kRigBaseSensorForces}) {
    const RigRegistration r = RandomRegistration(rng);
    const DragTrace sent = TraceFromObjectFrame(trace, frame, r);
    const DragTrace back = TraceToObjectFrame(sent, frame, r);
    ASSERT_EQ(back.samples.size(), trace.samples.size());
    for (size_t i = 0; i < trace.samples.size(); ++i) {
      EXPECT_EQ(back.samples[i].t, trace.samples[i].t);
      EXPECT_EQ(back.samples[i].phase, trace.samples[i].phase);
      EXPECT_LT((back.samples[i].position - trace.samples[i].position).norm(), 1e-9) << TraceFrameName(frame);
      EXPECT_LT((back.samples[i].force - trace.samples[i].force).norm(), 1e-12) << TraceFrameName(frame);
    }
    if (frame != TraceFrame::kObject) {
      EXPECT_GT((sent.samples[0].position - trace.samples[0].position).norm(), 1.0);  // really moved
    }
  }
}

TEST(RigFramesTest, SensorForcesAreTurnedBySensorRotation) {
  RigRegistration r;  // object frame = base frame
  r.sensor_rotation = Eigen::Quaterniond(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitX()));
  DragTrace trace;
  trace.samples.push_back({0.0, {1, 2, 3}, {0, 0, 5}, DragPhase::kForward});
  const DragTrace sent = TraceFromObjectFrame(trace, TraceFrame::kRigBaseSensorForces, r);
  // f_base = S f_sensor: the sensor reads the base's +z as its -y... check by applying S.
  EXPECT_LT((r.sensor_rotation * sent.samples[0].force - Eigen::Vector3d(0, 0, 5)).norm(), 1e-12);
  EXPECT_LT((sent.samples[0].position - Eigen::Vector3d(1, 2, 3)).norm(), 1e-12);
  EXPECT_GT((sent.samples[0].force - Eigen::Vector3d(0, 0, 5)).norm(), 1.0);
}

TEST(RigFramesTest, InverseRegistrationIsRecognisedAsSuch) {
  std::mt19937 rng(3);
  const DragTrace trace = SomeTrace(rng);
  const RigRegistration r = RandomRegistration(rng);
  // A rig that applied base -> object to object data: q = R^T (p - t).
  DragTrace wrong = TraceToObjectFrame(trace, TraceFrame::kRigBase, r);
  const DragTrace back = InverseRegisteredTraceToObjectFrame(wrong, r);
  for (size_t i = 0; i < trace.samples.size(); ++i) {
    EXPECT_LT((back.samples[i].position - trace.samples[i].position).norm(), 1e-9);
  }
}

// On a sphere the tool centre (a ball of radius r rolling on it) stays at
// distance R + r from the centre, and sits along the outward normal of every
// contact point, in the base frame.
TEST(RigFramesTest, ToolCentreOffsetAlongTheNormalOnASphere) {
  std::mt19937 rng(5);
  const double R = 30.0, tip = 4.0;
  const RigRegistration r = RandomRegistration(rng, tip);
  const Eigen::Vector3d centre(5, -2, 7);
  std::vector<Eigen::Vector3d> points, normals;
  for (int i = 0; i <= 20; ++i) {  // a 20 mm arc of a great circle, 1 mm apart
    const double a = (i - 10) / R;
    const Eigen::Vector3d n(std::sin(a), 0.0, std::cos(a));
    points.push_back(centre + R * n);
    normals.push_back(n);
  }
  const Eigen::Vector3d site = centre + R * Eigen::Vector3d::UnitZ();
  const RigFrameCommand c =
      CommandInRigFrame(r, site, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(), points, normals);
  ASSERT_EQ(c.tool_centre_path.size(), points.size());
  const Eigen::Vector3d centre_base = ObjectPointToBase(r, centre);
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR((c.tool_centre_path[i] - centre_base).norm(), R + tip, 1e-9) << i;
    const Eigen::Vector3d contact = ObjectPointToBase(r, points[i]);
    const Eigen::Vector3d offset = c.tool_centre_path[i] - contact;
    EXPECT_NEAR(offset.norm(), tip, 1e-9);
    EXPECT_NEAR(offset.normalized().dot(ObjectVectorToBase(r, normals[i])), 1.0, 1e-12);
  }
  // The tool centre's path is longer than the contact's on a convex surface:
  // (R + r) / R.
  double contact_length = 0, centre_length = 0;
  for (size_t i = 1; i < points.size(); ++i) {
    contact_length += (points[i] - points[i - 1]).norm();
    centre_length += (c.tool_centre_path[i] - c.tool_centre_path[i - 1]).norm();
  }
  EXPECT_NEAR(centre_length / contact_length, (R + tip) / R, 1e-9);
  EXPECT_LT((c.start - ObjectPointToBase(r, points.front())).norm(), 1e-9);
  EXPECT_LT((c.end - ObjectPointToBase(r, points.back())).norm(), 1e-9);
  EXPECT_LT((c.position - ObjectPointToBase(r, site)).norm(), 1e-9);
  EXPECT_NEAR(c.normal.dot(ObjectVectorToBase(r, Eigen::Vector3d::UnitZ())), 1.0, 1e-12);
  EXPECT_NEAR(c.drag_direction.dot(ObjectVectorToBase(r, Eigen::Vector3d::UnitX())), 1.0, 1e-12);
}

// Inside a concave cylinder (a bowl's wall) the offset points inwards, to the
// axis: the tool centre is at R - r from it.
TEST(RigFramesTest, ToolCentreOnAConcaveCylinder) {
  RigRegistration r;
  r.tip_radius_mm = 2.5;
  const double R = 15.0;
  std::vector<Eigen::Vector3d> points, normals;
  for (int i = 0; i <= 10; ++i) {
    const double a = i / R;
    const Eigen::Vector3d radial(std::cos(a), std::sin(a), 0.0);
    points.push_back(R * radial + Eigen::Vector3d(0, 0, 3.0 * i));
    normals.push_back(-radial);  // outward from the material = towards the axis
  }
  const RigFrameCommand c = CommandInRigFrame(r, points[5], normals[5], Eigen::Vector3d::UnitY(), points, normals);
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(c.tool_centre_path[i].head<2>().norm(), R - 2.5, 1e-9);
  }
}

TEST(RigFramesTest, EmptyPathGivesTheSite) {
  RigRegistration r;
  r.tip_radius_mm = 1.0;
  const RigFrameCommand c = CommandInRigFrame(r, {1, 2, 3}, {0, 0, 1}, {1, 0, 0}, {}, {});
  EXPECT_EQ(c.start, c.end);
  ASSERT_EQ(c.tool_centre_path.size(), 1u);
  EXPECT_LT((c.tool_centre_path[0] - Eigen::Vector3d(1, 2, 4)).norm(), 1e-12);
}

TEST(RigFramesTest, FrameFitMeasuresOffsetAndForceDirection) {
  DragTrace trace;
  for (int i = 0; i < 10; ++i) {
    // friction +-1 N along x cancels between the passes
    trace.samples.push_back({0.1 * i, {double(i), 0, 0}, {-1, 0, 5}, DragPhase::kForward});
  }
  for (int i = 0; i < 10; ++i) {
    trace.samples.push_back({1.0 + 0.1 * i, {double(9 - i), 0, 0}, {1, 0, 5}, DragPhase::kReverse});
  }
  const FrameFit fit = MeasureFrameFit(trace, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
  EXPECT_DOUBLE_EQ(fit.max_offset_mm, 9.0);
  EXPECT_NEAR(fit.force_angle_deg, 0.0, 1e-9);
  EXPECT_NEAR(MeasureFrameFit(trace, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()).force_angle_deg, 90.0, 1e-9);
}

TEST(RigFramesTest, FrameNames) {
  for (TraceFrame f : {TraceFrame::kObject, TraceFrame::kRigBase, TraceFrame::kRigBaseSensorForces}) {
    absl::StatusOr<TraceFrame> parsed = ParseTraceFrame(TraceFrameName(f));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, f);
  }
  EXPECT_FALSE(ParseTraceFrame("base").ok());
}

}  // namespace
}  // namespace surfmap
