#include "clients/render/digit_font.h"

#include <array>
#include <cstdint>

namespace surfmap {
namespace {

// Each glyph: 7 rows, the low 5 bits of each row, bit 4 = leftmost column.
using Glyph = std::array<std::uint8_t, kGlyphHeight>;

const Glyph* GlyphFor(char c) {
  static constexpr Glyph kDigits[10] = {
      {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E},  // 0
      {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E},  // 1
      {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F},  // 2
      {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E},  // 3
      {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02},  // 4
      {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E},  // 5
      {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E},  // 6
      {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},  // 7
      {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E},  // 8
      {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C},  // 9
  };
  static constexpr Glyph kDot = {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C};
  static constexpr Glyph kMinus = {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00};
  static constexpr Glyph kPlus = {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00};
  static constexpr Glyph kE = {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E};
  if (c >= '0' && c <= '9') return &kDigits[c - '0'];
  switch (c) {
    case '.': return &kDot;
    case '-': return &kMinus;
    case '+': return &kPlus;
    case 'e': return &kE;
    default: return nullptr;
  }
}

}  // namespace

int TextWidth(std::string_view text, int scale) {
  if (text.empty()) return 0;
  return (static_cast<int>(text.size()) * kGlyphAdvance - 1) * scale;
}

void DrawText(RgbImage& image, int x, int y, std::string_view text, Rgb color, int scale) {
  if (scale < 1) scale = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    const Glyph* glyph = GlyphFor(text[i]);
    if (glyph == nullptr) continue;
    const int gx = x + static_cast<int>(i) * kGlyphAdvance * scale;
    for (int row = 0; row < kGlyphHeight; ++row) {
      for (int col = 0; col < kGlyphWidth; ++col) {
        if (((*glyph)[row] >> (kGlyphWidth - 1 - col) & 1) == 0) continue;
        for (int dy = 0; dy < scale; ++dy) {
          for (int dx = 0; dx < scale; ++dx) image.SetClipped(gx + col * scale + dx, y + row * scale + dy, color);
        }
      }
    }
  }
}

}  // namespace surfmap
