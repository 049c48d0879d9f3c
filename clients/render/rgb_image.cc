#include "clients/render/rgb_image.h"

namespace surfmap {

void Blit(const RgbImage& src, int x0, int y0, RgbImage& dst) {
  for (int y = 0; y < src.height; ++y) {
    for (int x = 0; x < src.width; ++x) dst.SetClipped(x0 + x, y0 + y, src.At(x, y));
  }
}

}  // namespace surfmap
