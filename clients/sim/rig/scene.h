// A scene: an object the simulated rig can probe. A control mesh (OBJ or PLY)
// plus a small JSON file of materials and regions (clients/sim/scenes/README.md):
//
//   {"name": "bottle", "mesh": "bottle.obj", "units": "mm", "seed": 1, "surface": "control_mesh",
//    "default_material": "glass",
//    "materials": {"glass": {"mu": 0.13, "a1": 0, "a2": 0, "sigma": 0.005}, ...},
//    "regions": [{"material": "sandpaper", "shape": "cylinder_patch", ...},
//                {"material": "...", "shape": "box", "min": [..], "max": [..]},
//                {"material": "...", "shape": "sphere", "center": [..], "radius": r},
//                {"material": "...", "shape": "oriented_box", "center": [..], "u": [..], "v": [..],
//                 "half_size": [hu, hv, hw]},
//                {"material": "...", "shape": "polygon_decal", "center": [..], "u": [..], "v": [..],
//                 "polygon": [[x, y], ...], "depth": [from, to]}]}
//
// The first region containing a point gives its material; elsewhere the
// default material applies. Everything is converted to mm on load.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "clients/sim/dragsim/material.h"
#include "server/mesh/control_mesh.h"

namespace surfmap {

// Axis-aligned box, bounds inclusive.
struct BoxRegion {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
};

// Closed ball.
struct SphereRegion {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

// A patch on a cylinder-like object: the points whose cylindrical coordinates
// about the axis (through axis_point along unit `axis`) fall in an angle
// range, a height range along the axis and a radial range. Angles are
// counter-clockwise about the axis from `reference` (unit, perpendicular to
// the axis: the world axis least aligned with it, projected).
struct CylinderPatchRegion {
  Eigen::Vector3d axis_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d reference = Eigen::Vector3d::UnitX();
  double angle_from_deg = 0.0;  // angle_from < angle_to <= angle_from + 360
  double angle_to_deg = 0.0;
  double height_from_mm = 0.0;  // along the axis from axis_point
  double height_to_mm = 0.0;
  double radial_min_mm = 0.0;   // distance from the axis
  double radial_max_mm = 1e300;
};

// A frame at any orientation: unit axes u, v (made orthogonal to u) and
// w = u x v from `center`.
struct RegionFrame {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d u = Eigen::Vector3d::UnitX();
  Eigen::Vector3d v = Eigen::Vector3d::UnitY();
  Eigen::Vector3d w = Eigen::Vector3d::UnitZ();
  // A point's coordinates along u, v and w from the centre.
  Eigen::Vector3d Local(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d d = p - center;
    return {d.dot(u), d.dot(v), d.dot(w)};
  }
};

// A box in any orientation: the points whose coordinates in `frame` are
// within +-half_size on each axis. Strips (thin along one axis) and patches
// at any angle to the world axes.
struct OrientedBoxRegion {
  RegionFrame frame;
  Eigen::Vector3d half_size = Eigen::Vector3d::Zero();
};

// A decal: a flat polygon in the plane of `frame` (through its centre,
// spanned by u and v), projected along w onto the surface, within a depth
// range along w: the shapes of labels, triangles (corners sharper than a
// right angle), L-shapes (a corner turning inwards), any outline. Inside is
// the even-odd rule on the polygon's edges (it closes itself).
struct PolygonDecalRegion {
  RegionFrame frame;
  std::vector<Eigen::Vector2d> polygon;  // mm, in (u, v) from the frame's centre
  double depth_from_mm = 0.0;            // along w from center
  double depth_to_mm = 0.0;
};

using RegionShape =
    std::variant<BoxRegion, SphereRegion, CylinderPatchRegion, OrientedBoxRegion, PolygonDecalRegion>;

struct SceneRegion {
  int material = 0;  // index into Scene::materials
  RegionShape shape;
  bool Contains(const Eigen::Vector3d& point) const;
};

struct Scene {
  std::string name;
  std::string source;                        // the JSON file it came from (for messages)
  ControlMesh mesh;                          // mm
  std::vector<std::string> material_names;   // sorted by name; index = material index
  std::vector<Material> materials;
  int default_material = 0;
  std::vector<SceneRegion> regions;          // in file order: the first match wins
  std::uint64_t seed = 1;                    // makes simulated traces reproducible per scene
  // "surface": "facets" in the JSON: the mesh's flat facets are the object's
  // surface (a CAD part, uploaded with OBJECT_SURFACE_FACETS), not a Loop
  // control mesh. The rig drags, and the scorer scores, the facets
  // (SceneSurface).
  bool facets = false;

  // Index into materials of the material at `point` (mm).
  int MaterialIndexAt(const Eigen::Vector3d& point) const;
  const Material& MaterialAt(const Eigen::Vector3d& point) const { return materials[MaterialIndexAt(point)]; }
  // Index of the material called `name`, or -1.
  int FindMaterial(std::string_view name) const;
};

// Parses the JSON text of a scene; the mesh file it names is read relative
// to `base_dir`. Strict: unknown keys, wrong types, missing fields, unknown
// material names, non-finite numbers, empty or inverted ranges, negative
// sigma or mu, non-stationary AR(2) roughness, unsupported units and an
// invalid mesh are INVALID_ARGUMENT with a message naming `source` and the
// JSON path (e.g. "bottle.json: regions[1].radius: must be > 0"); a missing
// mesh file is NOT_FOUND.
absl::StatusOr<Scene> ParseScene(std::string_view json_text, std::string_view source,
                                 const std::filesystem::path& base_dir);

// Reads and parses a scene JSON file (NOT_FOUND if it does not exist).
absl::StatusOr<Scene> LoadSceneFiles(const std::filesystem::path& json_path);

// Loads `<dir>/<name>.json`. `name` must be 1-64 characters of [A-Za-z0-9_-]
// (it may come from a remote user: no paths).
absl::StatusOr<Scene> LoadScene(const std::filesystem::path& dir, std::string_view name);

// The directories searched for scenes by name, in order: each entry of
// $SURFMAP_SCENES (colon-separated), <exe dir>/../share/surfmap/scenes, then
// the source tree's clients/sim/scenes.
std::vector<std::filesystem::path> SceneSearchPath();

// Loads scene `name` from the first directory of SceneSearchPath() holding
// `<name>.json`. NOT_FOUND lists the directories searched.
absl::StatusOr<Scene> LoadSceneByName(std::string_view name);

// The material field of `scene` for the drag simulator (holds a copy).
MaterialField SceneMaterialField(const Scene& scene);

}  // namespace surfmap
