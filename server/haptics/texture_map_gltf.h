// The texture map as glTF 2.0 for engines: one mesh, one triangle primitive
// with POSITION and NORMAL and the map as custom vertex attributes (the
// spec's application-specific semantics start with an underscore), all FLOAT
// SCALAR:
//   _MU, _MU_STD                  friction coefficient and its std
//   _SIGMA, _A1, _A2              AR roughness (sigma in N) on the grid step
//   _K1 .. _Kp                    reflection coefficients
//   _REGION                       material region index (an integer value)
//   _BOUNDARY_PROBABILITY
// glTF has no NaN (the validator rejects it), so UNKNOWN is written as -1 in
// the attributes whose values are never negative (_MU, _MU_STD, _SIGMA,
// _BOUNDARY_PROBABILITY, and _REGION for "no region"); where sigma is
// unknown, _A1/_A2/_K* are 0.
// Positions are in METRES (glTF's unit; the map's mm / 1000); the mesh's
// extras.surfmap records the format, job, level, grid_step_mm, the units and
// the regions' texture model (texture_model_json.h).
#pragma once

#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "server/haptics/texture_map.h"

namespace surfmap::haptics {

inline constexpr std::string_view kTextureGltfFormat = "surfmap.texture-gltf.v1";

// The .gltf JSON with the buffer embedded as a data URI (binary = false), or
// a .glb (binary = true). Errors: ValidateTextureMap's, or more than 2^32
// vertices.
absl::StatusOr<std::string> WriteTextureGltf(const TextureMap& map, bool binary);

// Reads a file written by WriteTextureGltf back into a TextureMap (positions
// in mm again; -1 unknowns back to NaN; regions from the extras). Errors:
// INVALID_ARGUMENT naming `source` (tinygltf's message, or what is missing).
absl::StatusOr<TextureMap> ReadTextureGltf(std::string_view bytes, std::string_view source);

}  // namespace surfmap::haptics
