// Protobuf messages as the JSON every `--json` output prints.
//
// Protobuf's canonical JSON writes 64-bit integers as strings (JavaScript
// numbers lose precision above 2^53). Our 64-bit fields are ids and counts,
// far below that, and people and scripts compare them with the numbers the
// table output prints, so here they are JSON numbers. Everything else is
// protobuf's JSON unchanged: snake_case field names, zero values printed,
// Timestamps and Durations as RFC 3339 strings, NaN as "NaN".
#pragma once

#include <string>

#include <google/protobuf/message.h>
#include <nlohmann/json.hpp>

namespace surfmap::cli {

// `message` as JSON with every int64/uint64 field (also in repeated fields,
// map values and nested messages) a number. An unprintable message (never
// for our protos) gives an empty object.
nlohmann::json ProtoToJson(const google::protobuf::Message& message);

}  // namespace surfmap::cli
