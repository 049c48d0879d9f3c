// The API's map (GetMapResponse: MapLevel + mesh) as a TextureMap, the input
// of every exporter and of the renderer. Shared by the CLI, the service's
// SimulateDrag and the tests, so they all see the same model.
#pragma once

#include "absl/status/statusor.h"
#include "server/haptics/texture_map.h"
#include "proto/surfmap/v1/surfmap.pb.h"

namespace surfmap::haptics {

// The AR grid step of a map: the grid_step_mm of its samples' roughness fits
// (one per job), or 0.1 mm (the estimator's default) when no sample has one.
double GridStepOf(const ::surfmap::v1::MapLevel& map);

// Needs the mesh (GetMapRequest.include_mesh). Per-vertex reflection
// coefficients come from a1, a2 (the map's AR(2) per vertex). Errors:
// INVALID_ARGUMENT for a response without a mesh, per-vertex arrays whose
// length is not the mesh's vertex count, a triangle index list not a
// multiple of 3, and ValidateTextureMap's.
absl::StatusOr<TextureMap> TextureMapFromResponse(const ::surfmap::v1::GetMapResponse& response);

}  // namespace surfmap::haptics
