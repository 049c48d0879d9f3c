#include "server/service/provenance_proto.h"

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>
#include "absl/strings/str_cat.h"
#include "server/service/proto_conversion.h"

namespace surfmap {

absl::StatusOr<Provenance> ProvenanceFromProto(const pb::Provenance& proto) {
  // Counted before anything is copied: a map of a million keys is refused
  // without building a second one.
  if (static_cast<size_t>(proto.extra_size()) > Provenance::kMaxExtraKeys) {
    return absl::InvalidArgumentError(absl::StrCat("provenance extra: ", proto.extra_size(), " keys; the limit is ",
                                                   Provenance::kMaxExtraKeys));
  }
  Provenance p;
  p.operator_name = proto.operator_name();
  p.specimen = proto.specimen();
  p.probe_tip = proto.probe_tip();
  p.sensor = proto.sensor();
  p.notes = proto.notes();
  for (const auto& [key, value] : proto.extra()) p.extra[key] = value;
  if (absl::Status s = ValidateProvenance(p); !s.ok()) return s;
  return p;
}

pb::Provenance ProvenanceToProto(const Provenance& p) {
  pb::Provenance out;
  out.set_operator_name(p.operator_name);
  out.set_specimen(p.specimen);
  out.set_probe_tip(p.probe_tip);
  out.set_sensor(p.sensor);
  out.set_notes(p.notes);
  for (const auto& [key, value] : p.extra) (*out.mutable_extra())[key] = value;
  return out;
}

void FillMetadata(const std::string& metadata_json, int64_t imported_unix_ms, pb::Provenance* provenance,
                  pb::ImportInfo* import) {
  if (metadata_json.empty() || metadata_json == "{}") return;
  const nlohmann::json j = nlohmann::json::parse(metadata_json, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) {
    spdlog::warn("stored metadata is not a JSON object; left out of the answer");
    return;
  }
  if (provenance != nullptr) {
    if (auto it = j.find("provenance"); it != j.end()) {
      absl::StatusOr<Provenance> p = ProvenanceFromJson(*it);
      if (p.ok()) {
        *provenance = ProvenanceToProto(*p);
      } else {
        spdlog::warn("stored provenance cannot be read: {}", std::string(p.status().message()));
      }
    }
  }
  if (import != nullptr) {
    auto it = j.find("import");
    if (it == j.end() || !it->is_object()) return;
    const nlohmann::json& i = *it;
    // Field by field, type-checked (json::value throws on a wrong type).
    auto text = [&](const char* key) -> std::string {
      auto f = i.find(key);
      if (f == i.end()) return "";
      if (!f->is_string()) {
        spdlog::warn("stored import metadata: {} is not a string; left out of the answer", key);
        return "";
      }
      return f->get<std::string>();
    };
    import->set_source(text("source"));
    import->set_file_name(text("file_name"));
    import->set_file_sha256(text("file_sha256"));
    if (auto r = i.find("recorded_unix_ms"); r != i.end()) {
      // The range a Timestamp takes (0001..9999); 0 = not given.
      if (r->is_number_integer() && r->get<int64_t>() > 0 && r->get<int64_t>() <= 253402300799999LL) {
        *import->mutable_recorded() = TimestampFromUnixMs(r->get<int64_t>());
      } else if (!r->is_number_integer() || r->get<int64_t>() != 0) {
        spdlog::warn("stored import metadata: recorded_unix_ms is not a time; left out of the answer");
      }
    }
    *import->mutable_imported() = TimestampFromUnixMs(imported_unix_ms);
  }
}

absl::StatusOr<int64_t> UnixMsFromProto(const google::protobuf::Timestamp& ts, bool has, const char* field) {
  if (!has) return 0;
  // 0001-01-01 .. 9999-12-31, as google.protobuf.Timestamp allows; before 1970 is refused as a recording time.
  if (ts.seconds() < 0 || ts.seconds() > 253402300799LL || ts.nanos() < 0 || ts.nanos() > 999999999) {
    return absl::InvalidArgumentError(absl::StrCat(field, ": not a time between 1970 and 9999"));
  }
  return ts.seconds() * 1000 + ts.nanos() / 1'000'000;
}

}  // namespace surfmap
