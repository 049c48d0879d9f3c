// spdlog formatter writing one JSON object per line, for log collectors:
// {"time_ms", "level", "msg", then every key=value field of the line as its
// own key} (log_line_fields.h). A field named like one of the three fixed keys
// is written as "<name>_field", so it never replaces them.
#pragma once

#include <memory>

#include <spdlog/formatter.h>

namespace surfmap {

class JsonLogFormatter final : public spdlog::formatter {
 public:
  void format(const spdlog::details::log_msg& msg, spdlog::memory_buf_t& dest) override;
  std::unique_ptr<spdlog::formatter> clone() const override { return std::make_unique<JsonLogFormatter>(); }
};

}  // namespace surfmap
