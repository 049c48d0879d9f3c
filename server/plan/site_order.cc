#include "server/plan/site_order.h"

#include "server/base/splitmix64.h"

namespace surfmap {

std::uint64_t SiteShuffleKey(std::uint64_t seed, int vertex) {
  return SplitMix64(seed ^ SplitMix64(static_cast<std::uint64_t>(vertex)));
}

}  // namespace surfmap
