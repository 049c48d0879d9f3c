#include "server/jobs/provenance.h"

#include "absl/strings/str_cat.h"
#include "server/base/utf8_text.h"

namespace surfmap {
namespace {

using nlohmann::json;

absl::Status ValidateNotes(const std::string& notes) {
  size_t bad = 0;
  const std::optional<size_t> chars = Utf8Length(notes, &bad);
  if (!chars) return absl::InvalidArgumentError(absl::StrCat("provenance notes: not valid UTF-8 at byte ", bad));
  if (*chars > Provenance::kMaxNotesChars) {
    return absl::InvalidArgumentError(absl::StrCat("provenance notes: ", *chars, " characters; the limit is ",
                                                   Provenance::kMaxNotesChars));
  }
  return absl::OkStatus();
}

bool IsKeyChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.' ||
         c == '-';
}

}  // namespace

absl::Status ValidateProvenance(const Provenance& p) {
  const struct {
    const char* name;
    const std::string& value;
  } fields[] = {{"provenance operator", p.operator_name},
                {"provenance specimen", p.specimen},
                {"provenance probe_tip", p.probe_tip},
                {"provenance sensor", p.sensor}};
  for (const auto& f : fields) {
    if (absl::Status s = ValidateName(f.name, f.value, 0, Provenance::kMaxFieldChars); !s.ok()) return s;
  }
  if (absl::Status s = ValidateNotes(p.notes); !s.ok()) return s;
  if (p.extra.size() > Provenance::kMaxExtraKeys) {
    return absl::InvalidArgumentError(absl::StrCat("provenance extra: ", p.extra.size(), " keys; the limit is ",
                                                   Provenance::kMaxExtraKeys));
  }
  for (const auto& [key, value] : p.extra) {
    if (key.empty() || key.size() > Provenance::kMaxKeyChars) {
      return absl::InvalidArgumentError(absl::StrCat("provenance extra key '", EscapeForLog(key.substr(0, 80)),
                                                     "': must have 1..", Provenance::kMaxKeyChars, " characters"));
    }
    for (char c : key) {
      if (!IsKeyChar(c)) {
        return absl::InvalidArgumentError(absl::StrCat("provenance extra key '", EscapeForLog(key),
                                                       "': only letters, digits, '_', '.' and '-' are allowed"));
      }
    }
    if (absl::Status s = ValidateName(absl::StrCat("provenance extra '", key, "'"), value, 0,
                                      Provenance::kMaxFieldChars);
        !s.ok()) {
      return s;
    }
  }
  return absl::OkStatus();
}

json ProvenanceToJson(const Provenance& p) {
  json j = json::object();
  if (!p.operator_name.empty()) j["operator"] = p.operator_name;
  if (!p.specimen.empty()) j["specimen"] = p.specimen;
  if (!p.probe_tip.empty()) j["probe_tip"] = p.probe_tip;
  if (!p.sensor.empty()) j["sensor"] = p.sensor;
  if (!p.notes.empty()) j["notes"] = p.notes;
  if (!p.extra.empty()) j["extra"] = p.extra;
  return j;
}

absl::StatusOr<Provenance> ProvenanceFromJson(const json& j) {
  if (!j.is_object()) return absl::InvalidArgumentError("provenance: not a JSON object");
  Provenance p;
  const struct {
    const char* key;
    std::string* out;
  } fields[] = {{"operator", &p.operator_name}, {"specimen", &p.specimen}, {"probe_tip", &p.probe_tip},
                {"sensor", &p.sensor},          {"notes", &p.notes}};
  for (const auto& f : fields) {
    auto it = j.find(f.key);
    if (it == j.end()) continue;
    if (!it->is_string()) return absl::InvalidArgumentError(absl::StrCat("provenance ", f.key, ": not a string"));
    *f.out = it->get<std::string>();
  }
  if (auto extra = j.find("extra"); extra != j.end()) {
    if (!extra->is_object()) return absl::InvalidArgumentError("provenance extra: not a JSON object");
    for (const auto& [key, value] : extra->items()) {
      if (!value.is_string()) {
        return absl::InvalidArgumentError(absl::StrCat("provenance extra '", key, "': not a string"));
      }
      p.extra[key] = value.get<std::string>();
    }
  }
  return p;
}

std::string MetadataJsonOf(const Provenance& provenance) {
  if (provenance.empty()) return "{}";
  return json{{"provenance", ProvenanceToJson(provenance)}}.dump();
}

absl::StatusOr<Provenance> ProvenanceOfMetadata(const std::string& metadata_json) {
  const json j = json::parse(metadata_json, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) return absl::DataLossError("stored metadata is not a JSON object");
  auto it = j.find("provenance");
  if (it == j.end()) return Provenance{};
  absl::StatusOr<Provenance> p = ProvenanceFromJson(*it);
  if (!p.ok()) return absl::DataLossError(absl::StrCat("stored metadata: ", p.status().message()));
  return p;
}

}  // namespace surfmap
