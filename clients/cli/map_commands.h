// `surfmap map get|query`, `surfmap sample get`, `surfmap trace get`,
// `surfmap refit`: reading maps, samples and raw traces, and re-estimation.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <CLI/CLI.hpp>
#include "absl/status/statusor.h"
#include "clients/cli/remote_command.h"

namespace surfmap::cli {

void AddMapCommands(CLI::App& app, std::shared_ptr<RemoteCli> cli);
void AddTraceCommands(CLI::App& app, std::shared_ptr<RemoteCli> cli);

// "X,Y,Z" (three finite numbers) -> the point. INVALID_ARGUMENT naming the text.
absl::StatusOr<Eigen::Vector3d> ParsePoint(std::string_view text);

// The map file format for `--format` (json, png, ply), or from the output
// file's extension when `format` is empty. INVALID_ARGUMENT otherwise.
absl::StatusOr<std::string> ResolveMapFormat(std::string_view format, std::string_view output_path);

}  // namespace surfmap::cli
