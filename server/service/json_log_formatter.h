// spdlog formatter writing one JSON object per line ({"time","level","msg"}),
// with the message escaped properly, for log collectors.
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
