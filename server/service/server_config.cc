#include "server/service/server_config.h"

#include <set>

#include <nlohmann/json.hpp>
#include "absl/strings/str_cat.h"

namespace surfmap {

bool ServerConfig::IsValid(std::string* why) const {
  auto fail = [&](std::string text) {
    *why = std::move(text);
    return false;
  };
  if (listen.empty()) return fail("listen address is empty");
  if (db_path.empty()) return fail("database path is empty");
  if (max_message_bytes < 1024) return fail("max message size must be at least 1 KiB");
  if (max_trace_samples < 10) return fail("max_trace_samples must be at least 10");
  if (max_query_points < 1) return fail("max_query_points must be at least 1");
  if (!(shutdown_deadline_s >= 0 && shutdown_deadline_s <= 600)) return fail("shutdown_deadline_s must be in [0, 600]");
  if (worker_threads < 1 || worker_threads > 64) return fail("worker_threads must be in [1, 64]");
  if (probe_threads < 1 || probe_threads > 64) return fail("probe_threads must be in [1, 64]");
  if (!(default_lease_s > 0 && default_lease_s <= 86400)) return fail("default_lease_s must be in (0, 86400]");
  if (log_format != "text" && log_format != "json") return fail("log_format must be 'text' or 'json'");
  return true;
}

absl::StatusOr<ServerConfig> ParseServerConfig(const std::string& json_text, const ServerConfig& defaults) {
  nlohmann::json j = nlohmann::json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return absl::InvalidArgumentError("config: not valid JSON");
  if (!j.is_object()) return absl::InvalidArgumentError("config: top level must be a JSON object");
  static const std::set<std::string> kKeys = {"listen",          "db",         "max_message_mb", "max_trace_samples",
                                              "max_query_points", "shutdown_deadline_s", "worker_threads", "probe_threads",
                                              "default_lease_s", "log_format", "log_level",      "tokens"};
  ServerConfig c = defaults;
  try {
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (!kKeys.count(it.key())) return absl::InvalidArgumentError(absl::StrCat("config: unknown key '", it.key(), "'"));
    }
    if (j.contains("listen")) c.listen = j["listen"].get<std::string>();
    if (j.contains("db")) c.db_path = j["db"].get<std::string>();
    if (j.contains("max_message_mb")) c.max_message_bytes = static_cast<int>(j["max_message_mb"].get<double>() * (1 << 20));
    if (j.contains("max_trace_samples")) c.max_trace_samples = j["max_trace_samples"].get<int>();
    if (j.contains("max_query_points")) c.max_query_points = j["max_query_points"].get<int>();
    if (j.contains("shutdown_deadline_s")) c.shutdown_deadline_s = j["shutdown_deadline_s"].get<double>();
    if (j.contains("worker_threads")) c.worker_threads = j["worker_threads"].get<int>();
    if (j.contains("probe_threads")) c.probe_threads = j["probe_threads"].get<int>();
    if (j.contains("default_lease_s")) c.default_lease_s = j["default_lease_s"].get<double>();
    if (j.contains("log_format")) c.log_format = j["log_format"].get<std::string>();
    if (j.contains("log_level")) c.log_level = j["log_level"].get<std::string>();
    if (j.contains("tokens")) {
      c.tokens.clear();
      for (auto& [token, role_text] : j["tokens"].items()) {
        Role role;
        if (!ParseRole(role_text.get<std::string>(), &role)) {
          return absl::InvalidArgumentError(
              absl::StrCat("config: token role must be read, probe or steer, got '", role_text.get<std::string>(), "'"));
        }
        if (token.size() < 16) return absl::InvalidArgumentError("config: tokens must be at least 16 characters");
        c.tokens[token] = role;
      }
    }
  } catch (const nlohmann::json::exception& e) {
    return absl::InvalidArgumentError(absl::StrCat("config: ", e.what()));
  }
  std::string why;
  if (!c.IsValid(&why)) return absl::InvalidArgumentError("config: " + why);
  return c;
}

}  // namespace surfmap
