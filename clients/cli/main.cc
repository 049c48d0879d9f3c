// surfmap: command-line client. `surfmap fit` works offline; every other
// command talks to a surfmapd over gRPC (--server, --token, --timeout).
#include <CLI/CLI.hpp>

#include "clients/cli/fit_command.h"
#include "clients/cli/job_commands.h"
#include "clients/cli/map_commands.h"
#include "clients/cli/object_commands.h"
#include "clients/cli/remote_command.h"
#include "clients/cli/watch_command.h"

int main(int argc, char** argv) {
  CLI::App app{"surfmap: robotic mapping of surface friction and roughness"};
  app.require_subcommand(1);
  int exit_code = 0;
  // First: subcommands inherit the fall-through of global options.
  auto remote = surfmap::cli::AddRemoteOptions(app, &exit_code);
  surfmap::cli::AddFitCommand(app, &exit_code);
  surfmap::cli::AddObjectCommands(app, remote);
  surfmap::cli::AddJobCommands(app, remote);
  surfmap::cli::AddMapCommands(app, remote);
  surfmap::cli::AddTraceCommands(app, remote);
  surfmap::cli::AddWatchCommand(app, remote);
  CLI11_PARSE(app, argc, argv);
  return exit_code;
}
