// `surfmap object register|registration`: a rig's registration to an object
// (frames and calibration; docs/trace-format.md, "Frames").
#pragma once

#include <memory>

#include <CLI/CLI.hpp>
#include "clients/cli/remote_command.h"

namespace surfmap::cli {

void AddRegistrationCommands(CLI::App& object, std::shared_ptr<RemoteCli> cli);

}  // namespace surfmap::cli
