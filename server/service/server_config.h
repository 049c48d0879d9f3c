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
  int max_trace_samples = 1'000'000;   // per submitted trace
  int max_query_points = 10'000;       // per QueryMap
  double shutdown_deadline_s = 10.0;   // in-flight calls get this long on SIGTERM
  int worker_threads = 2;              // pool for long work (maps, refits, mesh refinement, watchers)
  int probe_threads = 2;               // pool that fits the rigs' traces
  double default_lease_s = 60.0;       // probe command lease when a job does not set one
  std::string log_format = "text";     // "text" or "json" (one JSON object per line)
  std::string log_level = "info";      // spdlog level name
  std::map<std::string, Role> tokens;  // empty = open access (loopback lab)

  bool IsValid(std::string* why) const;
};

// Parses a JSON config: {"listen": "...", "db": "...", "max_message_mb": 64,
// "shutdown_deadline_s": 10, "worker_threads": 2, "default_lease_s": 60,
// "log_format": "json", "log_level": "info", "tokens": {"tok": "read", ...}}.
// Unknown keys are errors (a typo must not be silently ignored).
absl::StatusOr<ServerConfig> ParseServerConfig(const std::string& json_text, const ServerConfig& defaults);

}  // namespace surfmap
