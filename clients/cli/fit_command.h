// `surfmap fit TRACE.csv ...`: offline friction and roughness fits of drag traces.
#pragma once

#include <CLI/CLI.hpp>

namespace surfmap::cli {

// Adds the `fit` subcommand to `app`; its callback sets `*exit_code`.
void AddFitCommand(CLI::App& app, int* exit_code);

}  // namespace surfmap::cli
