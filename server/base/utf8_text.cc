#include "server/base/utf8_text.h"

#include <cstdint>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace surfmap {
namespace {

// Length in bytes of the well-formed UTF-8 sequence at `i`, or 0 when the
// bytes there are not one (RFC 3629: shortest form, no surrogates, <= U+10FFFF).
size_t SequenceLength(std::string_view s, size_t i, uint32_t* code_point) {
  const auto byte = [&](size_t k) { return static_cast<uint8_t>(s[k]); };
  const uint8_t b0 = byte(i);
  if (b0 < 0x80) {
    *code_point = b0;
    return 1;
  }
  size_t n;
  uint32_t cp, min;
  if ((b0 & 0xE0) == 0xC0) n = 2, cp = b0 & 0x1F, min = 0x80;
  else if ((b0 & 0xF0) == 0xE0) n = 3, cp = b0 & 0x0F, min = 0x800;
  else if ((b0 & 0xF8) == 0xF0) n = 4, cp = b0 & 0x07, min = 0x10000;
  else return 0;
  if (i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (byte(i + k) & 0x3F);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  *code_point = cp;
  return n;
}

bool IsControl(uint32_t cp) { return cp < 0x20 || cp == 0x7F; }

}  // namespace

std::optional<size_t> Utf8Length(std::string_view text, size_t* bad_byte) {
  size_t count = 0;
  for (size_t i = 0; i < text.size();) {
    uint32_t cp = 0;
    const size_t n = SequenceLength(text, i, &cp);
    if (n == 0) {
      if (bad_byte) *bad_byte = i;
      return std::nullopt;
    }
    i += n;
    ++count;
  }
  return count;
}

absl::Status ValidateName(std::string_view field, std::string_view text, size_t min_chars, size_t max_chars) {
  size_t bad = 0;
  std::optional<size_t> length = Utf8Length(text, &bad);
  if (!length) {
    return absl::InvalidArgumentError(
        absl::StrFormat("%s is not valid UTF-8 (byte %d is 0x%02x)", std::string(field), bad, static_cast<uint8_t>(text[bad])));
  }
  if (*length < min_chars || *length > max_chars) {
    return absl::InvalidArgumentError(
        absl::StrCat(std::string(field), " must have ", min_chars, "..", max_chars, " characters, got ", *length));
  }
  size_t chars = 0;
  for (size_t i = 0; i < text.size(); ++chars) {
    uint32_t cp = 0;
    i += SequenceLength(text, i, &cp);
    if (IsControl(cp)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "%s contains the control character U+%04X at character %d; names are one line of printable text",
          std::string(field),
          cp, chars + 1));
    }
  }
  return absl::OkStatus();
}

std::string EscapeForLog(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size();) {
    uint32_t cp = 0;
    const size_t n = SequenceLength(text, i, &cp);
    if (n == 0) {
      absl::StrAppendFormat(&out, "\\x%02x", static_cast<uint8_t>(text[i]));
      ++i;
      continue;
    }
    if (cp == '\n') out += "\\n";
    else if (cp == '\r') out += "\\r";
    else if (cp == '\t') out += "\\t";
    else if (cp == '\\') out += "\\\\";
    else if (IsControl(cp)) absl::StrAppendFormat(&out, "\\x%02x", cp);
    else out.append(text.data() + i, n);
    i += n;
  }
  return out;
}

}  // namespace surfmap
