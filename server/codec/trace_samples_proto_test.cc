#include "server/codec/trace_samples_proto.h"

#include <gtest/gtest.h>

namespace surfmap {
namespace {

namespace pb = ::surfmap::v1;

DragTrace ThreeSamples() {
  DragTrace trace;
  trace.samples.push_back({0.0, {1, 2, 3}, {4, 5, 6}, DragPhase::kForward});
  trace.samples.push_back({0.5, {1, 2, 3}, {0, 0, 6}, DragPhase::kPause});
  trace.samples.push_back({1.0, {7, 8, 9}, {-4, -5, 6}, DragPhase::kReverse});
  return trace;
}

TEST(TraceSamplesProtoTest, ColumnsInOrderAndBackExactly) {
  const DragTrace trace = ThreeSamples();
  const pb::TraceSamples s = DragTraceToProto(trace);
  ASSERT_EQ(s.t_size(), 3);
  EXPECT_EQ(s.phases_size(), 3);
  EXPECT_DOUBLE_EQ(s.x(2), 7.0);
  EXPECT_DOUBLE_EQ(s.fy(0), 5.0);
  EXPECT_EQ(s.phases(1), pb::PHASE_PAUSE);
  absl::StatusOr<DragTrace> back = DragTraceFromProto(s);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->samples.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back->samples[i].t, trace.samples[i].t);
    EXPECT_EQ(back->samples[i].position, trace.samples[i].position);
    EXPECT_EQ(back->samples[i].force, trace.samples[i].force);
    EXPECT_EQ(back->samples[i].phase, trace.samples[i].phase);
  }
}

TEST(TraceSamplesProtoTest, MalformedColumnsNameTheProblem) {
  pb::TraceSamples s = DragTraceToProto(ThreeSamples());
  pb::TraceSamples short_column = s;
  short_column.mutable_fy()->RemoveLast();
  absl::StatusOr<DragTrace> r = DragTraceFromProto(short_column);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("'fy' has 2 values"), std::string::npos) << r.status();

  pb::TraceSamples no_phase = s;
  no_phase.set_phases(2, pb::PHASE_UNSPECIFIED);
  r = DragTraceFromProto(no_phase);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("sample 2"), std::string::npos) << r.status();

  EXPECT_EQ(DragTraceFromProto(pb::TraceSamples()).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(DragTraceFromProto(s, /*max_samples=*/2).status().code(), absl::StatusCode::kResourceExhausted);
}

}  // namespace
}  // namespace surfmap
