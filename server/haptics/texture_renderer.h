// TextureRenderer: the map as a haptic texture. For a probe's contact point,
// sliding velocity and normal force it returns the friction force (Coulomb,
// mu interpolated at the point, against the sliding direction) and a
// roughness force resynthesised from the map's AR model over the arc length
// the probe has slid (spatial_texture.h), so the texture belongs to the
// place: a probe that stops feels a steady force, and one that goes back
// feels the same bumps in reverse.
//
// Per-sample cost: one coherent closest-triangle query (surface_locator.h),
// barycentric interpolation of the vertex quantities, and an impulse-response
// sum of a few dozen table look-ups. Sample() allocates nothing (all state is
// in the caller's ProbeState; the renderer is immutable after Create), so it
// can run in a 1 kHz haptic loop; texture_renderer_benchmark.cc measures it.
//
// Interpolation within a triangle: mu linearly over the vertices that know
// it (and, with sharp_regions, lie in the heaviest vertex's region); roughness in reflection coefficients (any |k| < 1 is a stable model)
// and log sigma over the vertices that have a roughness fit, the amplitude
// scaled by the share of the triangle's weight that has one (a texture fades
// out towards a region without roughness instead of jumping).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "server/haptics/spatial_texture.h"
#include "server/haptics/surface_locator.h"
#include "server/haptics/texture_map.h"

namespace surfmap::haptics {

struct TextureRendererOptions {
  std::uint64_t seed = 1;          // the texture realisation (spatial_texture.h)
  // Below this tangential speed the sliding direction is undefined: no
  // friction or roughness force is applied (holding the probe is the haptic
  // loop's business, e.g. a static-friction spring).
  double min_speed_mm_s = 1e-3;
  // A probe farther than this from the surface is not in contact: no force,
  // and the stroke ends (touching down again starts a new one).
  double contact_distance_mm = 2.0;
  // Materials do not blend: in a triangle whose vertices lie in different
  // regions, only the vertices of the region of the heaviest vertex (the
  // nearest, in barycentric weight) are interpolated, so the boundary runs
  // sharp through the triangle instead of a band of mixed friction an edge
  // wide. Off: plain interpolation over all three vertices.
  bool sharp_regions = true;
  bool IsValid(std::string* why) const;
};

// The renderer's memory of one probe between samples. Create one per probe
// and pass it to every Sample() call of that probe; Reset() starts a new stroke.
struct ProbeState {
  int triangle = -1;                  // the last closest triangle (lookup hint)
  bool touching = false;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   // last surface point
  Eigen::Vector3d stroke = Eigen::Vector3d::Zero();  // unit tangent: the direction s grows
  double arc_length_mm = 0.0;         // signed arc length slid in this stroke
  // The texture cell of arc length 0 in this stroke: a hash of the touchdown
  // point's cell on a grid of grid_step_mm, so strokes started at different
  // places feel different realisations and one started at the same place the same.
  std::int64_t stroke_origin = 0;
  ArImpulse impulse;                  // cached impulse response of the last model
  void Reset();
};

struct SurfaceLookup {
  int triangle = -1;
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // interpolated vertex normal, unit
  double distance_mm = 0.0;
};

struct ContactSample {
  bool in_contact = false;
  SurfaceLookup surface;
  int region = -1;                    // the region of the triangle's heaviest vertex
  bool mu_known = false;              // false: no vertex of the triangle knows mu (mu = 0)
  double mu = 0.0;
  double sigma = 0.0;                 // innovation std of the local AR model, N
  double arc_length_mm = 0.0;         // the probe's arc length (drives the texture)
  std::int64_t cell = 0;              // the texture cell: stroke_origin + round(arc length / grid step)
  double roughness_n = 0.0;           // r: tangential texture force against the motion, N
  // Forces by the surface on the probe, N (tangential; the normal force is
  // the caller's): friction = -mu Fn u, roughness = -r u, u the unit
  // tangential velocity. Zero below min_speed_mm_s or out of contact.
  Eigen::Vector3d friction_force = Eigen::Vector3d::Zero();
  Eigen::Vector3d roughness_force = Eigen::Vector3d::Zero();
  Eigen::Vector3d tangential_force = Eigen::Vector3d::Zero();
};

class TextureRenderer {
 public:
  // Validates the map (ValidateTextureMap) and the options, builds the
  // lookup grid and the noise table.
  static absl::StatusOr<std::unique_ptr<TextureRenderer>> Create(TextureMap map,
                                                                  const TextureRendererOptions& options = {});

  // The closest surface point, using and updating state.triangle as the
  // hint. (Sample() does this itself; exposed as the benchmark's baseline.)
  SurfaceLookup Locate(const Eigen::Vector3d& position, ProbeState& state) const;

  // One haptic sample: probe at `position` (mm) moving at `velocity` (mm/s)
  // pressing with `normal_force_n` (N, >= 0; negative is taken as 0).
  // Allocation-free.
  ContactSample Sample(ProbeState& state, const Eigen::Vector3d& position, const Eigen::Vector3d& velocity,
                       double normal_force_n) const;

  const TextureMap& map() const { return map_; }
  const TextureRendererOptions& options() const { return options_; }
  const SurfaceLocator& locator() const { return locator_; }

 private:
  TextureRenderer(TextureMap map, const TextureRendererOptions& options);

  TextureMap map_;
  TextureRendererOptions options_;
  SurfaceLocator locator_;
  SpatialTexture texture_;
  std::vector<double> log_sigma_;  // per vertex; NaN where no roughness fit
};

}  // namespace surfmap::haptics
