// ExternalDriver against real driver programs: small /bin/sh scripts that
// speak (or break) the protocol.
#include "clients/rig/external_driver.h"

#include <unistd.h>

#include <vector>

#include <gtest/gtest.h>

namespace surfmap::rig {
namespace {

// Answers every command with a three-sample trace for its command id, after a log line.
constexpr char kEchoDriver[] = R"(
echo '{"type":"log","message":"homing"}'
echo '{"type":"ready","protocol":1,"driver":"shell echo driver"}'
while read -r line; do
  id=$(printf '%s' "$line" | sed 's/.*"command_id":\([0-9]*\).*/\1/')
  echo "{\"type\":\"log\",\"message\":\"measuring $id\"}"
  echo "{\"type\":\"trace\",\"command_id\":$id,\"t\":[0,0.1,0.2],\"x\":[0,1,0],\"y\":[0,0,0],\"z\":[0,0,0],\"fx\":[-1,0,1],\"fy\":[0,0,0],\"fz\":[5,5,5],\"phase\":[\"fwd\",\"pause\",\"rev\"]}"
done
echo '{"type":"log","message":"stdin closed, parking"}'
)";

constexpr char kReady[] = R"(echo '{"type":"ready","protocol":1}'; )";

ProbeRequest Request(int64_t command_id) {
  ProbeRequest r;
  r.command_id = command_id;
  r.job_id = 1;
  return r;
}

struct Logged {
  std::vector<std::string> lines;
  ExternalDriverOptions Options(const std::string& command) {
    ExternalDriverOptions options;
    options.command = command;
    options.start_timeout_s = 10;
    options.command_timeout_s = 10;
    options.exit_grace_s = 5;
    options.on_log = [this](const std::string& line) { lines.push_back(line); };
    return options;
  }
};

TEST(ExternalDriverTest, SpeaksTheProtocolAndPassesLogsOn) {
  Logged log;
  {
    auto driver = ExternalDriver::Start(log.Options(kEchoDriver));
    ASSERT_TRUE(driver.ok()) << driver.status();
    EXPECT_EQ((*driver)->name(), "shell echo driver");
    for (int64_t id : {5, 6}) {
      auto trace = (*driver)->Execute(Request(id));
      ASSERT_TRUE(trace.ok()) << trace.status();
      ASSERT_EQ(trace->samples.size(), 3u);
      EXPECT_EQ(trace->samples[2].phase, DragPhase::kReverse);
      EXPECT_DOUBLE_EQ(trace->samples[0].force.x(), -1.0);
    }
    EXPECT_EQ((*driver)->starts(), 1);
  }  // closes stdin: the driver logs and exits 0
  EXPECT_EQ(log.lines, (std::vector<std::string>{"driver: homing", "driver ready: shell echo driver",
                                                 "driver: measuring 5", "driver: measuring 6",
                                                 "driver: stdin closed, parking", "driver exited with code 0"}));
}

TEST(ExternalDriverTest, FailuresBecomeTheRigDriverCodes) {
  Logged log;
  auto driver = ExternalDriver::Start(log.Options(std::string(kReady) + R"(
read -r a; echo '{"type":"failure","command_id":1,"kind":"unreachable","reason":"outside the workspace box"}'
read -r b; echo '{"type":"failure","command_id":2,"kind":"transient","reason":"force ceiling 15 N exceeded"}'
read -r c; echo '{"type":"failure","command_id":3,"kind":"transient","reason":"emergency stop","stop":true}'
cat > /dev/null)"));
  ASSERT_TRUE(driver.ok()) << driver.status();
  auto a = (*driver)->Execute(Request(1));
  EXPECT_EQ(a.status(), absl::FailedPreconditionError("outside the workspace box"));
  auto b = (*driver)->Execute(Request(2));
  EXPECT_EQ(b.status(), absl::UnavailableError("force ceiling 15 N exceeded"));
  auto c = (*driver)->Execute(Request(3));
  EXPECT_EQ(c.status(), absl::AbortedError("emergency stop"));
}

TEST(ExternalDriverTest, StartFailuresSayWhy) {
  Logged log;
  auto missing = ExternalDriver::Start(log.Options("/nonexistent/robot-driver --port /dev/ttyUSB0"));
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_EQ(missing.status().message(),
            "driver '/nonexistent/robot-driver --port /dev/ttyUSB0' exited with code 127 before its ready line "
            "(command not found?)");

  ExternalDriverOptions slow = log.Options("sleep 30");
  slow.start_timeout_s = 0.3;
  auto silent = ExternalDriver::Start(slow);
  EXPECT_EQ(silent.status().code(), absl::StatusCode::kDeadlineExceeded);
  EXPECT_NE(silent.status().message().find("wrote no ready line within 0 s"), std::string::npos) << silent.status();

  auto chatty = ExternalDriver::Start(log.Options("echo 'Connecting to robot at 192.168.0.10'; sleep 30"));
  EXPECT_EQ(chatty.status().code(), absl::StatusCode::kInternal);
  EXPECT_NE(chatty.status().message().find("broke the protocol: line is not JSON"), std::string::npos)
      << chatty.status();

  ExternalDriverOptions empty = log.Options(" ");
  EXPECT_EQ(ExternalDriver::Start(empty).status(), absl::InvalidArgumentError("the driver command is empty"));
}

TEST(ExternalDriverTest, ATimedOutDriverIsStoppedAndRestartedForTheNextCommand) {
  Logged log;
  ExternalDriverOptions options = log.Options(std::string(kReady) + "read -r line; sleep 30");
  options.command_timeout_s = 0.3;
  auto driver = ExternalDriver::Start(options);
  ASSERT_TRUE(driver.ok()) << driver.status();
  auto first = (*driver)->Execute(Request(1));
  EXPECT_EQ(first.status().code(), absl::StatusCode::kDeadlineExceeded);
  EXPECT_EQ(first.status().message(),
            "driver did not answer command 1 within 0 s; it was stopped and a fresh one starts for the next command");
  auto second = (*driver)->Execute(Request(2));
  EXPECT_EQ(second.status().code(), absl::StatusCode::kDeadlineExceeded);
  EXPECT_EQ((*driver)->starts(), 2);
}

TEST(ExternalDriverTest, ADyingDriverIsRestartedAFewTimesThenGivenUp) {
  Logged log;
  ExternalDriverOptions options = log.Options(std::string(kReady) + "read -r line; exit 3");
  options.max_restarts = 2;
  auto driver = ExternalDriver::Start(options);
  ASSERT_TRUE(driver.ok()) << driver.status();
  for (int64_t id = 1; id <= 3; ++id) {
    auto trace = (*driver)->Execute(Request(id));
    EXPECT_EQ(trace.status(), absl::UnavailableError(absl::StrCat("the driver exited with code 3 while measuring command ", id)));
  }
  auto given_up = (*driver)->Execute(Request(4));
  EXPECT_EQ(given_up.status(), absl::InternalError("driver failed 3 times in a row without a trace; not restarted"));
  EXPECT_EQ((*driver)->starts(), 3);
}

TEST(ExternalDriverTest, ProtocolErrorsAreInternalAndNamed) {
  struct Case {
    const char* script;
    const char* message;
  };
  const Case cases[] = {
      {"read -r l; echo 'moving to approach pose'; cat >/dev/null",
       "driver protocol: line is not JSON ("},
      {R"(read -r l; echo '{"type":"trace","command_id":99}'; cat >/dev/null)",
       "driver protocol: trace for command 99 while command 7 is being measured"},
      {R"(read -r l; echo '{"type":"trace","command_id":7,"t":[NaN]}'; cat >/dev/null)",
       "driver protocol: line is not JSON: it holds NaN or Infinity"},
  };
  for (const Case& c : cases) {
    Logged log;
    auto driver = ExternalDriver::Start(log.Options(std::string(kReady) + c.script));
    ASSERT_TRUE(driver.ok()) << driver.status();
    auto trace = (*driver)->Execute(Request(7));
    EXPECT_EQ(trace.status().code(), absl::StatusCode::kInternal) << c.script;
    EXPECT_EQ(std::string(trace.status().message()).rfind(c.message, 0), 0u) << trace.status();
  }
}

TEST(ExternalDriverTest, ADriverThatStoppedReadingIsNoSigpipeForTheRig) {
  Logged log;
  // Closes its stdin at once, then waits: the command cannot be written.
  auto driver = ExternalDriver::Start(log.Options(std::string(kReady) + "exec 0<&-; sleep 1"));
  ASSERT_TRUE(driver.ok()) << driver.status();
  ::usleep(100'000);
  auto trace = (*driver)->Execute(Request(1));
  EXPECT_EQ(trace.status().code(), absl::StatusCode::kUnavailable) << trace.status();
  EXPECT_NE(trace.status().message().find("no longer reads its stdin"), std::string::npos) << trace.status();
}

}  // namespace
}  // namespace surfmap::rig
