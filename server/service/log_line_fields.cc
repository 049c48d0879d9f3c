#include "server/service/log_line_fields.h"

#include <cctype>
#include <cmath>
#include <cstdint>
#include <optional>

#include "absl/strings/numbers.h"

namespace surfmap {
namespace {

using json = nlohmann::ordered_json;

bool IsKeyStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool IsKeyChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.'; }

// Length of the key at the start of `word` when the word is key=..., else 0.
std::size_t KeyLength(std::string_view word) {
  if (word.empty() || !IsKeyStart(word[0])) return 0;
  std::size_t i = 1;
  while (i < word.size() && IsKeyChar(word[i])) ++i;
  return i < word.size() && word[i] == '=' ? i : 0;
}

json TypedValue(std::string_view text) {
  // Debian's Abseil has its own string_view type.
  const absl::string_view view(text.data(), text.size());
  int64_t integer = 0;
  if (absl::SimpleAtoi(view, &integer)) return integer;
  double number = 0.0;
  // SimpleAtod accepts "nan" and "inf", which JSON cannot hold: those stay text.
  if (absl::SimpleAtod(view, &number) && std::isfinite(number)) return number;
  if (text == "true") return true;
  if (text == "false") return false;
  return std::string(text);
}

// Reads a quoted value starting at line[pos] == '"'; sets pos past the closing
// quote. Nothing when the quote is not closed.
std::optional<std::string> QuotedValue(std::string_view line, std::size_t& pos) {
  std::string value;
  for (std::size_t i = pos + 1; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '"') {
      pos = i + 1;
      return value;
    }
    if (c == '\\' && i + 1 < line.size()) {
      const char e = line[++i];
      value.push_back(e == 'n' ? '\n' : e == 'r' ? '\r' : e == 't' ? '\t' : e);
    } else {
      value.push_back(c);
    }
  }
  return std::nullopt;
}

}  // namespace

LogLineFields ParseLogLine(std::string_view line) {
  LogLineFields out;
  std::size_t pos = 0;
  while (pos < line.size()) {
    while (pos < line.size() && line[pos] == ' ') ++pos;
    if (pos >= line.size()) break;
    std::size_t end = line.find(' ', pos);
    if (end == std::string_view::npos) end = line.size();
    const std::size_t key_length = KeyLength(line.substr(pos, end - pos));
    if (key_length == 0) {
      if (!out.message.empty()) out.message.push_back(' ');
      out.message.append(line.substr(pos, end - pos));
      pos = end;
      continue;
    }
    std::string key(line.substr(pos, key_length));
    std::size_t value_pos = pos + key_length + 1;
    if (value_pos < line.size() && line[value_pos] == '"') {
      std::optional<std::string> value = QuotedValue(line, value_pos);
      if (!value) return LogLineFields{std::string(line), {}};
      out.fields.emplace_back(std::move(key), json(std::move(*value)));
      pos = value_pos;
    } else {
      out.fields.emplace_back(std::move(key), TypedValue(line.substr(value_pos, end - value_pos)));
      pos = end;
    }
  }
  return out;
}

}  // namespace surfmap
