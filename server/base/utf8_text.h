// Text a client sends (object names, rig ids, failure reasons): checked as
// UTF-8 and measured in characters (code points), not bytes, so a limit means
// the same for "Flasche" and "瓶"; and escaped before it reaches a text log,
// so a newline in a name cannot forge a log line.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "absl/status/status.h"

namespace surfmap {

// The number of code points, or nullopt when `text` is not valid UTF-8
// (overlong forms, surrogates and code points above U+10FFFF are invalid).
// `bad_byte`, when given, receives the offset of the first invalid byte.
std::optional<size_t> Utf8Length(std::string_view text, size_t* bad_byte = nullptr);

// INVALID_ARGUMENT naming `field` unless `text` is valid UTF-8 with
// min_chars..max_chars characters and no control character (U+0000..U+001F,
// U+007F; tab and newline too: these are one-line names).
absl::Status ValidateName(std::string_view field, std::string_view text, size_t min_chars, size_t max_chars);

// `text` with control characters, backslashes and bytes that are not UTF-8
// written as escapes (\n, \r, \t, \\, \xNN): always one line, always UTF-8.
std::string EscapeForLog(std::string_view text);

}  // namespace surfmap
