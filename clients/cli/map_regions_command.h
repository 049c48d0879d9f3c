// `surfmap map regions`: a job's material regions with their estimates and,
// with --pieces, the drag pieces behind each (GetMap's MapRegion.pieces), so
// a region's mu can be checked against the drags that made it.
#pragma once

#include <memory>

#include <CLI/CLI.hpp>
#include "clients/cli/remote_command.h"

namespace surfmap::cli {

// Adds `regions` under the `map` command.
void AddMapRegionsCommand(CLI::App& map, std::shared_ptr<RemoteCli> cli);

}  // namespace surfmap::cli
