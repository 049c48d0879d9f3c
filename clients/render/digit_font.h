// A tiny built-in 5x7 bitmap font for the colour bar's number labels and
// title. Covers the digits, '.', '-', '+', 'e', ' ', the capitals A-Z and
// '(', ')', '_', '/'; any other character is drawn as a blank cell, so
// labels never fail to render (titles are written in capitals).
#pragma once

#include <string_view>

#include "clients/render/rgb_image.h"

namespace surfmap {

inline constexpr int kGlyphWidth = 5;
inline constexpr int kGlyphHeight = 7;
inline constexpr int kGlyphAdvance = 6;  // glyph width + one column of spacing

// Width in pixels of `text` drawn at integer `scale` (>= 1).
int TextWidth(std::string_view text, int scale);

// Draws `text` with its top-left corner at (x, y), each font pixel a
// scale x scale block, clipped to the image.
void DrawText(RgbImage& image, int x, int y, std::string_view text, Rgb color, int scale);

}  // namespace surfmap
