// The texture map as an ASCII PLY that MeshLab and ParaView open (they show
// any vertex property), and that TextureRenderer loads back:
//
//   comment surfmap.texture-ply.v1
//   comment job_id <id>
//   comment level <k>
//   comment grid_step_mm <L>        the AR model's arc-length grid
//   comment units mm N               positions in mm, sigma in N
//   element vertex <n>
//   property double x y z [nx ny nz] mu mu_std [sigma a1 a2] [k1 .. kp]
//   property int region              [-1 = no region]
//   property double boundary_probability
//   property uchar red green blue    grey by mu (whiter = more friction; magenta = unknown)
//   element face <m>
//   property list uchar int vertex_indices
//
// Properties in [] are written when the map has them. Doubles are written
// with 17 significant digits (they read back bit for bit); unknown values
// as `nan`.
#pragma once

#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "server/haptics/texture_map.h"

namespace surfmap::haptics {

inline constexpr std::string_view kTexturePlyFormat = "surfmap.texture-ply.v1";

// Errors: ValidateTextureMap's.
absl::StatusOr<std::string> WriteTexturePly(const TextureMap& map);

// Reads a PLY written by WriteTexturePly (ASCII; the properties may come in
// any order; unknown vertex properties are ignored; faces must be
// triangles). Errors: INVALID_ARGUMENT naming `source` and the line.
absl::StatusOr<TextureMap> ReadTexturePly(std::string_view text, std::string_view source);

}  // namespace surfmap::haptics
