// surfmapd: the surfmap measurement service.
//   surfmapd --listen 127.0.0.1:PORT --db PATH [--config FILE] [--port-file F]
#include <fstream>
#include <iostream>
#include <sstream>

#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include "server/service/json_log_formatter.h"
#include "server/service/server_runner.h"
#include "server/service/text_log_formatter.h"
#include "surfmap_version.h"

int main(int argc, char** argv) {
  CLI::App app{"surfmapd: robotic mapping of surface friction and roughness (gRPC service)"};
  app.set_version_flag("--version", std::string("surfmapd ") + surfmap::kSurfmapVersion);
  std::string listen, db, config_path, port_file, log_format, log_level;
  app.add_option("--listen", listen, "Address to listen on, e.g. 127.0.0.1:50051 (port 0 = any free port)");
  app.add_option("--db", db, "SQLite database file (created if missing)");
  app.add_option("--config", config_path, "JSON config file (see deploy/surfmapd.example.json)")->check(CLI::ExistingFile);
  app.add_option("--port-file", port_file, "Write the bound port to this file once serving");
  app.add_option("--log-format", log_format, "text or json")->check(CLI::IsMember({"text", "json"}));
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error, critical, off");
  CLI11_PARSE(app, argc, argv);

  surfmap::ServerConfig config;
  if (!config_path.empty()) {
    std::ifstream in(config_path);
    if (!in) {
      std::cerr << "surfmapd: cannot read config file " << config_path << "\n";
      return 2;
    }
    std::stringstream text;
    text << in.rdbuf();
    absl::StatusOr<surfmap::ServerConfig> parsed = surfmap::ParseServerConfig(text.str(), config);
    if (!parsed.ok()) {
      std::cerr << "surfmapd: " << config_path << ": " << parsed.status().message() << "\n";
      return 2;
    }
    config = *parsed;
  }
  if (!listen.empty()) config.listen = listen;
  if (!db.empty()) config.db_path = db;
  if (!log_format.empty()) config.log_format = log_format;
  if (!log_level.empty()) config.log_level = log_level;
  std::string why;
  if (!config.IsValid(&why)) {
    std::cerr << "surfmapd: invalid configuration: " << why << "\n";
    return 2;
  }

  auto logger = spdlog::stderr_logger_mt("surfmapd");
  if (config.log_format == "json") {
    logger->set_formatter(std::make_unique<surfmap::JsonLogFormatter>());
  } else {
    logger->set_formatter(surfmap::MakeTextLogFormatter());
  }
  logger->set_level(spdlog::level::from_str(config.log_level));
  spdlog::set_default_logger(logger);

  absl::Status status = surfmap::RunServer(config, port_file);
  if (!status.ok()) {
    spdlog::error("surfmapd: {}", std::string(status.message()));
    return 1;
  }
  return 0;
}
