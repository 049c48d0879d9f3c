#include "server/service/server_config.h"

#include <cmath>
#include <set>

#include <nlohmann/json.hpp>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace surfmap {
namespace {

bool KnownLogLevel(const std::string& level) {
  static const std::set<std::string> kLevels = {"trace", "debug", "info", "warn", "error", "critical", "off"};
  return kLevels.count(level) > 0;
}

// "<key> must be <what> in <min>..<max> <unit>, got <value>".
absl::Status OutOfRange(const std::string& key, const char* what, double min, double max, const char* unit,
                        const std::string& got) {
  return absl::InvalidArgumentError(
      absl::StrFormat("config: %s must be %s in %.15g..%.15g %s, got %s", key, what, min, max, unit, got));
}

// A number in [min, max] (checked as a double: no cast before the check).
absl::StatusOr<double> NumberIn(const nlohmann::json& j, const std::string& key, double min, double max,
                                const char* unit) {
  const nlohmann::json& v = j.at(key);
  if (!v.is_number()) return OutOfRange(key, "a number", min, max, unit, v.dump());
  const double d = v.get<double>();
  if (!std::isfinite(d) || d < min || d > max) return OutOfRange(key, "a number", min, max, unit, v.dump());
  return d;
}

absl::StatusOr<int> IntegerIn(const nlohmann::json& j, const std::string& key, int min, int max, const char* unit) {
  const nlohmann::json& v = j.at(key);
  const bool integral = v.is_number_integer() || (v.is_number_float() && std::trunc(v.get<double>()) == v.get<double>());
  if (!integral) return OutOfRange(key, "an integer", min, max, unit, v.dump());
  absl::StatusOr<double> d = NumberIn(j, key, min, max, unit);
  if (!d.ok()) return OutOfRange(key, "an integer", min, max, unit, v.dump());
  return static_cast<int>(*d);
}

absl::StatusOr<std::string> Text(const nlohmann::json& j, const std::string& key) {
  if (!j.at(key).is_string()) return absl::InvalidArgumentError(absl::StrCat("config: ", key, " must be a string"));
  return j.at(key).get<std::string>();
}

}  // namespace

bool ServerConfig::IsValid(std::string* why) const {
  auto fail = [&](std::string text) {
    *why = std::move(text);
    return false;
  };
  if (listen.empty()) return fail("listen address is empty");
  if (db_path.empty()) return fail("database path is empty");
  if (max_message_bytes < kMinMessageMb * (1 << 20) || max_message_bytes > kMaxMessageMb * (1 << 20)) {
    return fail(absl::StrFormat("max_message_mb must be in %g..%g MB", kMinMessageMb, kMaxMessageMb));
  }
  if (max_trace_samples < 10 || max_trace_samples > kMaxTraceSamplesLimit) {
    return fail(absl::StrCat("max_trace_samples must be in 10..", kMaxTraceSamplesLimit, " samples"));
  }
  if (max_query_points < 1 || max_query_points > kMaxQueryPointsLimit) {
    return fail(absl::StrCat("max_query_points must be in 1..", kMaxQueryPointsLimit, " points"));
  }
  if (!(shutdown_deadline_s >= 0 && shutdown_deadline_s <= 600)) return fail("shutdown_deadline_s must be in 0..600 s");
  if (worker_threads < 1 || worker_threads > 64) return fail("worker_threads must be in 1..64 threads");
  if (probe_threads < 1 || probe_threads > 64) return fail("probe_threads must be in 1..64 threads");
  if (!(default_lease_s >= kMinLeaseS && default_lease_s <= kMaxLeaseS)) {
    return fail(absl::StrFormat("default_lease_s must be in %g..%g s (a job's lease has the same range), got %g",
                                kMinLeaseS, kMaxLeaseS, default_lease_s));
  }
  if (log_format != "text" && log_format != "json") return fail("log_format must be 'text' or 'json'");
  if (!KnownLogLevel(log_level)) {
    return fail(absl::StrCat("log_level must be one of trace, debug, info, warn, error, critical, off; got '",
                             log_level, "'"));
  }
  if (tls_cert_file.empty() != tls_key_file.empty()) {
    return fail("tls_cert_file and tls_key_file go together: set both (TLS) or neither (plaintext)");
  }
  if (!tls_client_ca_file.empty() && tls_cert_file.empty()) {
    return fail("tls_client_ca_file needs tls_cert_file and tls_key_file (client certificates are checked over TLS)");
  }
  return true;
}

absl::StatusOr<ServerConfig> ParseServerConfig(const std::string& json_text, const ServerConfig& defaults) {
  nlohmann::json j = nlohmann::json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return absl::InvalidArgumentError("config: not valid JSON");
  if (!j.is_object()) return absl::InvalidArgumentError("config: top level must be a JSON object");
  static const std::set<std::string> kKeys = {
      "listen",          "db",          "max_message_mb", "max_trace_samples", "max_query_points",
      "shutdown_deadline_s", "worker_threads", "probe_threads", "default_lease_s", "log_format",
      "log_level",       "tokens",      "tls_cert_file",  "tls_key_file",      "tls_client_ca_file"};
  ServerConfig c = defaults;
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!kKeys.count(it.key())) return absl::InvalidArgumentError(absl::StrCat("config: unknown key '", it.key(), "'"));
  }
  // Assigns `key` from `parse` when present; returns early on an error.
#define SURFMAP_CONFIG_FIELD(key, field, parse)            \
  if (j.contains(key)) {                                   \
    auto value = parse;                                    \
    if (!value.ok()) return value.status();                \
    field = *value;                                        \
  }
  SURFMAP_CONFIG_FIELD("listen", c.listen, Text(j, "listen"));
  SURFMAP_CONFIG_FIELD("db", c.db_path, Text(j, "db"));
  if (j.contains("max_message_mb")) {
    absl::StatusOr<double> mb = NumberIn(j, "max_message_mb", kMinMessageMb, kMaxMessageMb, "MB");
    if (!mb.ok()) return mb.status();
    c.max_message_bytes = static_cast<int>(*mb * (1 << 20));  // <= 1 GiB: fits an int
  }
  SURFMAP_CONFIG_FIELD("max_trace_samples", c.max_trace_samples,
                       IntegerIn(j, "max_trace_samples", 10, kMaxTraceSamplesLimit, "samples"));
  SURFMAP_CONFIG_FIELD("max_query_points", c.max_query_points,
                       IntegerIn(j, "max_query_points", 1, kMaxQueryPointsLimit, "points"));
  SURFMAP_CONFIG_FIELD("shutdown_deadline_s", c.shutdown_deadline_s, NumberIn(j, "shutdown_deadline_s", 0, 600, "s"));
  SURFMAP_CONFIG_FIELD("worker_threads", c.worker_threads, IntegerIn(j, "worker_threads", 1, 64, "threads"));
  SURFMAP_CONFIG_FIELD("probe_threads", c.probe_threads, IntegerIn(j, "probe_threads", 1, 64, "threads"));
  SURFMAP_CONFIG_FIELD("default_lease_s", c.default_lease_s,
                       NumberIn(j, "default_lease_s", kMinLeaseS, kMaxLeaseS, "s"));
  SURFMAP_CONFIG_FIELD("log_format", c.log_format, Text(j, "log_format"));
  SURFMAP_CONFIG_FIELD("log_level", c.log_level, Text(j, "log_level"));
  SURFMAP_CONFIG_FIELD("tls_cert_file", c.tls_cert_file, Text(j, "tls_cert_file"));
  SURFMAP_CONFIG_FIELD("tls_key_file", c.tls_key_file, Text(j, "tls_key_file"));
  SURFMAP_CONFIG_FIELD("tls_client_ca_file", c.tls_client_ca_file, Text(j, "tls_client_ca_file"));
#undef SURFMAP_CONFIG_FIELD
  if (j.contains("tokens")) {
    if (!j["tokens"].is_object()) {
      return absl::InvalidArgumentError("config: tokens must be an object {\"<token>\": \"read|probe|steer\"}");
    }
    c.tokens.clear();
    for (auto& [token, role_text] : j["tokens"].items()) {
      Role role;
      if (!role_text.is_string() || !ParseRole(role_text.get<std::string>(), &role)) {
        return absl::InvalidArgumentError(
            absl::StrCat("config: token role must be read, probe or steer, got ", role_text.dump()));
      }
      // The token itself is never echoed: config errors reach logs.
      if (token.size() < 16) return absl::InvalidArgumentError("config: tokens must be at least 16 characters");
      c.tokens[token] = role;
    }
  }
  std::string why;
  if (!c.IsValid(&why)) return absl::InvalidArgumentError("config: " + why);
  return c;
}

}  // namespace surfmap
