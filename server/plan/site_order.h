// The order in which pending sites are issued.
#pragma once

#include <cstdint>

namespace surfmap {

// A pseudo-random 64-bit key for a vertex, a pure function of (seed, vertex)
// (SplitMix64 mixing). Sites of one level are issued in increasing key order:
// a seeded shuffle that does not depend on the order in which sites became
// pending, so a restored plan issues exactly what the uninterrupted one would.
std::uint64_t SiteShuffleKey(std::uint64_t seed, int vertex);

}  // namespace surfmap
