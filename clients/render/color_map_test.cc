#include "clients/render/color_map.h"

#include <cmath>

#include <gtest/gtest.h>
#include "clients/render/digit_font.h"

namespace surfmap {
namespace {

TEST(ColorMapTest, GreyIsDarkGreyToWhite) {
  EXPECT_EQ(MapColor(ColorMap::kGrey, 0.0), (Rgb{40, 40, 40}));
  EXPECT_EQ(MapColor(ColorMap::kGrey, 1.0), (Rgb{255, 255, 255}));
  EXPECT_EQ(MapColor(ColorMap::kGrey, 2.0), (Rgb{255, 255, 255}));  // clamped
  EXPECT_EQ(MapColor(ColorMap::kGrey, std::nan("")), (Rgb{40, 40, 40}));
  EXPECT_NEAR(MapColor(ColorMap::kGrey, 0.5)[0], 147.5, 0.6);
}

TEST(ColorMapTest, ViridisEndsMatchMatplotlib) {
  EXPECT_EQ(MapColor(ColorMap::kViridis, 0.0), (Rgb{68, 1, 84}));
  EXPECT_EQ(MapColor(ColorMap::kViridis, 1.0), (Rgb{253, 231, 37}));
  EXPECT_EQ(MapColor(ColorMap::kViridis, 0.5), (Rgb{33, 145, 140}));
}

TEST(ColorMapTest, ViridisLightnessIncreases) {
  int previous = -1;
  for (int i = 0; i <= 20; ++i) {
    const Rgb c = MapColor(ColorMap::kViridis, i / 20.0);
    const int luma = 299 * c[0] + 587 * c[1] + 114 * c[2];
    EXPECT_GT(luma, previous) << "t " << i / 20.0;
    previous = luma;
  }
}

TEST(ColorMapTest, ParseNames) {
  EXPECT_EQ(*ParseColorMap("gray"), ColorMap::kGrey);
  EXPECT_EQ(*ParseColorMap("viridis"), ColorMap::kViridis);
  auto bad = ParseColorMap("jet");
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("'jet'"), std::string::npos);
}

TEST(ColorMapTest, NormalizeToRange) {
  EXPECT_DOUBLE_EQ(NormalizeToRange(0.3, 0.1, 0.5), 0.5);
  EXPECT_DOUBLE_EQ(NormalizeToRange(-1, 0.1, 0.5), 0.0);
  EXPECT_DOUBLE_EQ(NormalizeToRange(0.2, 0.2, 0.2), 0.5);
}

TEST(DigitFontTest, DrawsDigitsAndSkipsUnknownCharacters) {
  RgbImage image(40, 10, {0, 0, 0});
  DrawText(image, 0, 0, "1?", {255, 255, 255}, 1);
  int lit_digit = 0, lit_unknown = 0;
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 40; ++x) {
      if (image.At(x, y)[0] == 255) (x < kGlyphAdvance ? lit_digit : lit_unknown)++;
    }
  }
  EXPECT_EQ(lit_digit, 10);  // the glyph of '1' has 10 pixels
  EXPECT_EQ(lit_unknown, 0);
  EXPECT_EQ(TextWidth("0.13", 2), (4 * kGlyphAdvance - 1) * 2);
}

}  // namespace
}  // namespace surfmap
