#include "server/service/json_log_formatter.h"

#include <chrono>
#include <string>

#include <fmt/chrono.h>
#include <nlohmann/json.hpp>

namespace surfmap {

void JsonLogFormatter::format(const spdlog::details::log_msg& msg, spdlog::memory_buf_t& dest) {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(msg.time.time_since_epoch()).count();
  nlohmann::json line{{"time_ms", ms},
                      {"level", std::string(spdlog::level::to_string_view(msg.level).data(),
                                            spdlog::level::to_string_view(msg.level).size())},
                      {"msg", std::string(msg.payload.data(), msg.payload.size())}};
  std::string text = line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  text.push_back('\n');
  dest.append(text.data(), text.data() + text.size());
}

}  // namespace surfmap
