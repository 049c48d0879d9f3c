// SimulateDrag (the API call) on a map already fetched as a GetMapResponse
// with its mesh: validates the request, renders the drag through the texture
// renderer and returns the response. The service calls this after building
// the map; tests and clients can call it on a saved response.
#pragma once

#include "absl/status/statusor.h"
#include "proto/surfmap/v1/surfmap.pb.h"

namespace surfmap::haptics {

// Errors: INVALID_ARGUMENT naming the field (ranges in surfmap.proto), a map
// without mesh, or a direction along the normal; FAILED_PRECONDITION when
// the start is more than 2 mm from the surface, the map has no measured
// value yet, or the path leaves the surface.
absl::StatusOr<::surfmap::v1::SimulateDragResponse> SimulateDragOnMap(const ::surfmap::v1::GetMapResponse& map,
                                                                     const ::surfmap::v1::SimulateDragRequest& request);

}  // namespace surfmap::haptics
