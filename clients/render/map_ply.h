// WriteMapPly: a friction map as an ASCII PLY that MeshLab (and any PLY
// reader) opens: per vertex x y z nx ny nz (float), mu and mu_std (float),
// red green blue (uchar, the colour map applied to mu); faces as
// `vertex_indices` lists.
#pragma once

#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "clients/render/color_map.h"
#include "clients/render/map_mesh.h"

namespace surfmap {

struct MapPlyOptions {
  ColorMap color_map = ColorMap::kGrey;
  std::optional<double> value_min;  // colour scale; default: the finite value range
  std::optional<double> value_max;
  Rgb no_data_color = {170, 60, 150};
  std::string comment;  // optional one-line provenance comment (newlines become spaces)
};

// The PLY text. `mesh.values` goes to property `mu` and `mesh.uncertainties`
// (zero when empty) to `mu_std`; unknown (NaN) values are written as `nan`
// and coloured with no_data_color. Errors: INVALID_ARGUMENT from
// ValidateMapMesh, or a value_min > value_max.
absl::StatusOr<std::string> WriteMapPly(const MapMesh& mesh, const MapPlyOptions& options = {});

}  // namespace surfmap
