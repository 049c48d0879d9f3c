// The fields of a logfmt log line (server/base/log_text.h), for the JSON log
// format: "job completed job_id=3 reason=\"lease expired\"" becomes the
// message "job completed" and the fields job_id: 3, reason: "lease expired".
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace surfmap {

struct LogLineFields {
  std::string message;  // the words that are not fields, joined by one space
  std::vector<std::pair<std::string, nlohmann::ordered_json>> fields;  // in line order
};

// A word key=value is a field when key is [A-Za-z_][A-Za-z0-9_.]*. A quoted
// value ("...", LogQuote's escapes) is a string; an unquoted one is a number
// when it reads whole as an integer or a finite decimal, true/false a bool,
// else a string. A line that does not parse (an unterminated quote) is all
// message, no fields: a log line is never lost to its format.
LogLineFields ParseLogLine(std::string_view line);

}  // namespace surfmap
