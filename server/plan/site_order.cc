#include "server/plan/site_order.h"

namespace surfmap {
namespace {

std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace

std::uint64_t SiteShuffleKey(std::uint64_t seed, int vertex) {
  return SplitMix64(seed ^ SplitMix64(static_cast<std::uint64_t>(vertex)));
}

}  // namespace surfmap
