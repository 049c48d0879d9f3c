#include "storage/stored_sample.h"

#include <bit>
#include <cstring>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

// Byte order is fixed (little-endian) so a database file moves between hosts.
void PutDouble(double value, char* out) {
  uint64_t bits = std::bit_cast<uint64_t>(value);
  for (int i = 0; i < 8; ++i) out[i] = static_cast<char>((bits >> (8 * i)) & 0xff);
}

double GetDouble(const char* in) {
  uint64_t bits = 0;
  for (int i = 0; i < 8; ++i) bits |= uint64_t{static_cast<unsigned char>(in[i])} << (8 * i);
  return std::bit_cast<double>(bits);
}

}  // namespace

std::string EncodeSamples(const std::vector<StoredSample>& samples) {
  std::string blob(samples.size() * kEncodedSampleBytes, '\0');
  char* p = blob.data();
  for (const StoredSample& s : samples) {
    for (double v : {s.t, s.x, s.y, s.z, s.fx, s.fy, s.fz}) {
      PutDouble(v, p);
      p += 8;
    }
    *p++ = static_cast<char>(s.phase);
  }
  return blob;
}

absl::StatusOr<std::vector<StoredSample>> DecodeSamples(std::string_view blob) {
  if (blob.size() % kEncodedSampleBytes != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("sample blob of ", blob.size(), " bytes is not a multiple of ",
                     kEncodedSampleBytes, " bytes per sample"));
  }
  std::vector<StoredSample> samples(blob.size() / kEncodedSampleBytes);
  const char* p = blob.data();
  for (StoredSample& s : samples) {
    for (double* v : {&s.t, &s.x, &s.y, &s.z, &s.fx, &s.fy, &s.fz}) {
      *v = GetDouble(p);
      p += 8;
    }
    s.phase = static_cast<uint8_t>(*p++);
  }
  return samples;
}

bool BitwiseEqual(const StoredSample& a, const StoredSample& b) {
  auto same = [](double u, double v) {
    return std::bit_cast<uint64_t>(u) == std::bit_cast<uint64_t>(v);
  };
  return same(a.t, b.t) && same(a.x, b.x) && same(a.y, b.y) && same(a.z, b.z) &&
         same(a.fx, b.fx) && same(a.fy, b.fy) && same(a.fz, b.fz) && a.phase == b.phase;
}

}  // namespace surfmap
