#include "clients/rig/driver_protocol.h"

#include <cmath>
#include <optional>

#include "absl/strings/str_cat.h"
#include "clients/rig/json_number.h"

namespace surfmap::rig {

namespace pb = ::surfmap::v1;
using nlohmann::json;

namespace {

// This abseil build's absl::string_view is not std::string_view.
absl::string_view A(std::string_view s) { return absl::string_view(s.data(), s.size()); }

// The first 80 characters of a line, for messages.
std::string Quote(std::string_view line) {
  std::string text(line.substr(0, 80));
  if (line.size() > 80) text += "...";
  return absl::StrCat("'", text, "'");
}

json Vector(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

absl::StatusOr<json> ParseObject(std::string_view line) {
  json value;
  try {
    value = json::parse(line);
  } catch (const json::parse_error& error) {
    if (line.find("NaN") != std::string_view::npos || line.find("Infinity") != std::string_view::npos) {
      return absl::InvalidArgumentError(
          "line is not JSON: it holds NaN or Infinity (a measured value is not finite: report a failure instead)");
    }
    return absl::InvalidArgumentError(absl::StrCat("line is not JSON (", error.what(), "): ", Quote(line)));
  }
  if (!value.is_object()) return absl::InvalidArgumentError(absl::StrCat("line is not a JSON object: ", Quote(line)));
  return value;
}

absl::Status Missing(std::string_view what, std::string_view field, std::string_view kind) {
  return absl::InvalidArgumentError(absl::StrCat(A(what), ": field '", A(field), "' must be ", A(kind)));
}

absl::StatusOr<std::int64_t> Integer(const json& object, std::string_view what, const char* field) {
  auto it = object.find(field);
  if (it == object.end() || !it->is_number_integer()) return Missing(what, field, "an integer");
  return it->get<std::int64_t>();
}

absl::StatusOr<double> Real(const json& object, std::string_view what, const char* field) {
  auto it = object.find(field);
  if (it == object.end() || !it->is_number()) return Missing(what, field, "a number");
  return it->get<double>();
}

absl::StatusOr<Eigen::Vector3d> Vector3(const json& object, std::string_view what, const char* field) {
  auto it = object.find(field);
  if (it == object.end() || !it->is_array() || it->size() != 3 ||
      !((*it)[0].is_number() && (*it)[1].is_number() && (*it)[2].is_number())) {
    return Missing(what, field, "an array of 3 numbers");
  }
  return Eigen::Vector3d((*it)[0].get<double>(), (*it)[1].get<double>(), (*it)[2].get<double>());
}

absl::StatusOr<std::string> Text(const json& object, std::string_view what, const char* field) {
  auto it = object.find(field);
  if (it == object.end() || !it->is_string()) return Missing(what, field, "a string");
  return it->get<std::string>();
}

std::optional<DragPhase> PhaseFromName(const std::string& name) {
  if (name == "fwd") return DragPhase::kForward;
  if (name == "pause") return DragPhase::kPause;
  if (name == "rev") return DragPhase::kReverse;
  return std::nullopt;
}

absl::StatusOr<DragTrace> TraceFromMessage(const json& object) {
  static const char* kColumns[] = {"t", "x", "y", "z", "fx", "fy", "fz"};
  const json* columns[7];
  size_t n = 0;
  for (int c = 0; c < 7; ++c) {
    auto it = object.find(kColumns[c]);
    if (it == object.end() || !it->is_array()) return Missing("trace", kColumns[c], "an array of numbers");
    if (c == 0) n = it->size();
    if (it->size() != n) {
      return absl::InvalidArgumentError(absl::StrCat("trace: column '", kColumns[c], "' has ", it->size(),
                                                     " values, column 't' has ", n));
    }
    columns[c] = &*it;
  }
  auto phases = object.find("phase");
  if (phases == object.end() || !phases->is_array()) return Missing("trace", "phase", "an array of \"fwd\"/\"pause\"/\"rev\"");
  if (phases->size() != n) {
    return absl::InvalidArgumentError(
        absl::StrCat("trace: column 'phase' has ", phases->size(), " values, column 't' has ", n));
  }
  if (n == 0) return absl::InvalidArgumentError("trace: no samples");
  DragTrace trace;
  trace.samples.resize(n);
  for (size_t i = 0; i < n; ++i) {
    double values[7];
    for (int c = 0; c < 7; ++c) {
      const json& v = (*columns[c])[i];
      if (!v.is_number()) {
        return absl::InvalidArgumentError(absl::StrCat("trace: ", kColumns[c], "[", i, "] is ",
                                                       v.is_null() ? "null (not finite?)" : "not a number"));
      }
      values[c] = v.get<double>();
      if (!std::isfinite(values[c])) {
        return absl::InvalidArgumentError(absl::StrCat("trace: ", kColumns[c], "[", i, "] is not finite"));
      }
    }
    const json& p = (*phases)[i];
    std::optional<DragPhase> phase = p.is_string() ? PhaseFromName(p.get<std::string>()) : std::nullopt;
    if (!phase) {
      return absl::InvalidArgumentError(absl::StrCat("trace: phase[", i, "] is ", p.dump(), ", not \"fwd\", \"pause\" or \"rev\""));
    }
    DragSample& s = trace.samples[i];
    s.t = values[0];
    s.position = Eigen::Vector3d(values[1], values[2], values[3]);
    s.force = Eigen::Vector3d(values[4], values[5], values[6]);
    s.phase = *phase;
  }
  return trace;
}

}  // namespace

std::string FormatCommandMessage(const ProbeRequest& r) {
  json message = {{"type", "command"},
                  {"protocol", kDriverProtocolVersion},
                  {"command_id", r.command_id},
                  {"job_id", r.job_id},
                  {"attempt", r.attempt},
                  {"site", {{"level", r.site_level}, {"vertex", r.site_vertex}}},
                  {"position_mm", Vector(r.position)},
                  {"normal", Vector(r.normal)},
                  {"drag_direction", Vector(r.drag_direction)},
                  {"segment_length_mm", r.segment_length_mm},
                  {"speed_mm_s", r.speed_mm_s},
                  {"normal_force_n", r.normal_force_n},
                  {"lease_deadline_unix_ms", r.lease_deadline_unix_ms}};
  if (r.rig_frame) {
    // The same command in the rig's base frame (the rig is registered to the object).
    const RigFrameCommand& f = r.rig_frame->command;
    json path = json::array();
    for (const Eigen::Vector3d& p : f.tool_centre_path) path.push_back(Vector(p));
    message["rig_frame"] = {{"registration_id", r.rig_frame->registration_id},
                            {"position_mm", Vector(f.position)},
                            {"normal", Vector(f.normal)},
                            {"drag_direction", Vector(f.drag_direction)},
                            {"start_mm", Vector(f.start)},
                            {"end_mm", Vector(f.end)},
                            {"tool_centre_path_mm", path},
                            {"tip_radius_mm", r.rig_frame->tip_radius_mm}};
  }
  return message.dump();
}

std::string FormatReadyMessage(std::string_view driver) {
  return json{{"type", "ready"}, {"protocol", kDriverProtocolVersion}, {"driver", std::string(driver)}}.dump(
      -1, ' ', false, json::error_handler_t::replace);
}

std::string FormatTraceMessage(std::int64_t command_id, const DragTrace& trace) {
  json t = json::array(), x = json::array(), y = json::array(), z = json::array(), fx = json::array(),
       fy = json::array(), fz = json::array(), phase = json::array();
  for (const DragSample& s : trace.samples) {
    t.push_back(FiniteOrNull(s.t));
    x.push_back(FiniteOrNull(s.position.x()));
    y.push_back(FiniteOrNull(s.position.y()));
    z.push_back(FiniteOrNull(s.position.z()));
    fx.push_back(FiniteOrNull(s.force.x()));
    fy.push_back(FiniteOrNull(s.force.y()));
    fz.push_back(FiniteOrNull(s.force.z()));
    phase.push_back(std::string(DragPhaseName(s.phase)));
  }
  json message = {{"type", "trace"}, {"command_id", command_id}, {"t", t}, {"x", x}, {"y", y}, {"z", z},
                  {"fx", fx},        {"fy", fy},                 {"fz", fz}, {"phase", phase}};
  return message.dump();
}

std::string FormatFailureMessage(std::int64_t command_id, pb::FailureKind kind, std::string_view reason, bool stop) {
  json message = {{"type", "failure"},
                  {"command_id", command_id},
                  {"kind", kind == pb::FAILURE_KIND_UNREACHABLE ? "unreachable" : "transient"},
                  {"reason", std::string(reason)},
                  {"stop", stop}};
  return message.dump(-1, ' ', false, json::error_handler_t::replace);
}

absl::StatusOr<ProbeRequest> ParseCommandMessage(std::string_view line) {
  absl::StatusOr<json> parsed = ParseObject(line);
  if (!parsed.ok()) return parsed.status();
  const json& m = *parsed;
  absl::StatusOr<std::string> type = Text(m, "command", "type");
  if (!type.ok() || *type != "command") {
    return absl::InvalidArgumentError(absl::StrCat("not a command message: ", Quote(line)));
  }
  absl::StatusOr<std::int64_t> protocol = Integer(m, "command", "protocol");
  if (!protocol.ok()) return protocol.status();
  if (*protocol != kDriverProtocolVersion) {
    return absl::InvalidArgumentError(absl::StrCat("command: protocol ", *protocol, " is not ", kDriverProtocolVersion));
  }
  ProbeRequest r;
  auto command_id = Integer(m, "command", "command_id");
  auto job_id = Integer(m, "command", "job_id");
  auto attempt = Integer(m, "command", "attempt");
  auto lease = Integer(m, "command", "lease_deadline_unix_ms");
  auto position = Vector3(m, "command", "position_mm");
  auto normal = Vector3(m, "command", "normal");
  auto direction = Vector3(m, "command", "drag_direction");
  auto length = Real(m, "command", "segment_length_mm");
  auto speed = Real(m, "command", "speed_mm_s");
  auto force = Real(m, "command", "normal_force_n");
  for (const absl::Status& s : {command_id.status(), job_id.status(), attempt.status(), lease.status(),
                                position.status(), normal.status(), direction.status(), length.status(),
                                speed.status(), force.status()}) {
    if (!s.ok()) return s;
  }
  auto site = m.find("site");
  if (site == m.end() || !site->is_object()) return Missing("command", "site", "an object {level, vertex}");
  auto level = Integer(*site, "command: site", "level");
  auto vertex = Integer(*site, "command: site", "vertex");
  if (!level.ok()) return level.status();
  if (!vertex.ok()) return vertex.status();
  r.command_id = *command_id;
  r.job_id = *job_id;
  r.attempt = static_cast<int>(*attempt);
  r.lease_deadline_unix_ms = *lease;
  r.position = *position;
  r.normal = *normal;
  r.drag_direction = *direction;
  r.segment_length_mm = *length;
  r.speed_mm_s = *speed;
  r.normal_force_n = *force;
  r.site_level = static_cast<int>(*level);
  r.site_vertex = static_cast<int>(*vertex);
  if (absl::Status valid = ValidateProbeRequest(r); !valid.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("command ", r.command_id, ": ", valid.message()));
  }
  return r;
}

absl::StatusOr<DriverReady> ParseReadyMessage(std::string_view line) {
  absl::StatusOr<json> parsed = ParseObject(line);
  if (!parsed.ok()) return parsed.status();
  absl::StatusOr<std::string> type = Text(*parsed, "ready", "type");
  if (!type.ok() || *type != "ready") {
    return absl::InvalidArgumentError(
        absl::StrCat("the first line must be {\"type\":\"ready\",\"protocol\":1,...}, got ", Quote(line)));
  }
  absl::StatusOr<std::int64_t> protocol = Integer(*parsed, "ready", "protocol");
  if (!protocol.ok()) return protocol.status();
  if (*protocol != kDriverProtocolVersion) {
    return absl::InvalidArgumentError(absl::StrCat("the driver speaks protocol ", *protocol,
                                                   ", this surfmap-rig speaks protocol ", kDriverProtocolVersion));
  }
  DriverReady ready;
  ready.protocol = static_cast<int>(*protocol);
  if (auto it = parsed->find("driver"); it != parsed->end() && it->is_string()) ready.driver = it->get<std::string>();
  return ready;
}

absl::StatusOr<DriverReply> ParseDriverReply(std::string_view line, std::int64_t expected_command_id) {
  absl::StatusOr<json> parsed = ParseObject(line);
  if (!parsed.ok()) return parsed.status();
  const json& m = *parsed;
  absl::StatusOr<std::string> type = Text(m, "reply", "type");
  if (!type.ok()) return type.status();
  DriverReply reply;
  if (*type == "log") {
    absl::StatusOr<std::string> message = Text(m, "log", "message");
    if (!message.ok()) return message.status();
    reply.type = DriverReply::Type::kLog;
    reply.message = *message;
    return reply;
  }
  if (*type != "trace" && *type != "failure") {
    return absl::InvalidArgumentError(absl::StrCat("unknown message type '", *type,
                                                   "' (expected trace, failure or log): ", Quote(line)));
  }
  absl::StatusOr<std::int64_t> command_id = Integer(m, *type, "command_id");
  if (!command_id.ok()) return command_id.status();
  if (*command_id != expected_command_id) {
    return absl::InvalidArgumentError(absl::StrCat(*type, " for command ", *command_id, " while command ",
                                                   expected_command_id, " is being measured"));
  }
  reply.command_id = *command_id;
  if (*type == "trace") {
    absl::StatusOr<DragTrace> trace = TraceFromMessage(m);
    if (!trace.ok()) return trace.status();
    reply.type = DriverReply::Type::kTrace;
    reply.trace = *std::move(trace);
    return reply;
  }
  reply.type = DriverReply::Type::kFailure;
  absl::StatusOr<std::string> kind = Text(m, "failure", "kind");
  if (!kind.ok()) return kind.status();
  if (*kind == "transient") {
    reply.kind = pb::FAILURE_KIND_TRANSIENT;
  } else if (*kind == "unreachable") {
    reply.kind = pb::FAILURE_KIND_UNREACHABLE;
  } else {
    return absl::InvalidArgumentError(
        absl::StrCat("failure: kind '", *kind, "' is not \"transient\" or \"unreachable\""));
  }
  absl::StatusOr<std::string> reason = Text(m, "failure", "reason");
  if (!reason.ok()) return reason.status();
  if (reason->empty()) return absl::InvalidArgumentError("failure: field 'reason' is empty (say what went wrong)");
  reply.reason = *reason;
  if (auto it = m.find("stop"); it != m.end()) {
    if (!it->is_boolean()) return Missing("failure", "stop", "true or false");
    reply.stop = it->get<bool>();
  }
  return reply;
}

}  // namespace surfmap::rig
