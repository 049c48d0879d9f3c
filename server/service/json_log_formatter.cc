#include "server/service/json_log_formatter.h"

#include <chrono>
#include <string>

#include <nlohmann/json.hpp>
#include "server/service/log_line_fields.h"

namespace surfmap {

void JsonLogFormatter::format(const spdlog::details::log_msg& msg, spdlog::memory_buf_t& dest) {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(msg.time.time_since_epoch()).count();
  const spdlog::string_view_t level = spdlog::level::to_string_view(msg.level);
  LogLineFields parsed = ParseLogLine(std::string_view(msg.payload.data(), msg.payload.size()));
  // ordered_json keeps time, level and msg first, then the fields in line order.
  nlohmann::ordered_json line{{"time_ms", ms},
                              {"level", std::string(level.data(), level.size())},
                              {"msg", std::move(parsed.message)}};
  for (auto& [key, value] : parsed.fields) {
    const bool reserved = key == "time_ms" || key == "level" || key == "msg";
    line[reserved ? key + "_field" : key] = std::move(value);
  }
  std::string text = line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  text.push_back('\n');
  dest.append(text.data(), text.data() + text.size());
}

}  // namespace surfmap
