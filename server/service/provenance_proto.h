// Provenance and import metadata (issues 13, 14): the API's messages <->
// the domain's Provenance and the records' metadata_json.
#pragma once

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "proto/surfmap/v1/surfmap.pb.h"
#include "server/jobs/provenance.h"

namespace surfmap {

namespace pb = ::surfmap::v1;

// Validated (ValidateProvenance): INVALID_ARGUMENT naming the field.
absl::StatusOr<Provenance> ProvenanceFromProto(const pb::Provenance& proto);
pb::Provenance ProvenanceToProto(const Provenance& provenance);

// A record's metadata_json into the answer: its provenance (when `provenance`
// is given) and, for an imported trace, where it came from (when `import` is
// given; imported_unix_ms is the trace's stored time). Metadata that cannot
// be read (never written so by this server) is left out with a warning in the
// log, so one damaged row does not hide every other.
void FillMetadata(const std::string& metadata_json, int64_t imported_unix_ms, pb::Provenance* provenance,
                  pb::ImportInfo* import);

// Unix ms of a client's timestamp (0 when unset); INVALID_ARGUMENT naming
// `field` when out of range.
absl::StatusOr<int64_t> UnixMsFromProto(const google::protobuf::Timestamp& ts, bool has, const char* field);

}  // namespace surfmap
