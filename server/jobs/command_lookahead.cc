#include "server/jobs/command_lookahead.h"

#include <algorithm>
#include <unordered_map>

namespace surfmap {

CommandLookahead::CommandLookahead(int64_t window_ms) : window_ms_(std::max<int64_t>(window_ms, 1)) {}

void CommandLookahead::RigAsked(const std::string& rig_id, int64_t now_unix_ms) {
  MutexLock lock(&mu_);
  int64_t& last = last_asked_ms_[rig_id];
  last = std::max(last, now_unix_ms);
}

int CommandLookahead::CommandsAhead(int64_t now_unix_ms) {
  MutexLock lock(&mu_);
  // Rigs gone quiet are forgotten, so the map holds only the recent ones.
  std::erase_if(last_asked_ms_, [&](const auto& rig) { return rig.second < now_unix_ms - window_ms_; });
  return std::max(1, static_cast<int>(last_asked_ms_.size()));
}

}  // namespace surfmap
