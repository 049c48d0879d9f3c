#include "storage/stored_sample.h"

#include <bit>
#include <cmath>
#include <limits>
#include <random>

#include "gtest/gtest.h"

namespace surfmap {
namespace {

TEST(StoredSampleTest, EncodingIsLittleEndianPacked57Bytes) {
  StoredSample s;
  s.t = 1.0;  // 0x3FF0000000000000
  s.phase = 2;
  std::string blob = EncodeSamples({s});
  ASSERT_EQ(blob.size(), 57u);
  EXPECT_EQ(static_cast<unsigned char>(blob[6]), 0xF0);
  EXPECT_EQ(static_cast<unsigned char>(blob[7]), 0x3F);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(blob[i], 0) << i;
  EXPECT_EQ(blob[56], 2);
}

TEST(StoredSampleTest, SpecialValuesRoundTripBitExactly) {
  const double values[] = {
      -0.0,
      0.0,
      std::numeric_limits<double>::denorm_min(),
      -std::numeric_limits<double>::denorm_min(),
      std::bit_cast<double>(uint64_t{0x000FFFFFFFFFFFFF}),  // largest subnormal
      std::numeric_limits<double>::min(),
      std::numeric_limits<double>::max(),
      std::numeric_limits<double>::infinity(),
      -std::numeric_limits<double>::infinity(),
      std::bit_cast<double>(uint64_t{0x7FF8000000000123}),  // quiet NaN with payload
      std::bit_cast<double>(uint64_t{0xFFF0000000000001}),  // signalling NaN, sign set
      0.1,
  };
  std::vector<StoredSample> in;
  for (double v : values) {
    StoredSample s{v, -v, v, -v, v, -v, v, 255};
    in.push_back(s);
  }
  absl::StatusOr<std::vector<StoredSample>> out = DecodeSamples(EncodeSamples(in));
  ASSERT_TRUE(out.ok()) << out.status();
  ASSERT_EQ(out->size(), in.size());
  for (size_t i = 0; i < in.size(); ++i) {
    EXPECT_TRUE(BitwiseEqual(in[i], (*out)[i])) << "sample " << i;
    EXPECT_EQ(std::bit_cast<uint64_t>((*out)[i].t), std::bit_cast<uint64_t>(values[i]));
  }
  // -0.0 must stay negative zero.
  EXPECT_TRUE(std::signbit((*out)[0].t));
}

TEST(StoredSampleTest, RandomBitPatternsRoundTrip) {
  std::mt19937_64 rng(20010521);
  std::vector<StoredSample> in(1000);
  for (StoredSample& s : in) {
    for (double* v : {&s.t, &s.x, &s.y, &s.z, &s.fx, &s.fy, &s.fz}) {
      *v = std::bit_cast<double>(rng());
    }
    s.phase = static_cast<uint8_t>(rng() % 3);
  }
  std::string blob = EncodeSamples(in);
  EXPECT_EQ(blob.size(), in.size() * kEncodedSampleBytes);
  absl::StatusOr<std::vector<StoredSample>> out = DecodeSamples(blob);
  ASSERT_TRUE(out.ok());
  for (size_t i = 0; i < in.size(); ++i) ASSERT_TRUE(BitwiseEqual(in[i], (*out)[i])) << i;
}

TEST(StoredSampleTest, BitwiseEqualDistinguishesSignedZero) {
  StoredSample a, b;
  b.fz = -0.0;
  EXPECT_FALSE(BitwiseEqual(a, b));
}

TEST(StoredSampleTest, TruncatedBlobIsRejectedWithItsLength) {
  std::string blob = EncodeSamples(std::vector<StoredSample>(2));
  blob.pop_back();
  absl::StatusOr<std::vector<StoredSample>> out = DecodeSamples(blob);
  ASSERT_FALSE(out.ok());
  EXPECT_EQ(out.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(out.status().message().find("113 bytes"), std::string::npos) << out.status();
}

TEST(StoredSampleTest, EmptyRoundTrips) {
  EXPECT_TRUE(EncodeSamples({}).empty());
  absl::StatusOr<std::vector<StoredSample>> out = DecodeSamples("");
  ASSERT_TRUE(out.ok());
  EXPECT_TRUE(out->empty());
}

}  // namespace
}  // namespace surfmap
