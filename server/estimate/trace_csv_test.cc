#include "server/estimate/trace_csv.h"

#include <string>

#include <gtest/gtest.h>
#include "clients/sim/dragsim/drag_geometry.h"
#include "clients/sim/dragsim/drag_simulator.h"

namespace surfmap {
namespace {

constexpr char kHeader[] = "t,x,y,z,fx,fy,fz,phase\n";

std::string Good() {
  return std::string(kHeader) +
         "0,0,0,0,-0.5,0,5,fwd\n"
         "0.01,0.1,0,0,-0.5,0,5,fwd\n"
         "0.02,0.1,0,0,-0.2,0,5,pause\n"
         "0.03,0.1,0,0,0.5,0,5,rev\n"
         "0.04,0,0,0,0.5,0,5,rev\n";
}

TEST(TraceCsvTest, ParsesAGoodTrace) {
  absl::StatusOr<DragTrace> trace = ParseTraceCsv(Good(), "good.csv");
  ASSERT_TRUE(trace.ok()) << trace.status();
  ASSERT_EQ(trace->samples.size(), 5u);
  EXPECT_DOUBLE_EQ(trace->samples[1].t, 0.01);
  EXPECT_DOUBLE_EQ(trace->samples[1].position.x(), 0.1);
  EXPECT_DOUBLE_EQ(trace->samples[0].force.z(), 5.0);
  EXPECT_EQ(trace->samples[2].phase, DragPhase::kPause);
  EXPECT_EQ(trace->samples[4].phase, DragPhase::kReverse);
}

TEST(TraceCsvTest, AcceptsColumnsInAnyOrderCommentsBlanksCrlfAndNoPause) {
  const std::string text =
      "# a comment before the header\r\n"
      "\r\n"
      "phase, fz,fy,fx,z,y,x,t\r\n"
      "fwd,5,0,-0.5,3,2,1,0\r\n"
      "  # an indented comment\n"
      "fwd,5,0,-0.5,3,2,1.1,0.01\n"
      "\n"
      "rev,5,0,0.5,3,2,1,0.02\n";
  absl::StatusOr<DragTrace> trace = ParseTraceCsv(text, "any.csv");
  ASSERT_TRUE(trace.ok()) << trace.status();
  ASSERT_EQ(trace->samples.size(), 3u);
  EXPECT_EQ(trace->samples[0].position, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(trace->samples[0].force, Eigen::Vector3d(-0.5, 0, 5));
  EXPECT_DOUBLE_EQ(trace->samples[2].t, 0.02);
}

struct BadCase {
  const char* name;
  std::string text;
  const char* expected;  // fragment of the message, including "<source>:<line>:"
};

TEST(TraceCsvTest, RejectsEveryBadInputWithLineAndProblem) {
  const std::string h = kHeader;
  const std::string f0 = "0,0,0,0,-0.5,0,5,fwd\n";
  const std::string f1 = "0.01,0.1,0,0,-0.5,0,5,fwd\n";
  const std::string r2 = "0.02,0.1,0,0,0.5,0,5,rev\n";
  const BadCase cases[] = {
      {"empty", "", "bad.csv:1: missing header line"},
      {"only comments", "# nothing\n\n", "bad.csv:2: missing header line"},
      {"data before header", f0 + h, "bad.csv:1: missing header line (found data"},
      {"missing column", "t,x,y,z,fx,fy,phase\n" + f0, "bad.csv:1: header: missing column 'fz'"},
      {"unknown column", "t,x,y,z,fx,fy,fz,phase,temp\n", "bad.csv:1: header has 9 columns"},
      {"renamed column", "t,x,y,z,fx,fy,Fz,phase\n", "bad.csv:1: header: unknown column 'Fz'"},
      {"duplicate column", "t,x,y,z,fx,fy,fx,phase\n", "bad.csv:1: header: duplicate column 'fx'"},
      {"too few fields", h + "0,0,0,0,-0.5,0,fwd\n", "bad.csv:2: expected 8 fields, found 7"},
      {"too many fields", h + "0,0,0,0,-0.5,0,5,fwd,1\n", "bad.csv:2: expected 8 fields, found 9"},
      {"text for number", h + f0 + "0.01,abc,0,0,-0.5,0,5,fwd\n",
       "bad.csv:3: column 'x': 'abc' is not a number"},
      {"trailing junk", h + "0,0,0,0,-0.5x,0,5,fwd\n", "bad.csv:2: column 'fx': '-0.5x' is not a number"},
      {"empty field", h + "0,0,,0,-0.5,0,5,fwd\n", "bad.csv:2: column 'y' is empty"},
      {"plus sign", h + "0,+1,0,0,-0.5,0,5,fwd\n", "bad.csv:2: column 'x': '+1' is not a number"},
      {"nan", h + "0,0,0,0,nan,0,5,fwd\n", "bad.csv:2: column 'fx': 'nan' is not finite"},
      {"inf", h + "0,0,0,0,0,0,inf,fwd\n", "bad.csv:2: column 'fz': 'inf' is not finite"},
      {"overflow", h + "0,1e999,0,0,0,0,5,fwd\n", "bad.csv:2: column 'x': '1e999' is out of the range"},
      {"time repeats", h + f0 + "0,0.1,0,0,-0.5,0,5,fwd\n", "bad.csv:3: time 0 s does not increase"},
      {"time goes back", h + f1 + f0, "bad.csv:3: time 0 s does not increase (previous sample at 0.01 s)"},
      {"unknown phase", h + f0 + "0.01,0,0,0,-0.5,0,5,back\n",
       "bad.csv:3: unknown phase 'back' (expected fwd, pause or rev)"},
      {"phase case", h + "0,0,0,0,-0.5,0,5,FWD\n", "bad.csv:2: unknown phase 'FWD'"},
      {"fwd after rev", h + f0 + "0.01,0,0,0,0.5,0,5,rev\n" + "0.02,0,0,0,-0.5,0,5,fwd\n",
       "bad.csv:4: phase 'fwd' after 'rev'"},
      {"pause after rev", h + f0 + "0.01,0,0,0,0.5,0,5,rev\n" + "0.02,0,0,0,0,0,5,pause\n",
       "bad.csv:4: phase 'pause' after 'rev'"},
      {"starts with rev", h + "0,0,0,0,0.5,0,5,rev\n", "bad.csv:2: first sample has phase 'rev'"},
      {"no reverse", h + f0 + f1, "bad.csv:3: end of input: no reverse (rev) samples"},
      {"header only", h, "bad.csv:1: end of input: no forward (fwd) samples"},
  };
  for (const BadCase& c : cases) {
    absl::StatusOr<DragTrace> trace = ParseTraceCsv(c.text, "bad.csv");
    ASSERT_FALSE(trace.ok()) << c.name;
    EXPECT_EQ(trace.status().code(), absl::StatusCode::kInvalidArgument) << c.name;
    EXPECT_NE(std::string(trace.status().message()).find(c.expected), std::string::npos)
        << c.name << ": got \"" << trace.status().message() << "\", expected \"" << c.expected
        << "\"";
  }
}

TEST(TraceCsvTest, RoundTripsASimulatedTraceExactly) {
  DragSimOptions options;
  options.seed = 11;
  absl::StatusOr<DragSimResult> sim =
      SimulateDrag(CylinderGeometry(40.0, 20.0), UniformMaterial(kRubber), options);
  ASSERT_TRUE(sim.ok()) << sim.status();
  const std::string text = FormatTraceCsv(sim->trace);
  absl::StatusOr<DragTrace> back = ParseTraceCsv(text, "sim.csv");
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->samples.size(), sim->trace.samples.size());
  for (std::size_t i = 0; i < back->samples.size(); ++i) {
    const DragSample& a = sim->trace.samples[i];
    const DragSample& b = back->samples[i];
    ASSERT_EQ(a.t, b.t) << i;
    ASSERT_EQ(a.position, b.position) << i;
    ASSERT_EQ(a.force, b.force) << i;
    ASSERT_EQ(a.phase, b.phase) << i;
  }
  EXPECT_EQ(FormatTraceCsv(*back), text);
}

}  // namespace
}  // namespace surfmap
