// What the planner hands to a rig: one drag measurement at one site.
#pragma once

#include <compare>
#include <cstdint>

#include <Eigen/Core>

namespace surfmap {

// A sampling site: vertex `vertex` of subdivision level `level`. By the mesh's
// numbering contract it is also vertex `vertex` of every finer level, so a
// vertex is measured at most once whatever level names it.
struct SiteId {
  int level = 0;
  int vertex = -1;
  auto operator<=>(const SiteId&) const = default;
};

struct ProbeParameters {
  double segment_length_mm = 20.0;  // paper: 20 mm
  double speed_mm_per_s = 10.0;     // paper: 10 mm/s
  double normal_force_n = 5.0;      // paper: 5 N
};

struct ProbeCommand {
  std::uint64_t sequence = 0;  // unique per plan, increasing from 1
  SiteId site;
  int attempt = 1;             // 1 for the first issue of a site, 2 after one failure, ...
  Eigen::Vector3d position = Eigen::Vector3d::Zero();        // limit position of the site, mm
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();         // unit limit normal, outward
  Eigen::Vector3d drag_direction = Eigen::Vector3d::UnitX(); // unit, tangent (orthogonal to normal)
  ProbeParameters probe;
};

}  // namespace surfmap
