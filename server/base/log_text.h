// Log lines are logfmt: a few plain words saying what happened, then
// key=value fields, e.g.
//
//   job completed job_id=3 measured=100 failed=2 skipped=0
//   trace rejected rig=lab-arm-1 command_id=17 job_id=3 reason="too few pairs"
//
// Text logs stay readable; with `log_format json` the service's formatter
// (server/service/log_line_fields.h) turns each field into its own JSON key.
// A value that may hold spaces, quotes or '=' (names, reasons, errors) must
// go through LogQuote so the line parses back. Never log a token.
#pragma once

#include <string>
#include <string_view>

namespace surfmap {

// `value` in double quotes with '"' and '\' escaped and control characters
// written as \n, \r, \t (others as a space), so a field never breaks the line.
inline std::string LogQuote(std::string_view value) {
  std::string out;
  out.reserve(value.size() + 2);
  out.push_back('"');
  for (char c : value) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default: out.push_back(static_cast<unsigned char>(c) < 0x20 ? ' ' : c);
    }
  }
  out.push_back('"');
  return out;
}

}  // namespace surfmap
