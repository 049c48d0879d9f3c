#include "clients/cli/remote_command.h"

#include <cstdlib>

#include "clients/remote/proto_json.h"

namespace surfmap::cli {

std::shared_ptr<RemoteCli> AddRemoteOptions(CLI::App& app, int* exit_code) {
  auto cli = std::make_shared<RemoteCli>();
  cli->exit_code = exit_code;
  cli->options.server = std::string(kDefaultServer);
  app.add_option("--server", cli->options.server, "surfmapd address host:port")
      ->envname("SURFMAP_SERVER")
      ->capture_default_str();
  app.add_option("--token", cli->options.token, "Bearer token sent with every call")->envname("SURFMAP_TOKEN");
  app.add_option("--ca-file", cli->options.ca_file, "Connect with TLS, trusting the CA in this PEM file")
      ->envname("SURFMAP_CA_FILE")
      ->check(CLI::ExistingFile);
  app.add_option("--timeout", cli->options.timeout_s, "Deadline of every call, seconds (watch streams: none)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  // Global options may also follow the subcommand names.
  app.fallthrough();
  return cli;
}

void FailUsage(RemoteCli& cli, std::string_view what) {
  std::cout.flush();
  std::cerr << "surfmap: " << what << "\n";
  *cli.exit_code = kExitUsage;
}

std::string MessageToJson(const google::protobuf::Message& message, bool pretty) {
  return ProtoToJson(message).dump(pretty ? 2 : -1);
}

}  // namespace surfmap::cli
