#include "clients/render/depth_canvas.h"

namespace surfmap {

bool IsVisible(const DepthCanvas& canvas, const Eigen::Vector3d& p, double bias) {
  const int x = static_cast<int>(std::floor(p.x()));
  const int y = static_cast<int>(std::floor(p.y()));
  if (!canvas.image.Contains(x, y)) return false;
  // A point on the rim may fall on a background pixel; then compare with the
  // nearest surface drawn in its 3x3 neighbourhood instead.
  float nearest_surface = canvas.DepthAt(x, y);
  if (!std::isfinite(nearest_surface)) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (!canvas.image.Contains(x + dx, y + dy)) continue;
        nearest_surface = std::min(nearest_surface, canvas.DepthAt(x + dx, y + dy));
      }
    }
  }
  if (!std::isfinite(nearest_surface)) return true;  // nothing drawn around it
  return p.z() <= nearest_surface + bias;
}

void DrawDot(DepthCanvas& canvas, const Eigen::Vector3d& p, double radius, Rgb color, double bias) {
  if (!IsVisible(canvas, p, bias)) return;
  const int r = static_cast<int>(std::ceil(radius));
  const int cx = static_cast<int>(std::floor(p.x()));
  const int cy = static_cast<int>(std::floor(p.y()));
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      if (dx * dx + dy * dy <= radius * radius) canvas.image.SetClipped(cx + dx, cy + dy, color);
    }
  }
}

void DrawLine(DepthCanvas& canvas, const Eigen::Vector3d& a, const Eigen::Vector3d& b, int width, Rgb color,
              double bias) {
  const double len = std::max(std::abs(b.x() - a.x()), std::abs(b.y() - a.y()));
  if (!std::isfinite(len)) return;
  const int steps = std::max(1, static_cast<int>(std::ceil(2.0 * len)));
  const int lo = -(width - 1) / 2;
  const int hi = lo + width - 1;
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector3d p = a + (b - a) * (static_cast<double>(i) / steps);
    if (!IsVisible(canvas, p, bias)) continue;
    const int x = static_cast<int>(std::floor(p.x()));
    const int y = static_cast<int>(std::floor(p.y()));
    for (int dy = lo; dy <= hi; ++dy) {
      for (int dx = lo; dx <= hi; ++dx) canvas.image.SetClipped(x + dx, y + dy, color);
    }
  }
}

}  // namespace surfmap
