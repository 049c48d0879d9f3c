#include "server/service/server_config.h"

#include "gtest/gtest.h"

namespace surfmap {
namespace {

std::string ErrorOf(const std::string& json) {
  absl::StatusOr<ServerConfig> c = ParseServerConfig(json, ServerConfig{});
  return c.ok() ? "OK" : std::string(c.status().message());
}

TEST(ServerConfig, NumbersAreRangeCheckedInTheirUnitsBeforeAnyConversion) {
  EXPECT_EQ(ErrorOf(R"({"max_message_mb": 2048})"), "config: max_message_mb must be a number in 1..1024 MB, got 2048");
  EXPECT_EQ(ErrorOf(R"({"max_trace_samples": 1e12})"),
            "config: max_trace_samples must be an integer in 10..4000000 samples, got 1000000000000.0");
  EXPECT_EQ(ErrorOf(R"({"max_trace_samples": 4294967306})"),  // 2^32 + 10: wrapped to 10 as an int
            "config: max_trace_samples must be an integer in 10..4000000 samples, got 4294967306");
  EXPECT_EQ(ErrorOf(R"({"default_lease_s": 1e-9})"), "config: default_lease_s must be a number in 0.1..86400 s, got 1e-09");
  EXPECT_EQ(ErrorOf(R"({"worker_threads": 2.5})"), "config: worker_threads must be an integer in 1..64 threads, got 2.5");
  EXPECT_EQ(ErrorOf(R"({"worker_threads": "2"})"), "config: worker_threads must be an integer in 1..64 threads, got \"2\"");
  EXPECT_EQ(ErrorOf(R"({"max_message_mb": 8, "max_trace_samples": 2e5, "default_lease_s": 0.1})"), "OK");
  absl::StatusOr<ServerConfig> c = ParseServerConfig(R"({"max_message_mb": 1024, "max_trace_samples": 4e6})", {});
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_EQ(c->max_message_bytes, 1 << 30);
  EXPECT_EQ(c->max_trace_samples, 4'000'000);
}

TEST(ServerConfig, LogLevelsAndTlsKeys) {
  EXPECT_EQ(ErrorOf(R"({"log_level": "garbage"})"),
            "config: log_level must be one of trace, debug, info, warn, error, critical, off; got 'garbage'");
  EXPECT_EQ(ErrorOf(R"({"log_level": "warn"})"), "OK");
  EXPECT_EQ(ErrorOf(R"({"tls_key_file": "k.pem"})"),
            "config: tls_cert_file and tls_key_file go together: set both (TLS) or neither (plaintext)");
  EXPECT_EQ(ErrorOf(R"({"tls_cert_file": "c.pem", "tls_key_file": "k.pem", "tls_client_ca_file": "ca.pem"})"), "OK");
  EXPECT_EQ(ErrorOf(R"({"tls_cert_file": 3, "tls_key_file": "k.pem"})"), "config: tls_cert_file must be a string");
}

TEST(ServerConfig, TokensAreNeverEchoed) {
  const std::string error = ErrorOf(R"({"tokens": {"secret-but-short": "admin"}})");
  EXPECT_EQ(error, "config: token role must be read, probe or steer, got \"admin\"");
  EXPECT_EQ(ErrorOf(R"({"tokens": {"short": "read"}})").find("short"), std::string::npos);
}

}  // namespace
}  // namespace surfmap
