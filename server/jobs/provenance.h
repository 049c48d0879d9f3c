// Provenance: what a lab keeps with its data (issue 14), attached at creation
// to an object, a job or a trace: who measured (operator), what (specimen),
// with which probe tip and force sensor, free notes, and lab-specific keys.
// Stored in the records' metadata_json as {"provenance": {...}} (a trace
// imported from a file also has {"import": {...}}, trace_import.h).
//
// Bounded, so metadata cannot be used to grow the database without limit:
// each named field at most kMaxFieldChars characters on one line, notes at
// most kMaxNotesChars (several lines allowed), at most kMaxExtraKeys extra
// keys of 1..kMaxKeyChars characters [A-Za-z0-9_.-], values at most
// kMaxFieldChars. Everything valid UTF-8; errors name the field.
#pragma once

#include <cstddef>
#include <map>
#include <string>

#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"

namespace surfmap {

struct Provenance {
  static constexpr size_t kMaxFieldChars = 200;
  static constexpr size_t kMaxNotesChars = 4000;
  static constexpr size_t kMaxExtraKeys = 32;
  static constexpr size_t kMaxKeyChars = 64;

  std::string operator_name;  // "operator" in JSON and the API
  std::string specimen;
  std::string probe_tip;
  std::string sensor;
  std::string notes;
  std::map<std::string, std::string> extra;

  bool empty() const {
    return operator_name.empty() && specimen.empty() && probe_tip.empty() && sensor.empty() && notes.empty() &&
           extra.empty();
  }
  bool operator==(const Provenance&) const = default;
};

// INVALID_ARGUMENT naming the first field out of bounds.
absl::Status ValidateProvenance(const Provenance& provenance);

// {"operator": ..., ...}: empty fields left out.
nlohmann::json ProvenanceToJson(const Provenance& provenance);
// The inverse; INVALID_ARGUMENT naming a field that is not a string.
absl::StatusOr<Provenance> ProvenanceFromJson(const nlohmann::json& json);

// A record's metadata_json with this provenance ("{}" when empty).
std::string MetadataJsonOf(const Provenance& provenance);
// The provenance in a record's metadata_json ({} when it has none);
// DATA_LOSS when the stored text cannot be read.
absl::StatusOr<Provenance> ProvenanceOfMetadata(const std::string& metadata_json);

}  // namespace surfmap
