// The provenance flags of `object upload`, `job create` and `job import`
// (--operator, --specimen, --tip, --sensor, --note, --meta key=value) and the
// human-readable lines `show` commands print for a Provenance.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include "proto/surfmap/v1/surfmap.pb.h"

namespace surfmap::cli {

struct ProvenanceArgs {
  std::string operator_name;
  std::string specimen;
  std::string tip;
  std::string sensor;
  std::vector<std::string> notes;  // one per --note, joined with newlines
  std::vector<std::string> meta;   // key=value
};

void AddProvenanceOptions(CLI::App* command, ProvenanceArgs* args);

// False with `error` set for a --meta without '=' or with an empty key (the
// server checks the bounds and names what is wrong).
bool ProvenanceFromArgs(const ProvenanceArgs& args, surfmap::v1::Provenance* out, std::string* error);

// "operator ..., specimen ..." lines, each starting with `indent`; empty for
// an empty provenance.
std::string FormatProvenance(const surfmap::v1::Provenance& provenance, const std::string& indent);

}  // namespace surfmap::cli
