// `surfmap job create|list|show|import|pause|resume|cancel|plan`: steering mapping jobs.
#pragma once

#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include "clients/cli/remote_command.h"
#include "proto/surfmap/v1/surfmap.pb.h"

namespace surfmap::cli {

void AddJobCommands(CLI::App& app, std::shared_ptr<RemoteCli> cli);

// The human-readable form of `surfmap job show`: state, spec, progress per level.
std::string FormatJobInfo(const surfmap::v1::JobInfo& job);

}  // namespace surfmap::cli
