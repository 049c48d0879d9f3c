// surfmap: command-line client. `surfmap fit` works offline; every other
// command talks to a surfmapd over gRPC (--server, --token, --timeout).
//
// A bare `surfmap`, or a command group without its subcommand (`surfmap job`),
// prints that level's help on stdout and exits 0: it is a person asking what
// there is, not a script's mistake (a wrong command still exits non-zero).
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "clients/cli/fit_command.h"
#include "clients/cli/job_commands.h"
#include "clients/cli/map_commands.h"
#include "clients/cli/object_commands.h"
#include "clients/cli/remote_command.h"
#include "clients/cli/watch_command.h"
#include "surfmap_version.h"

int main(int argc, char** argv) {
  CLI::App app{"surfmap: robotic mapping of surface friction and roughness"};
  app.set_version_flag("--version", std::string("surfmap ") + surfmap::kSurfmapVersion);
  int exit_code = 0;
  // First: subcommands inherit the fall-through of global options.
  auto remote = surfmap::cli::AddRemoteOptions(app, &exit_code);
  surfmap::cli::AddFitCommand(app, &exit_code);
  surfmap::cli::AddObjectCommands(app, remote);
  surfmap::cli::AddJobCommands(app, remote);
  surfmap::cli::AddMapCommands(app, remote);
  surfmap::cli::AddTraceCommands(app, remote);
  surfmap::cli::AddWatchCommand(app, remote);

  // Groups that need a subcommand accept none at parse time, so that the
  // bare group can print its help below instead of a "required" error.
  std::vector<CLI::App*> groups;
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    if (sub->get_require_subcommand_min() > 0) {
      sub->require_subcommand(0, 1);
      groups.push_back(sub);
    }
  }
  app.require_subcommand(0, 1);
  CLI11_PARSE(app, argc, argv);
  if (app.get_subcommands().empty()) {
    std::cout << app.help();
    return 0;
  }
  for (CLI::App* group : groups) {
    if (group->parsed() && group->get_subcommands().empty()) {
      std::cout << group->help();
      return 0;
    }
  }
  return exit_code;
}
