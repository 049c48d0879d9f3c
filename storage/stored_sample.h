// Lossless binary encoding of a drag trace's samples for the traces.samples BLOB.
//
// Storage keeps its own plain sample struct so that it depends on nothing in
// server/ (the service converts DragSample <-> StoredSample).
//
// Encoding kSampleEncodingPackedLE (the only one so far), per sample, 57 bytes:
//   t, x, y, z, fx, fy, fz  as IEEE-754 binary64, little-endian (7 x 8 bytes)
//   phase                   one byte (the caller's phase code, stored as is)
// Samples are concatenated in order; no header (the count and the encoding are
// columns of the traces table). Every bit pattern round-trips, including -0.0,
// subnormals, infinities and NaN payloads.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"

namespace surfmap {

struct StoredSample {
  double t = 0.0;                    // s
  double x = 0.0, y = 0.0, z = 0.0;  // mm
  double fx = 0.0, fy = 0.0, fz = 0.0;  // N, by the surface on the probe
  uint8_t phase = 0;                 // caller's code (service: 0 fwd, 1 pause, 2 rev)
};

// Value of traces.sample_encoding for the format above.
inline constexpr int kSampleEncodingPackedLE = 1;
inline constexpr size_t kEncodedSampleBytes = 7 * sizeof(double) + 1;

// Never fails.
std::string EncodeSamples(const std::vector<StoredSample>& samples);

// InvalidArgumentError if the blob length is not a multiple of
// kEncodedSampleBytes (the message gives the length).
absl::StatusOr<std::vector<StoredSample>> DecodeSamples(std::string_view blob);

// Bitwise equality (so -0.0 != 0.0 and NaN == the same NaN); for tests and checks.
bool BitwiseEqual(const StoredSample& a, const StoredSample& b);

}  // namespace surfmap
