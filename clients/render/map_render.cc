#include "clients/render/map_render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>
#include "absl/strings/str_cat.h"
#include "clients/render/depth_canvas.h"
#include "clients/render/digit_font.h"
#include "clients/render/png_encoding.h"
#include "clients/render/view_camera.h"

namespace surfmap {
namespace {

Rgb Scale(Rgb c, double k) {
  Rgb out;
  for (int i = 0; i < 3; ++i) {
    out[i] = static_cast<std::uint8_t>(std::clamp(std::lround(c[i] * k), 0L, 255L));
  }
  return out;
}

std::string FormatLabel(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3g", v);
  return buf;
}

absl::Status ValidateOverlay(const MapOverlay& overlay) {
  for (size_t i = 0; i < overlay.sample_points.size(); ++i) {
    if (!overlay.sample_points[i].allFinite()) {
      return absl::InvalidArgumentError(absl::StrCat("sample point ", i, " is not finite"));
    }
  }
  for (size_t p = 0; p < overlay.drag_paths.size(); ++p) {
    for (size_t i = 0; i < overlay.drag_paths[p].size(); ++i) {
      if (!overlay.drag_paths[p][i].allFinite()) {
        return absl::InvalidArgumentError(absl::StrCat("drag path ", p, " point ", i, " is not finite"));
      }
    }
  }
  return absl::OkStatus();
}

struct ColorScale {
  ColorMap map;
  double lo;
  double hi;
};

RgbImage RenderView(const MapMesh& mesh, const std::vector<Eigen::Vector3d>& normals, const MapOverlay& overlay,
                    const MapRenderOptions& options, const Eigen::Vector3d& view_direction,
                    const ColorScale& scale) {
  Eigen::AlignedBox3d box;
  for (const auto& p : mesh.positions) box.extend(p);
  ViewCameraSpec spec;
  spec.view_direction = view_direction;
  spec.up = options.up;
  spec.perspective = options.perspective;
  spec.fov_deg = options.fov_deg;
  const ViewCamera camera = ViewCamera::Frame(box, spec, options.view_width, options.view_height);

  std::vector<Eigen::Vector3d> screen(mesh.positions.size());
  for (size_t i = 0; i < screen.size(); ++i) screen[i] = camera.Project(mesh.positions[i]);

  DepthCanvas canvas(options.view_width, options.view_height, options.background);
  for (const auto& t : mesh.triangles) {
    const double va = mesh.values[t[0]], vb = mesh.values[t[1]], vc = mesh.values[t[2]];
    const Eigen::Vector3d& na = normals[t[0]];
    const Eigen::Vector3d& nb = normals[t[1]];
    const Eigen::Vector3d& nc = normals[t[2]];
    const Eigen::Vector3d& pa = mesh.positions[t[0]];
    const Eigen::Vector3d& pb = mesh.positions[t[1]];
    const Eigen::Vector3d& pc = mesh.positions[t[2]];
    RasterizeTriangle(canvas, screen[t[0]], screen[t[1]], screen[t[2]], [&](const Eigen::Vector3d& w) {
      // Interpolate the value, not the colour: the colour map is then applied
      // per pixel, so region boundaries stay as sharp as the data.
      const double value = w[0] * va + w[1] * vb + w[2] * vc;
      const Rgb base = std::isnan(value) ? options.no_data_color
                                         : MapColor(scale.map, NormalizeToRange(value, scale.lo, scale.hi));
      Eigen::Vector3d n = w[0] * na + w[1] * nb + w[2] * nc;
      const double len = n.norm();
      const Eigen::Vector3d ray = camera.RayDirection(w[0] * pa + w[1] * pb + w[2] * pc);
      // Two-sided headlight: a surface facing the camera gets full colour.
      const double lambert = len > 0 ? std::abs(n.dot(ray)) / len : 1.0;
      return Scale(base, options.ambient + (1.0 - options.ambient) * lambert);
    });
  }

  // Overlays lie on the surface: allow a depth slack of a small share of the
  // object's size so they are not lost to z-fighting, yet stay hidden behind it.
  const double bias = 0.02 * camera.scene_radius();
  for (const auto& path : overlay.drag_paths) {
    for (size_t i = 1; i < path.size(); ++i) {
      DrawLine(canvas, camera.Project(path[i - 1]), camera.Project(path[i]), options.line_width_px,
               options.path_color, bias);
    }
  }
  for (const auto& p : overlay.sample_points) {
    DrawDot(canvas, camera.Project(p), options.dot_radius_px, options.sample_color, bias);
  }
  return std::move(canvas.image);
}

void DrawColorBar(RgbImage& image, int x0, const ColorScale& scale, const MapRenderOptions& options) {
  const int text_scale = 2;
  const int text_h = kGlyphHeight * text_scale;
  const int bar_w = 24;
  const int bar_x = x0 + (kColorBarStripWidth - bar_w) / 2;
  // The title (at font scale 1) above the max label, when there is one.
  const int title_h = options.color_bar_title.empty() ? 0 : kGlyphHeight + 6;
  const int bar_top = 12 + title_h + text_h + 6;
  const int bar_bottom = image.height - 12 - text_h - 6;
  if (bar_bottom <= bar_top) return;
  for (int y = bar_top; y <= bar_bottom; ++y) {
    const double t = 1.0 - static_cast<double>(y - bar_top) / (bar_bottom - bar_top);  // max at the top
    const Rgb c = MapColor(scale.map, t);
    for (int x = bar_x; x < bar_x + bar_w; ++x) image.SetClipped(x, y, c);
  }
  const std::string max_label = FormatLabel(scale.hi);
  const std::string min_label = FormatLabel(scale.lo);
  const int center = x0 + kColorBarStripWidth / 2;
  if (title_h > 0) {
    DrawText(image, center - TextWidth(options.color_bar_title, 1) / 2, 8, options.color_bar_title,
             options.label_color, 1);
  }
  DrawText(image, center - TextWidth(max_label, text_scale) / 2, 12 + title_h, max_label, options.label_color,
           text_scale);
  DrawText(image, center - TextWidth(min_label, text_scale) / 2, bar_bottom + 6, min_label, options.label_color,
           text_scale);
}

}  // namespace

bool MapRenderOptions::IsValid(std::string* why) const {
  auto fail = [why](std::string message) {
    if (why != nullptr) *why = std::move(message);
    return false;
  };
  if (view_width < 16 || view_width > 8192) return fail(absl::StrCat("view_width ", view_width, " not in 16..8192"));
  if (view_height < 16 || view_height > 8192) {
    return fail(absl::StrCat("view_height ", view_height, " not in 16..8192"));
  }
  if (!view_direction.allFinite() || view_direction.norm() < 1e-12) {
    return fail("view_direction must be a finite non-zero vector");
  }
  if (!up.allFinite()) return fail("up must be finite");
  if (perspective && !(fov_deg > 1.0 && fov_deg < 120.0)) {
    return fail(absl::StrCat("fov_deg ", fov_deg, " not in (1, 120)"));
  }
  if (value_min && !std::isfinite(*value_min)) return fail("value_min must be finite");
  if (value_max && !std::isfinite(*value_max)) return fail("value_max must be finite");
  if (value_min && value_max && *value_min > *value_max) {
    return fail(absl::StrCat("value_min ", *value_min, " > value_max ", *value_max));
  }
  if (!(ambient >= 0.0 && ambient <= 1.0)) return fail(absl::StrCat("ambient ", ambient, " not in [0, 1]"));
  if (!(dot_radius_px >= 0.0 && dot_radius_px <= 100.0)) {
    return fail(absl::StrCat("dot_radius_px ", dot_radius_px, " not in [0, 100]"));
  }
  if (line_width_px < 1 || line_width_px > 50) {
    return fail(absl::StrCat("line_width_px ", line_width_px, " not in 1..50"));
  }
  return true;
}

absl::StatusOr<RgbImage> RenderMap(const MapMesh& mesh, const MapOverlay& overlay, const MapRenderOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("render options: ", why));
  if (absl::Status s = ValidateMapMesh(mesh); !s.ok()) return s;
  if (absl::Status s = ValidateOverlay(overlay); !s.ok()) return s;

  const auto [data_lo, data_hi] = FiniteValueRange(mesh.values);
  ColorScale scale{options.color_map, options.value_min.value_or(data_lo), options.value_max.value_or(data_hi)};
  if (scale.lo > scale.hi) std::swap(scale.lo, scale.hi);  // only one bound given, beyond the data

  const std::vector<Eigen::Vector3d> normals = mesh.normals.empty() ? ComputeVertexNormals(mesh) : mesh.normals;
  const int views = options.two_views ? 2 : 1;
  const int width = views * options.view_width + (options.color_bar ? kColorBarStripWidth : 0);
  RgbImage image(width, options.view_height, options.background);
  const Eigen::Vector3d dir = options.view_direction.normalized();
  Blit(RenderView(mesh, normals, overlay, options, dir, scale), 0, 0, image);
  if (options.two_views) Blit(RenderView(mesh, normals, overlay, options, -dir, scale), options.view_width, 0, image);
  if (options.color_bar) DrawColorBar(image, views * options.view_width, scale, options);
  return image;
}

absl::StatusOr<std::string> RenderMapPng(const MapMesh& mesh, const MapOverlay& overlay,
                                         const MapRenderOptions& options) {
  absl::StatusOr<RgbImage> image = RenderMap(mesh, overlay, options);
  if (!image.ok()) return image.status();
  return EncodePng(*image);
}

}  // namespace surfmap
