// Runs surfmapd: opens the store, restores jobs, serves gRPC until SIGTERM or
// SIGINT, then shuts down within the configured deadline.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "server/service/server_config.h"

namespace surfmap {

// `port_file`: if not empty, the bound port is written there (atomically)
// once the server accepts calls. Blocks until shutdown.
absl::Status RunServer(const ServerConfig& config, const std::string& port_file);

}  // namespace surfmap
