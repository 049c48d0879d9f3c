// surfmap: command-line client. `surfmap fit` works offline; every other
// command talks to a surfmapd over gRPC (--server).
#include <CLI/CLI.hpp>

#include "clients/cli/fit_command.h"

int main(int argc, char** argv) {
  CLI::App app{"surfmap: robotic mapping of surface friction and roughness"};
  app.require_subcommand(1);
  int exit_code = 0;
  surfmap::cli::AddFitCommand(app, &exit_code);
  CLI11_PARSE(app, argc, argv);
  return exit_code;
}
