// Whether a name a rig sends (its id, a spool header's fields) holds a
// control character (below 0x20, or DEL): such a name would break a log line
// or a spool file's line, so it is refused where it enters.
#pragma once

#include <string_view>

namespace surfmap::rig {

inline bool HasControlCharacter(std::string_view s) {
  for (unsigned char c : s) {
    if (c < 0x20 || c == 0x7f) return true;
  }
  return false;
}

}  // namespace surfmap::rig
