#include "clients/rig/spool_file.h"

#include <cmath>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

namespace surfmap::rig {
namespace {

// Values that need all 17 digits, a subnormal and a negative zero: the file
// must give back the same bits.
DragTrace AwkwardTrace() {
  DragTrace trace;
  const double values[] = {0.1, 1.0 / 3.0, -2.718281828459045, 5e-324, -0.0, 123456789.12345678};
  const DragPhase phases[] = {DragPhase::kForward, DragPhase::kForward, DragPhase::kPause,
                              DragPhase::kReverse, DragPhase::kReverse, DragPhase::kReverse};
  for (int i = 0; i < 6; ++i) {
    DragSample s;
    s.t = 0.01 * i + 1e-9;
    s.position = Eigen::Vector3d(values[i], -values[(i + 1) % 6], values[(i + 2) % 6]);
    s.force = Eigen::Vector3d(values[(i + 3) % 6], values[(i + 4) % 6], 5.0 + values[(i + 5) % 6]);
    s.phase = phases[i];
    trace.samples.push_back(s);
  }
  return trace;
}

SpoolHeader Header() {
  SpoolHeader h;
  h.command_id = 17;
  h.job_id = 3;
  h.attempt = 2;
  h.rig_id = "lab arm #1";
  h.measured_unix_ms = 1795000000123;
  return h;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(SpoolFileTest, RoundTripsBitForBit) {
  const DragTrace trace = AwkwardTrace();
  auto text = FormatSpoolFile(Header(), trace);
  ASSERT_TRUE(text.ok()) << text.status();
  EXPECT_EQ(text->rfind(
                "# surfmap spooled trace v1\n# command_id: 17\n# job_id: 3\n# attempt: 2\n# rig_id: lab arm #1\n"
                "# measured_unix_ms: 1795000000123\nt,x,y,z,fx,fy,fz,phase\n",
                0),
            0u)
      << *text;
  auto parsed = ParseSpoolFile(*text, "f.csv");
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  EXPECT_EQ(parsed->header.command_id, 17);
  EXPECT_EQ(parsed->header.job_id, 3);
  EXPECT_EQ(parsed->header.attempt, 2);
  EXPECT_EQ(parsed->header.rig_id, "lab arm #1");
  EXPECT_EQ(parsed->header.measured_unix_ms, 1795000000123);
  ASSERT_EQ(parsed->trace.samples.size(), trace.samples.size());
  for (size_t i = 0; i < trace.samples.size(); ++i) {
    const DragSample& a = trace.samples[i];
    const DragSample& b = parsed->trace.samples[i];
    EXPECT_TRUE(SameBits(a.t, b.t)) << i;
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(SameBits(a.position[k], b.position[k])) << i << " position " << k;
      EXPECT_TRUE(SameBits(a.force[k], b.force[k])) << i << " force " << k;
    }
    EXPECT_EQ(a.phase, b.phase) << i;
  }
}

TEST(SpoolFileTest, KeepsTheFrameAndRegistrationOfARigFrameTrace) {
  SpoolHeader h = Header();
  h.frame = TraceFrame::kRigBaseSensorForces;
  h.registration_id = 7;
  auto text = FormatSpoolFile(h, AwkwardTrace());
  ASSERT_TRUE(text.ok()) << text.status();
  EXPECT_NE(text->find("# measured_unix_ms: 1795000000123\n# frame: rig_base_sensor_forces\n# registration_id: 7\n"
                       "t,x,y,z"),
            std::string::npos)
      << *text;
  auto parsed = ParseSpoolFile(*text, "f.csv");
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  EXPECT_EQ(parsed->header.frame, TraceFrame::kRigBaseSensorForces);
  EXPECT_EQ(parsed->header.registration_id, 7);
  EXPECT_EQ(parsed->trace.samples.size(), 6u);

  // A file from before frames (no keys) is in the object's frame.
  auto old = ParseSpoolFile(*FormatSpoolFile(Header(), AwkwardTrace()), "old.csv");
  ASSERT_TRUE(old.ok()) << old.status();
  EXPECT_EQ(old->header.frame, TraceFrame::kObject);
  EXPECT_EQ(old->header.registration_id, 0);

  auto replace = [&](const std::string& from, const std::string& to) {
    std::string t = *text;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  EXPECT_EQ(ParseSpoolFile(replace("rig_base_sensor_forces", "tool"), "f").status().message(),
            "f:7: frame: unknown trace frame \"tool\"; expected object, rig_base or rig_base_sensor_forces");
  EXPECT_EQ(ParseSpoolFile(replace("# registration_id: 7\n", ""), "f").status().message(),
            "f:8: expected '# registration_id: <value>' after the frame, found 't,x,y,z,fx,fy,fz,phase'");
  EXPECT_EQ(ParseSpoolFile(replace("# registration_id: 7", "# registration_id: x"), "f").status().message(),
            "f:8: registration_id 'x' is not an integer");
  h.frame = TraceFrame::kObject;
  EXPECT_EQ(FormatSpoolFile(h, AwkwardTrace()).status().message(),
            "registration_id 7 with the object's frame (a registration is for a rig frame)");
}

TEST(SpoolFileTest, BadHeadersAreNamed) {
  SpoolHeader h = Header();
  h.rig_id = "two\nlines";
  EXPECT_EQ(FormatSpoolFile(h, AwkwardTrace()).status().message(),
            "rig_id must not contain control characters (newline, tab, ...)");
  h = Header();
  h.command_id = 0;
  EXPECT_EQ(FormatSpoolFile(h, AwkwardTrace()).status().message(), "command_id 0 is not a command id (> 0)");
  h = Header();
  h.rig_id = std::string(101, 'r');
  EXPECT_EQ(FormatSpoolFile(h, AwkwardTrace()).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(SpoolFileTest, ParseErrorsNameTheLineAndTheProblem) {
  const std::string good = *FormatSpoolFile(Header(), AwkwardTrace());
  struct Case {
    std::string text;
    std::string message;
  };
  auto replace = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  const Case cases[] = {
      {"t,x,y,z,fx,fy,fz,phase\n", "f:1: not a spool file: the first line must be '# surfmap spooled trace v1'"},
      {replace("# job_id: 3\n", ""), "f:3: expected '# job_id: <value>', found '# attempt: 2'"},
      {replace("# job_id: 3", "# job_id: three"), "f:3: job_id 'three' is not an integer"},
      {replace("# job_id: 3", "# job_id: -3"), "f:2: header: job_id -3 is not a job id (> 0)"},
      {replace("# attempt: 2", "# attempt: -1"), "f:4: attempt -1 is out of range"},
      {"# surfmap spooled trace v1\n# command_id: 17\n", "f:3: missing header key 'job_id'"},
      {replace(",rev\n", ",sideways\n"), "f:"},  // the CSV reader's own message follows
  };
  for (const Case& c : cases) {
    auto parsed = ParseSpoolFile(c.text, "f");
    ASSERT_FALSE(parsed.ok()) << c.message;
    EXPECT_EQ(parsed.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_EQ(std::string(parsed.status().message()).rfind(c.message, 0), 0u) << parsed.status().message();
  }
  // The CSV's line numbers are the file's (the header lines count).
  auto bad_phase = ParseSpoolFile(replace("pause\n", "stop\n"), "f");
  EXPECT_NE(std::string(bad_phase.status().message()).find("f:10:"), std::string::npos) << bad_phase.status();
}

}  // namespace
}  // namespace surfmap::rig
