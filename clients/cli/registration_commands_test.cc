// `surfmap object register`'s option rules: a pose needs its tip radius, and
// --json takes none of the options it replaces (CLI11 refuses before any RPC).
#include "clients/cli/registration_commands.h"

#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace surfmap::cli {
namespace {

// Parses `surfmap object ARGS...`; the answer is the CLI11 error's message,
// or "" when parsing went through (and the command ran: see exit_code).
struct Parsed {
  std::string error;
  int exit_code = kExitOk;
};

Parsed ParseObject(std::vector<std::string> args) {
  Parsed out;
  CLI::App app("surfmap");
  CLI::App* object = app.add_subcommand("object");
  auto cli = std::make_shared<RemoteCli>();
  cli->exit_code = &out.exit_code;
  cli->options.server = "127.0.0.1:1";  // nothing listens: a command that runs fails its RPC at once
  cli->options.timeout_s = 0.5;
  AddRegistrationCommands(*object, cli);
  args.insert(args.begin(), "object");
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them last first
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    out.error = e.what();
  }
  return out;
}

TEST(RegistrationCommandsTest, APoseNeedsATipRadius) {
  Parsed p = ParseObject({"register", "5", "--rig", "arm", "--pose", "1,0,0,0,400,0,0"});
  EXPECT_EQ(p.error, "--pose requires --tip-radius-mm");
  // Neither --pose nor --json: the command says what to give.
  p = ParseObject({"register", "5", "--rig", "arm", "--tip-radius-mm", "2"});
  EXPECT_EQ(p.error, "");
  EXPECT_EQ(p.exit_code, kExitUsage);
}

TEST(RegistrationCommandsTest, JsonTakesNoneOfThePoseOptions) {
  // check(ExistingFile) needs a file.
  const std::string file = ::testing::TempDir() + "registration_commands_test.json";
  { std::ofstream(file) << "{}"; }
  EXPECT_EQ(ParseObject({"register", "5", "--rig", "arm", "--json", file, "--tip-radius-mm", "2"}).error,
            "--tip-radius-mm excludes --json");
  EXPECT_EQ(ParseObject({"register", "5", "--rig", "arm", "--json", file, "--sensor", "1,0,0,0"}).error,
            "--sensor excludes --json");
  EXPECT_EQ(ParseObject({"register", "5", "--rig", "arm", "--json", file, "--pose", "1,0,0,0,1,2,3",
                          "--tip-radius-mm", "2"}).error,
            "--pose excludes --json");
}

TEST(RegistrationCommandsTest, ACompletePoseReachesTheServer) {
  Parsed p = ParseObject({"register", "5", "--rig", "arm", "--pose", "1,0,0,0,400,0,0", "--tip-radius-mm", "2",
                          "--sensor", "1,0,0,0"});
  EXPECT_EQ(p.error, "");
  EXPECT_EQ(p.exit_code, kExitRpcError);  // parsed, then the RPC failed (no server)
}

}  // namespace
}  // namespace surfmap::cli
