// `surfmap object upload|list|show`: the meshes a job can map.
#pragma once

#include <memory>

#include <CLI/CLI.hpp>
#include "clients/cli/remote_command.h"

namespace surfmap::cli {

void AddObjectCommands(CLI::App& app, std::shared_ptr<RemoteCli> cli);

}  // namespace surfmap::cli
