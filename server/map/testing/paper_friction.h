// Test support (header-only): the Coulomb friction coefficients of the
// paper's materials, shared by the map's unit tests so each file need not
// spell them (and so they are one definition when a unity build batches the
// test files).
#pragma once

namespace surfmap::testing {

inline constexpr double kGlassMu = 0.106;
inline constexpr double kRubberMu = 0.305;
inline constexpr double kMasoniteMu = 0.36;
inline constexpr double kSandpaperMu = 0.5;

}  // namespace surfmap::testing
