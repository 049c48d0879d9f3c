// From a GetMap response to the renderers' input: the mesh coloured by mu and
// the measured samples with their drag segments.
#pragma once

#include "clients/render/map_mesh.h"
#include "clients/render/map_render.h"
#include "proto/surfmap/v1/surfmap.pb.h"

namespace surfmap::cli {

// Positions, normals and triangles of the response's mesh; values = mu,
// uncertainties = mu_uncertainty (when they have one entry per vertex).
MapMesh MapMeshFromResponse(const surfmap::v1::GetMapResponse& response);

// A dot per sample and its drag segment: `segment_length_mm` from the sample
// position along its drag direction, bent onto the surface by projecting each
// point onto the tangent plane of its nearest mesh vertex (the server does not
// send the executed path; on a 40 mm radius a straight 20 mm chord would sink
// 1.25 mm into the surface and be hidden).
MapOverlay SampleOverlay(const MapMesh& mesh, const surfmap::v1::MapLevel& map);

}  // namespace surfmap::cli
