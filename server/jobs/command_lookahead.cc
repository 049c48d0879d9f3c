#include "server/jobs/command_lookahead.h"

#include <algorithm>

namespace surfmap {

void CommandLookahead::RigAsked(const std::string& rig_id, int64_t now_unix_ms, int64_t lease_ms) {
  const int64_t until = now_unix_ms + std::max<int64_t>(lease_ms, 1);
  MutexLock lock(&mu_);
  auto it = counted_until_ms_.find(rig_id);
  if (it != counted_until_ms_.end()) {
    it->second = std::max(it->second, until);
    return;
  }
  if (counted_until_ms_.size() >= kMaxCountedRigs) ForgetQuietRigsLocked(now_unix_ms);
  if (counted_until_ms_.size() >= kMaxCountedRigs) return;  // still full of rigs that asked recently
  counted_until_ms_.emplace(rig_id, until);
}

int CommandLookahead::CommandsAhead(int64_t now_unix_ms) {
  MutexLock lock(&mu_);
  ForgetQuietRigsLocked(now_unix_ms);
  return std::max(1, static_cast<int>(counted_until_ms_.size()));
}

void CommandLookahead::ForgetQuietRigsLocked(int64_t now_unix_ms) {
  std::erase_if(counted_until_ms_, [&](const auto& rig) { return rig.second < now_unix_ms; });
}

}  // namespace surfmap
