#include "clients/cli/provenance_options.h"

#include <algorithm>

#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"

namespace surfmap::cli {

void AddProvenanceOptions(CLI::App* command, ProvenanceArgs* a) {
  command->add_option("--operator", a->operator_name, "Provenance: who measured");
  command->add_option("--specimen", a->specimen, "Provenance: the specimen (sample id, batch)");
  command->add_option("--tip", a->tip, "Provenance: the probe tip (e.g. \"steel ball 3 mm\")");
  command->add_option("--sensor", a->sensor, "Provenance: the force sensor (model, serial)");
  command->add_option("--note", a->notes, "Provenance: a free note (repeatable; one line each)");
  command->add_option("--meta", a->meta, "Provenance: a lab-specific key=value (repeatable)");
}

bool ProvenanceFromArgs(const ProvenanceArgs& a, surfmap::v1::Provenance* out, std::string* error) {
  out->set_operator_name(a.operator_name);
  out->set_specimen(a.specimen);
  out->set_probe_tip(a.tip);
  out->set_sensor(a.sensor);
  out->set_notes(absl::StrJoin(a.notes, "\n"));
  for (const std::string& kv : a.meta) {
    const size_t eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) {
      *error = absl::StrFormat("--meta '%s': expected key=value", kv);
      return false;
    }
    (*out->mutable_extra())[kv.substr(0, eq)] = kv.substr(eq + 1);
  }
  return true;
}

std::string FormatProvenance(const surfmap::v1::Provenance& p, const std::string& indent) {
  std::string out;
  auto line = [&](const char* name, const std::string& value) {
    if (!value.empty()) absl::StrAppendFormat(&out, "%s%s: %s\n", indent, name, value);
  };
  line("operator", p.operator_name());
  line("specimen", p.specimen());
  line("probe tip", p.probe_tip());
  line("sensor", p.sensor());
  line("notes", p.notes());
  std::vector<std::string> keys;
  for (const auto& [key, value] : p.extra()) keys.push_back(key);
  std::sort(keys.begin(), keys.end());  // a map's order is not stable
  for (const std::string& key : keys) absl::StrAppendFormat(&out, "%s%s = %s\n", indent, key, p.extra().at(key));
  return out;
}

}  // namespace surfmap::cli
