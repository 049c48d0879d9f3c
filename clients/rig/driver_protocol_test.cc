#include "clients/rig/driver_protocol.h"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

namespace surfmap::rig {
namespace {

namespace pb = ::surfmap::v1;

ProbeRequest Request() {
  ProbeRequest r;
  r.command_id = 17;
  r.job_id = 3;
  r.attempt = 2;
  r.site_level = 1;
  r.site_vertex = 12;
  r.position = Eigen::Vector3d(10.5, -2.25, 1.0 / 3.0);
  r.normal = Eigen::Vector3d(0, 0, 1);
  r.drag_direction = Eigen::Vector3d(1, 0, 0);
  r.segment_length_mm = 20;
  r.speed_mm_s = 10;
  r.normal_force_n = 5;
  r.lease_deadline_unix_ms = 1795000060000;
  return r;
}

TEST(DriverProtocolTest, TheCommandLineIsDocumentedAndReadsBack) {
  const std::string line = FormatCommandMessage(Request());
  EXPECT_EQ(line.find('\n'), std::string::npos);
  auto json = nlohmann::json::parse(line);
  EXPECT_EQ(json["type"], "command");
  EXPECT_EQ(json["protocol"], 1);
  EXPECT_EQ(json["site"]["vertex"], 12);
  EXPECT_EQ(json["position_mm"][2].get<double>(), 1.0 / 3.0) << "full precision";
  auto back = ParseCommandMessage(line);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->command_id, 17);
  EXPECT_EQ(back->job_id, 3);
  EXPECT_EQ(back->attempt, 2);
  EXPECT_EQ(back->site_level, 1);
  EXPECT_EQ(back->site_vertex, 12);
  EXPECT_EQ(back->position, Request().position);
  EXPECT_EQ(back->lease_deadline_unix_ms, 1795000060000);
}

TEST(DriverProtocolTest, TheRigFrameCommandIsPassedWhenRegistered) {
  EXPECT_FALSE(nlohmann::json::parse(FormatCommandMessage(Request())).contains("rig_frame"));
  ProbeRequest r = Request();
  RigFrameRequest frame;
  frame.registration_id = 4;
  frame.command.position = {400.5, 20, 1.0 / 7.0};
  frame.command.normal = {0, 1, 0};
  frame.command.start = {390.5, 20, 0};
  frame.command.end = {410.5, 20, 0};
  frame.command.tool_centre_path = {{390.5, 23, 0}, {410.5, 23, 0}};
  frame.tip_radius_mm = 3;
  r.rig_frame = frame;
  auto json = nlohmann::json::parse(FormatCommandMessage(r));
  ASSERT_TRUE(json.contains("rig_frame"));
  EXPECT_EQ(json["rig_frame"]["registration_id"], 4);
  EXPECT_EQ(json["rig_frame"]["position_mm"][2].get<double>(), 1.0 / 7.0);
  EXPECT_EQ(json["rig_frame"]["tool_centre_path_mm"].size(), 2u);
  EXPECT_EQ(json["rig_frame"]["tip_radius_mm"].get<double>(), 3.0);
  EXPECT_EQ(json["rig_frame"]["end_mm"][0].get<double>(), 410.5);
}

TEST(DriverProtocolTest, BadCommandsAreNamed) {
  auto with = [](const std::string& field, const nlohmann::json& value) {
    auto json = nlohmann::json::parse(FormatCommandMessage(Request()));
    if (value.is_discarded()) {
      json.erase(field);
    } else {
      json[field] = value;
    }
    return json.dump();
  };
  const nlohmann::json erase = nlohmann::json(nlohmann::json::value_t::discarded);
  EXPECT_EQ(ParseCommandMessage(with("speed_mm_s", erase)).status().message(),
            "command: field 'speed_mm_s' must be a number");
  EXPECT_EQ(ParseCommandMessage(with("normal", {0, 1})).status().message(),
            "command: field 'normal' must be an array of 3 numbers");
  EXPECT_EQ(ParseCommandMessage(with("protocol", 2)).status().message(), "command: protocol 2 is not 1");
  EXPECT_EQ(ParseCommandMessage(with("normal_force_n", 500)).status().message(),
            "command 17: probe normal_force_n 500 is not in (0, 100]");
  EXPECT_EQ(ParseCommandMessage(with("type", "trace")).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(ParseCommandMessage("{not json").status().message().find("line is not JSON"), std::string::npos);
}

DragTrace ThreeSamples() {
  DragTrace trace;
  const DragPhase phases[] = {DragPhase::kForward, DragPhase::kPause, DragPhase::kReverse};
  for (int i = 0; i < 3; ++i) {
    DragSample s;
    s.t = 0.1 * i;
    s.position = Eigen::Vector3d(i, 0.1, -0.2);
    s.force = Eigen::Vector3d(0.7, -0.3, 5.0 + 1e-13 * i);
    s.phase = phases[i];
    trace.samples.push_back(s);
  }
  return trace;
}

TEST(DriverProtocolTest, TracesRoundTripBitForBit) {
  const DragTrace trace = ThreeSamples();
  auto reply = ParseDriverReply(FormatTraceMessage(17, trace), 17);
  ASSERT_TRUE(reply.ok()) << reply.status();
  EXPECT_EQ(reply->type, DriverReply::Type::kTrace);
  ASSERT_EQ(reply->trace.samples.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const DragSample& a = trace.samples[i];
    const DragSample& b = reply->trace.samples[i];
    EXPECT_EQ(std::memcmp(&a.t, &b.t, sizeof a.t), 0);
    EXPECT_EQ(a.position, b.position);
    EXPECT_EQ(a.force, b.force);
    EXPECT_EQ(a.phase, b.phase);
  }
}

TEST(DriverProtocolTest, FailuresAndLogs) {
  auto unreachable = ParseDriverReply(FormatFailureMessage(5, pb::FAILURE_KIND_UNREACHABLE, "outside the box"), 5);
  ASSERT_TRUE(unreachable.ok()) << unreachable.status();
  EXPECT_EQ(unreachable->type, DriverReply::Type::kFailure);
  EXPECT_EQ(unreachable->kind, pb::FAILURE_KIND_UNREACHABLE);
  EXPECT_EQ(unreachable->reason, "outside the box");
  EXPECT_FALSE(unreachable->stop);
  auto stop = ParseDriverReply(R"({"type":"failure","command_id":5,"kind":"transient","reason":"e-stop","stop":true})", 5);
  ASSERT_TRUE(stop.ok());
  EXPECT_TRUE(stop->stop);
  auto log = ParseDriverReply(R"({"type":"log","message":"homing","extra":1})", 5);
  ASSERT_TRUE(log.ok());
  EXPECT_EQ(log->type, DriverReply::Type::kLog);
  EXPECT_EQ(log->message, "homing");
}

TEST(DriverProtocolTest, EveryProtocolErrorIsNamed) {
  const std::string good = FormatTraceMessage(9, ThreeSamples());
  auto replace = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  struct Case {
    std::string line;
    std::string message;
  };
  const Case cases[] = {
      {"Homing...", "line is not JSON ("},
      {"[1,2]", "line is not a JSON object: '[1,2]'"},
      {R"({"type":"trace","command_id":9,"t":[NaN]})",
       "line is not JSON: it holds NaN or Infinity (a measured value is not finite: report a failure instead)"},
      {R"({"type":"result","command_id":9})", "unknown message type 'result' (expected trace, failure or log): "},
      {good, ""},  // placeholder: replaced below by the other command id
      {replace("\"fz\":", "\"fzz\":"), "trace: field 'fz' must be an array of numbers"},
      {replace("\"fx\":[", "\"fx\":[1,"), "trace: column 'fx' has 4 values, column 't' has 3"},
      {replace("\"pause\"", "\"stop\""), "trace: phase[1] is \"stop\", not \"fwd\", \"pause\" or \"rev\""},
      {replace("\"t\":[0.0", "\"t\":[null"), "trace: t[0] is null (not finite?)"},
      {R"({"type":"trace","command_id":9,"t":[],"x":[],"y":[],"z":[],"fx":[],"fy":[],"fz":[],"phase":[]})",
       "trace: no samples"},
      {R"({"type":"failure","command_id":9,"kind":"sometimes","reason":"x"})",
       "failure: kind 'sometimes' is not \"transient\" or \"unreachable\""},
      {R"({"type":"failure","command_id":9,"kind":"transient","reason":""})",
       "failure: field 'reason' is empty (say what went wrong)"},
      {R"({"type":"failure","command_id":9,"kind":"transient"})", "failure: field 'reason' must be a string"},
  };
  for (const Case& c : cases) {
    if (c.message.empty()) {
      EXPECT_EQ(ParseDriverReply(c.line, 10).status().message(), "trace for command 9 while command 10 is being measured");
      continue;
    }
    auto reply = ParseDriverReply(c.line, 9);
    ASSERT_FALSE(reply.ok()) << c.line;
    EXPECT_EQ(reply.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_EQ(std::string(reply.status().message()).rfind(c.message, 0), 0u)
        << "got: " << reply.status().message() << "\nwant: " << c.message;
  }
}

TEST(DriverProtocolTest, TheReadyLine) {
  auto ready = ParseReadyMessage(FormatReadyMessage("UR5e + SensONE"));
  ASSERT_TRUE(ready.ok()) << ready.status();
  EXPECT_EQ(ready->driver, "UR5e + SensONE");
  EXPECT_EQ(ParseReadyMessage(R"({"type":"ready","protocol":2})").status().message(),
            "the driver speaks protocol 2, this surfmap-rig speaks protocol 1");
  EXPECT_EQ(ParseReadyMessage(R"({"type":"log","message":"x"})").status().message(),
            "the first line must be {\"type\":\"ready\",\"protocol\":1,...}, got '{\"type\":\"log\",\"message\":\"x\"}'");
}

}  // namespace
}  // namespace surfmap::rig
