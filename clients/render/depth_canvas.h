// A colour image with a z-buffer: triangles write depth, overlays (dots,
// lines) only test against it, so hidden samples and segments are not drawn.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include "clients/render/rgb_image.h"

namespace surfmap {

struct DepthCanvas {
  RgbImage image;
  std::vector<float> depth;  // +inf where nothing was drawn

  DepthCanvas(int width, int height, Rgb background)
      : image(width, height, background),
        depth(static_cast<size_t>(width) * height, std::numeric_limits<float>::infinity()) {}

  float DepthAt(int x, int y) const { return depth[static_cast<size_t>(y) * image.width + x]; }
};

// Fills the screen-space triangle (x, y, depth per corner) with z-buffering.
// `shade(barycentric)` gives the colour of a covered pixel; barycentrics are
// screen-affine (exact for orthographic views, close enough for the narrow
// perspective used here). Pixels are covered when their centre is inside.
inline constexpr double kEdgeTolerance = 1e-7;

template <typename Shade>
void RasterizeTriangle(DepthCanvas& canvas, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c, Shade&& shade) {
  const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
  if (!(std::abs(area) > 1e-12)) return;  // degenerate on screen (also catches NaN)
  const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x(), b.x(), c.x()}))));
  const int x1 = std::min(canvas.image.width - 1, static_cast<int>(std::ceil(std::max({a.x(), b.x(), c.x()}))));
  const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y(), b.y(), c.y()}))));
  const int y1 = std::min(canvas.image.height - 1, static_cast<int>(std::ceil(std::max({a.y(), b.y(), c.y()}))));
  const double inv_area = 1.0 / area;
  for (int y = y0; y <= y1; ++y) {
    const double py = y + 0.5;
    for (int x = x0; x <= x1; ++x) {
      const double px = x + 0.5;
      const double w0 = ((b.x() - px) * (c.y() - py) - (b.y() - py) * (c.x() - px)) * inv_area;
      const double w1 = ((c.x() - px) * (a.y() - py) - (c.y() - py) * (a.x() - px)) * inv_area;
      const double w2 = 1.0 - w0 - w1;
      // A small tolerance closes the cracks where a shared edge passes exactly
      // through pixel centres (axis-aligned grids seen head-on); the z-buffer
      // resolves the resulting one-pixel overlap.
      if (w0 < -kEdgeTolerance || w1 < -kEdgeTolerance || w2 < -kEdgeTolerance) continue;
      const float z = static_cast<float>(w0 * a.z() + w1 * b.z() + w2 * c.z());
      float& zbuf = canvas.depth[static_cast<size_t>(y) * canvas.image.width + x];
      if (z >= zbuf) continue;
      zbuf = z;
      canvas.image.Set(x, y, shade(Eigen::Vector3d(w0, w1, w2)));
    }
  }
}

// True when a point at screen position p (x, y, depth) is not behind the
// surface drawn at its pixel, allowing `bias` mm (points lie on the surface).
// Points off the image are not visible.
bool IsVisible(const DepthCanvas& canvas, const Eigen::Vector3d& p, double bias);

// A filled disc of `radius` px centred at p, drawn only if p is visible.
void DrawDot(DepthCanvas& canvas, const Eigen::Vector3d& p, double radius, Rgb color, double bias);

// A line of `width` px from a to b; each part is drawn only where visible.
void DrawLine(DepthCanvas& canvas, const Eigen::Vector3d& a, const Eigen::Vector3d& b, int width, Rgb color,
              double bias);

}  // namespace surfmap
