// SimulateDrag (the API call) on a map already fetched as a GetMapResponse
// with its mesh: validates the request, renders the drag through the texture
// renderer and returns the response. The service checks the request
// (ValidateSimulateDragRequest) before it builds the map, then calls
// SimulateDragOnMap; tests and clients can call it on a saved response.
#pragma once

#include <cstdint>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "proto/surfmap/v1/surfmap.pb.h"
#include "server/haptics/model_drag.h"

namespace surfmap::haptics {

// What a SimulateDragRequest asks for, its defaults filled in.
struct SimulateDragSettings {
  double length_mm = 20.0;
  ModelDragOptions options;
  Eigen::Vector3d start = Eigen::Vector3d::Zero();      // mm
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // finite, non-zero
  std::uint64_t seed = 1;
};

// The checks that need only the request (not the map nor the job): every
// field in its range (surfmap.proto), a finite position and a finite non-zero
// direction. Errors: INVALID_ARGUMENT naming the field. Cheap, so a bad
// request is refused before the map is built.
absl::StatusOr<SimulateDragSettings> ValidateSimulateDragRequest(const ::surfmap::v1::SimulateDragRequest& request);

// Errors: those of ValidateSimulateDragRequest; INVALID_ARGUMENT for a map
// without mesh, or a direction along the normal; FAILED_PRECONDITION when
// the start is more than 2 mm from the surface, the map has no measured
// value yet, or the path leaves the surface.
absl::StatusOr<::surfmap::v1::SimulateDragResponse> SimulateDragOnMap(const ::surfmap::v1::GetMapResponse& map,
                                                                     const ::surfmap::v1::SimulateDragRequest& request);

}  // namespace surfmap::haptics
