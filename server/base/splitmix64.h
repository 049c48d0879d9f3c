// SplitMix64 (Steele, Lea & Flood 2014): the one seeded 64-bit mix every
// module uses (plan issue order, the simulated rig's per-command seeds, the
// haptic texture's noise table), so the same seed means the same thing
// everywhere. Header only, standard library only.
#pragma once

#include <cstdint>

namespace surfmap {

// The finaliser alone: a bijective mix in which every input bit affects every
// output bit (distinct inputs give distinct, well-spread outputs).
constexpr std::uint64_t SplitMix64Finalize(std::uint64_t x) {
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// One SplitMix64 step: the golden-ratio increment, then the finaliser.
constexpr std::uint64_t SplitMix64(std::uint64_t x) { return SplitMix64Finalize(x + 0x9e3779b97f4a7c15ULL); }

}  // namespace surfmap
