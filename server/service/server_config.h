// surfmapd's settings: defaults, then the --config JSON file, then flags.
#pragma once

#include <map>
#include <string>

#include "absl/status/statusor.h"
#include "server/service/request_gate.h"

namespace surfmap {

struct ServerConfig {
  std::string listen = "127.0.0.1:50051";
  std::string db_path = "surfmap.db";
  int max_message_bytes = 64 << 20;    // larger requests get RESOURCE_EXHAUSTED
  int max_trace_samples = 1'000'000;   // per submitted trace (unary or streamed), every column
  int max_query_points = 10'000;       // per QueryMap
  double shutdown_deadline_s = 10.0;   // in-flight calls get this long on SIGTERM
  int worker_threads = 2;              // pool for long work (maps, refits, mesh refinement, watchers)
  int probe_threads = 2;               // pool that fits the rigs' traces
  double default_lease_s = 60.0;       // probe command lease when a job does not set one
  std::string log_format = "text";     // "text" or "json" (one JSON object per line)
  std::string log_level = "info";      // trace, debug, info, warn, error, critical, off
  std::map<std::string, Role> tokens;  // empty = open access (loopback lab)
  // TLS: both PEM files, or neither (plaintext). With a client CA, every
  // client must present a certificate signed by it.
  std::string tls_cert_file;
  std::string tls_key_file;
  std::string tls_client_ca_file;

  // Names the first invalid setting, its allowed range and its unit.
  bool IsValid(std::string* why) const;
  bool tls() const { return !tls_cert_file.empty(); }
};

// The limits of each numeric setting, in the config file's units.
inline constexpr double kMinMessageMb = 1, kMaxMessageMb = 1024;  // gRPC's limit is an int of bytes
inline constexpr int kMaxTraceSamplesLimit = 4'000'000;  // ~64 bytes a sample held twice: ~0.5 GB
inline constexpr int kMaxQueryPointsLimit = 1'000'000;
inline constexpr double kMinLeaseS = 0.1, kMaxLeaseS = 86'400;  // a job's own lease has the same range

// Parses a JSON config: {"listen": "...", "db": "...", "max_message_mb": 64,
// "max_trace_samples": 1000000, "max_query_points": 10000,
// "shutdown_deadline_s": 10, "worker_threads": 2, "probe_threads": 2,
// "default_lease_s": 60, "log_format": "json", "log_level": "info",
// "tokens": {"tok": "read", ...}, "tls_cert_file": "...", "tls_key_file": "...",
// "tls_client_ca_file": "..."}. Unknown keys are errors (a typo must not be
// silently ignored); every number is range-checked as a double before it is
// converted, so no value overflows into a misleading one.
absl::StatusOr<ServerConfig> ParseServerConfig(const std::string& json_text, const ServerConfig& defaults);

}  // namespace surfmap
