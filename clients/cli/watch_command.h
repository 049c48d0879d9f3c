// `surfmap watch JOB`: follows a job's WatchJob stream until the job ends,
// as a live progress line on a terminal and as plain lines otherwise.
#pragma once

#include <memory>

#include <CLI/CLI.hpp>
#include "clients/cli/remote_command.h"

namespace surfmap::cli {

void AddWatchCommand(CLI::App& app, std::shared_ptr<RemoteCli> cli);

}  // namespace surfmap::cli
