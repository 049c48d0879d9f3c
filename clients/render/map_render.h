// RenderMap / RenderMapPng: a friction map as an image. A small software
// rasteriser (z-buffer, Lambert shading from the vertex normals with a
// headlight) of a mesh coloured by a per-vertex scalar, with the sample
// points as dots and the drag segments as lines (hidden ones not drawn), a
// colour bar with min/max labels, and optionally a second view from the
// opposite side so the whole object is visible.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "clients/render/color_map.h"
#include "clients/render/map_mesh.h"
#include "clients/render/rgb_image.h"

namespace surfmap {

struct MapOverlay {
  std::vector<Eigen::Vector3d> sample_points;            // mm, drawn as dots
  std::vector<std::vector<Eigen::Vector3d>> drag_paths;  // mm, polylines (>= 2 points each)
};

struct MapRenderOptions {
  int view_width = 480;   // px per view
  int view_height = 480;
  Eigen::Vector3d view_direction = Eigen::Vector3d(0, 1, 0);  // the way the (first) camera looks
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  bool two_views = true;      // add a view looking along -view_direction, to the right
  bool perspective = false;   // orthographic by default (no size distortion of patches)
  double fov_deg = 30.0;      // perspective only, in (1, 120)
  ColorMap color_map = ColorMap::kGrey;
  // Colour scale; each defaults to the min/max of the finite values.
  std::optional<double> value_min;
  std::optional<double> value_max;
  bool color_bar = true;
  // Drawn above the colour bar, e.g. "SIGMA (N)": the quantity and its unit
  // (capitals, digits and ()_/ only, see digit_font.h; ~15 characters fit).
  std::string color_bar_title;
  Rgb background = {24, 32, 56};      // dark blue: distinct from every grey and from viridis' ends
  Rgb no_data_color = {170, 60, 150};  // vertices whose value is NaN
  Rgb sample_color = {255, 120, 0};
  Rgb path_color = {230, 30, 30};
  Rgb label_color = {255, 255, 255};
  double dot_radius_px = 3.0;
  int line_width_px = 2;
  double ambient = 0.3;  // share of the colour kept on surfaces seen edge-on, [0, 1]

  // False (and `why` says which field) for sizes outside 16..8192, a zero
  // view direction, non-finite or inverted value range, fov out of range,
  // ambient outside [0, 1], negative dot radius or line width < 1.
  bool IsValid(std::string* why) const;
};

// The rendered image: views side by side, then the colour bar (if enabled).
// Errors: INVALID_ARGUMENT for an invalid mesh (ValidateMapMesh), invalid
// options or non-finite overlay points (naming the point or path).
absl::StatusOr<RgbImage> RenderMap(const MapMesh& mesh, const MapOverlay& overlay, const MapRenderOptions& options);

// RenderMap encoded as PNG bytes (the caller writes the file or sends them).
absl::StatusOr<std::string> RenderMapPng(const MapMesh& mesh, const MapOverlay& overlay,
                                         const MapRenderOptions& options);

// Width of the colour bar strip added on the right when color_bar is set.
inline constexpr int kColorBarStripWidth = 96;

}  // namespace surfmap
