// An 8-bit RGB raster, row-major from the top-left corner.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace surfmap {

using Rgb = std::array<std::uint8_t, 3>;

struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // width * height * 3, row-major, top row first

  RgbImage() = default;
  RgbImage(int w, int h, Rgb fill) : width(w), height(h), pixels(static_cast<std::size_t>(w) * h * 3) {
    for (std::size_t i = 0; i < pixels.size(); i += 3) {
      pixels[i] = fill[0];
      pixels[i + 1] = fill[1];
      pixels[i + 2] = fill[2];
    }
  }
  bool Contains(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }
  // Callers check Contains(); out-of-range access is undefined.
  Rgb At(int x, int y) const {
    const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3;
    return {pixels[i], pixels[i + 1], pixels[i + 2]};
  }
  void Set(int x, int y, Rgb c) {
    const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3;
    pixels[i] = c[0];
    pixels[i + 1] = c[1];
    pixels[i + 2] = c[2];
  }
  // Ignores pixels outside the image, so shapes may be clipped freely.
  void SetClipped(int x, int y, Rgb c) {
    if (Contains(x, y)) Set(x, y, c);
  }
};

// Copies `src` into `dst` with its top-left corner at (x0, y0), clipped.
void Blit(const RgbImage& src, int x0, int y0, RgbImage& dst);

}  // namespace surfmap
