// `surfmap job import JOB FILE.csv [FILE...]`: drags recorded elsewhere (by
// hand, by another program) into a job's map (TraceService.ImportTrace).
#pragma once

#include <memory>

#include <CLI/CLI.hpp>
#include "clients/cli/remote_command.h"

namespace surfmap::cli {

void AddImportCommand(CLI::App* job, std::shared_ptr<RemoteCli> cli);

}  // namespace surfmap::cli
