// surfmapd started with bad settings: each row is a config file (or flags)
// the server must refuse at start, with its exit code and a message on stderr
// that names the setting, its range and its unit. Before the hardening these
// overflowed into misleading values (max_message_mb 2048, max_trace_samples
// 1e12), were accepted and failed later (default_lease_s 1e-9, a database
// the server cannot write) or silently turned logging off (log_level).
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "tests/support/child_process.h"
#include "tests/support/server_process.h"
#include "tests/support/temp_dir.h"

namespace surfmap::itest {
namespace {

struct ConfigRow {
  std::string name;
  std::string config_json;               // empty: no --config
  std::vector<std::string> extra_args;
  int exit_code;                         // 2: invalid configuration, 1: refused at start
  std::string message;                   // must appear in the output
};

// Runs surfmapd with `row`'s settings in a fresh directory; the output.
struct Outcome {
  int exit_code = -1;
  std::string output;
};

Outcome RunSurfmapd(const TempDir& dir, const ConfigRow& row, const std::vector<std::string>& prefix = {},
                  const std::string& db = "") {
  std::vector<std::string> argv = prefix;
  argv.push_back(DefaultSurfmapdPath());
  for (const std::string& a : {std::string("--listen"), std::string("127.0.0.1:0"), std::string("--db"),
                               db.empty() ? dir.File("surfmap.db") : db, std::string("--port-file"),
                               dir.File("port")}) {
    argv.push_back(a);
  }
  if (!row.config_json.empty()) {
    std::ofstream(dir.File("config.json")) << row.config_json;
    argv.push_back("--config");
    argv.push_back(dir.File("config.json"));
  }
  argv.insert(argv.end(), row.extra_args.begin(), row.extra_args.end());
  Outcome outcome;
  auto child = ChildProcess::Start(argv, dir.File("output.log"));
  if (!child.ok()) {
    outcome.output = std::string(child.status().message());
    return outcome;
  }
  auto code = (*child)->Wait(std::chrono::seconds(30));
  outcome.output = (*child)->Output();
  if (code.ok()) outcome.exit_code = *code;
  else outcome.output += "\n" + std::string(code.status().message());
  return outcome;
}

TEST(HostileConfigTest, BadSettingsAreRefusedAtStartNamingTheSettingAndItsRange) {
  const std::vector<ConfigRow> rows = {
      {"max_message_mb 2048 (2^31 bytes overflowed an int)", R"({"max_message_mb": 2048})", {}, 2,
       "max_message_mb must be a number in 1..1024 MB, got 2048"},
      {"max_message_mb 0.5", R"({"max_message_mb": 0.5})", {}, 2, "max_message_mb must be a number in 1..1024 MB"},
      {"max_trace_samples 1e12 (overflowed an int)", R"({"max_trace_samples": 1e12})", {}, 2,
       "max_trace_samples must be an integer in 10..4000000 samples"},
      {"max_trace_samples 2.5", R"({"max_trace_samples": 2.5})", {}, 2, "max_trace_samples must be an integer"},
      {"max_query_points -3", R"({"max_query_points": -3})", {}, 2, "max_query_points must be an integer in 1..1000000"},
      {"worker_threads as a string", R"({"worker_threads": "two"})", {}, 2, "worker_threads must be an integer in 1..64"},
      {"probe_threads 1e300", R"({"probe_threads": 1e300})", {}, 2, "probe_threads must be an integer in 1..64 threads"},
      {"shutdown_deadline_s -1", R"({"shutdown_deadline_s": -1})", {}, 2, "shutdown_deadline_s must be a number in 0..600 s"},
      {"default_lease_s 1e-9 (every CreateJob failed later)", R"({"default_lease_s": 1e-9})", {}, 2,
       "default_lease_s must be a number in 0.1..86400 s"},
      {"log_level garbage (logging went silent)", R"({"log_level": "garbage"})", {}, 2,
       "log_level must be one of trace, debug, info, warn, error, critical, off; got 'garbage'"},
      {"--log-level garbage on the command line", "", {"--log-level", "garbage"}, 2, "log_level must be one of"},
      {"log_format xml", R"({"log_format": "xml"})", {}, 2, "log_format must be 'text' or 'json'"},
      {"unknown key", R"({"max_mesage_mb": 8})", {}, 2, "unknown key 'max_mesage_mb'"},
      {"a token shorter than 16 characters", R"({"tokens": {"short": "read"}})", {}, 2, "at least 16 characters"},
      {"a token with an unknown role", R"({"tokens": {"a-long-enough-token-0001": "admin"}})", {}, 2,
       "token role must be read, probe or steer"},
      {"tls_cert_file without tls_key_file", R"({"tls_cert_file": "/etc/hostname"})", {}, 2,
       "tls_cert_file and tls_key_file go together"},
      {"tls_client_ca_file without a certificate", R"({"tls_client_ca_file": "/etc/hostname"})", {}, 2,
       "tls_client_ca_file needs tls_cert_file"},
      {"TLS files that do not exist", R"({"tls_cert_file": "/nonexistent/cert.pem", "tls_key_file": "/nonexistent/key.pem"})",
       {}, 1, "tls_cert_file: cannot read '/nonexistent/cert.pem'"},
      {"a TLS certificate that is not PEM", R"({"tls_cert_file": "/etc/hostname", "tls_key_file": "/etc/hostname"})", {},
       1, "holds no PEM block"},
      {"not JSON", "{max_message_mb: 8", {}, 2, "not valid JSON"},
  };
  for (const ConfigRow& row : rows) {
    SCOPED_TRACE(row.name);
    auto dir = TempDir::Create("surfmap-config");
    ASSERT_TRUE(dir.ok()) << dir.status();
    const Outcome outcome = RunSurfmapd(*dir, row);
    std::cout << "  " << row.name << " -> exit " << outcome.exit_code << ": "
              << outcome.output.substr(0, outcome.output.find('\n')) << "\n";
    EXPECT_EQ(outcome.exit_code, row.exit_code) << outcome.output;
    EXPECT_NE(outcome.output.find(row.message), std::string::npos)
        << "expected \"" << row.message << "\" in:\n" << outcome.output;
    EXPECT_EQ(access(dir->File("port").c_str(), F_OK), -1) << "the server served although it should have refused";
  }
}

TEST(HostileConfigTest, ADatabaseTheServerCannotWriteIsRefusedAtStart) {
  auto dir = TempDir::Create("surfmap-readonly");
  ASSERT_TRUE(dir.ok()) << dir.status();
  // A directory that does not exist.
  {
    const Outcome outcome = RunSurfmapd(*dir, {"", "", {}, 1, ""}, {}, "/nonexistent-dir/surfmap.db");
    std::cout << "  missing directory -> exit " << outcome.exit_code << ": " << outcome.output << "\n";
    EXPECT_EQ(outcome.exit_code, 1);
    EXPECT_NE(outcome.output.find("its directory '/nonexistent-dir' does not exist"), std::string::npos)
        << outcome.output;
  }
  // A database made by one user, the server started as another (nobody)
  // that may read it but not write it: refused before it serves, instead of
  // failing every write later. Root may write anything, hence the other user.
  {
    auto server = ServerProcess::Start();
    ASSERT_TRUE(server.ok()) << server.status();
    ASSERT_TRUE((*server)->Stop(std::chrono::seconds(30)).ok());
    ASSERT_EQ(chmod((*server)->dir().c_str(), 0755), 0);
    ASSERT_EQ(chmod((*server)->db_path().c_str(), 0644), 0);
    std::vector<std::string> as_nobody = {"/usr/bin/setpriv", "--reuid=65534", "--regid=65534", "--clear-groups"};
    if (getuid() != 0) as_nobody.clear();  // not root: the test's own user may not write a 0444 file
    if (getuid() != 0) {
      ASSERT_EQ(chmod((*server)->db_path().c_str(), 0444), 0);
    }
    ASSERT_EQ(chmod(dir->path().c_str(), 0777), 0);  // the port file and the log
    const Outcome outcome = RunSurfmapd(*dir, {"", "", {}, 1, ""}, as_nobody, (*server)->db_path());
    std::cout << "  database not writable -> exit " << outcome.exit_code << ": " << outcome.output << "\n";
    EXPECT_EQ(outcome.exit_code, 1);
    EXPECT_NE(outcome.output.find("is not writable by this process"), std::string::npos) << outcome.output;
    EXPECT_NE(outcome.output.find((*server)->db_path()), std::string::npos) << outcome.output;
  }
}

}  // namespace
}  // namespace surfmap::itest
