#include "clients/sim/rig/scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <set>
#include <sstream>
#include <utility>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"

#ifndef SURFMAP_SOURCE_SCENES_DIR
#define SURFMAP_SOURCE_SCENES_DIR ""
#endif

namespace surfmap {
namespace {

using Json = nlohmann::json;

// Validation errors carry "<source>: <json path>: <problem>".
class SceneParser {
 public:
  SceneParser(std::string_view source, std::filesystem::path base_dir)
      : source_(source), base_dir_(std::move(base_dir)) {}

  absl::StatusOr<Scene> Parse(std::string_view text);

 private:
  absl::Status Error(const std::string& path, const std::string& problem) const {
    return absl::InvalidArgumentError(absl::StrCat(source_, ": ", path, ": ", problem));
  }
  absl::Status CheckKeys(const Json& object, const std::string& path, const std::set<std::string>& required,
                         const std::set<std::string>& optional) const;
  absl::StatusOr<double> Number(const Json& object, const std::string& path, const std::string& key) const;
  absl::StatusOr<std::string> String(const Json& object, const std::string& path, const std::string& key) const;
  absl::StatusOr<Eigen::Vector3d> Vec3(const Json& object, const std::string& path, const std::string& key) const;
  absl::StatusOr<std::array<double, 2>> Range(const Json& object, const std::string& path,
                                              const std::string& key) const;
  // The keys "center" (scaled to mm), "u" and "v".
  absl::StatusOr<RegionFrame> Frame(const Json& object, const std::string& path) const;
  absl::StatusOr<std::vector<Eigen::Vector2d>> Polygon(const Json& object, const std::string& path) const;
  absl::Status ParseMaterials(const Json& materials, Scene& scene) const;
  absl::StatusOr<SceneRegion> ParseRegion(const Json& region, const std::string& path, const Scene& scene) const;

  std::string source_;
  std::filesystem::path base_dir_;
  double scale_ = 1.0;  // file units -> mm
};

std::string Quoted(const std::string& s) { return absl::StrCat("'", s, "'"); }

const char* TypeName(const Json& j) { return j.type_name(); }

absl::Status SceneParser::CheckKeys(const Json& object, const std::string& path, const std::set<std::string>& required,
                                    const std::set<std::string>& optional) const {
  if (!object.is_object()) return Error(path, absl::StrCat("must be an object, not ", TypeName(object)));
  for (const auto& [key, value] : object.items()) {
    if (!required.count(key) && !optional.count(key)) {
      std::vector<std::string> allowed(required.begin(), required.end());
      allowed.insert(allowed.end(), optional.begin(), optional.end());
      std::sort(allowed.begin(), allowed.end());
      return Error(path, absl::StrCat("unknown key ", Quoted(key), " (allowed: ", absl::StrJoin(allowed, ", "), ")"));
    }
  }
  for (const auto& key : required) {
    if (!object.contains(key)) return Error(path, absl::StrCat("missing required key ", Quoted(key)));
  }
  return absl::OkStatus();
}

absl::StatusOr<double> SceneParser::Number(const Json& object, const std::string& path, const std::string& key) const {
  const Json& v = object.at(key);
  if (!v.is_number()) return Error(absl::StrCat(path, ".", key), absl::StrCat("must be a number, not ", TypeName(v)));
  const double d = v.get<double>();
  if (!std::isfinite(d)) return Error(absl::StrCat(path, ".", key), "must be finite");
  return d;
}

absl::StatusOr<std::string> SceneParser::String(const Json& object, const std::string& path,
                                                const std::string& key) const {
  const Json& v = object.at(key);
  if (!v.is_string()) return Error(absl::StrCat(path, ".", key), absl::StrCat("must be a string, not ", TypeName(v)));
  return v.get<std::string>();
}

absl::StatusOr<Eigen::Vector3d> SceneParser::Vec3(const Json& object, const std::string& path,
                                                  const std::string& key) const {
  const Json& v = object.at(key);
  const std::string where = absl::StrCat(path, ".", key);
  if (!v.is_array() || v.size() != 3) return Error(where, "must be an array of 3 numbers");
  Eigen::Vector3d out;
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number()) return Error(absl::StrCat(where, "[", i, "]"), "must be a number");
    out[i] = v[i].get<double>();
  }
  if (!out.allFinite()) return Error(where, "must be finite");
  return out;
}

absl::StatusOr<std::array<double, 2>> SceneParser::Range(const Json& object, const std::string& path,
                                                         const std::string& key) const {
  const Json& v = object.at(key);
  const std::string where = absl::StrCat(path, ".", key);
  if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number()) {
    return Error(where, "must be an array of 2 numbers [from, to]");
  }
  const std::array<double, 2> r{v[0].get<double>(), v[1].get<double>()};
  if (!std::isfinite(r[0]) || !std::isfinite(r[1])) return Error(where, "must be finite");
  if (!(r[0] < r[1])) return Error(where, absl::StrCat("is empty or inverted: [", r[0], ", ", r[1], "]"));
  return r;
}

absl::StatusOr<RegionFrame> SceneParser::Frame(const Json& object, const std::string& path) const {
  auto center = Vec3(object, path, "center");
  auto u = Vec3(object, path, "u");
  auto v = Vec3(object, path, "v");
  if (!center.ok()) return center.status();
  if (!u.ok()) return u.status();
  if (!v.ok()) return v.status();
  if (u->norm() < 1e-12) return Error(path + ".u", "must be non-zero");
  const Eigen::Vector3d unit_u = u->normalized();
  const Eigen::Vector3d v_perp = *v - v->dot(unit_u) * unit_u;
  if (v_perp.norm() < 1e-6 * v->norm() || v->norm() < 1e-12) {
    return Error(path + ".v", "must be non-zero and not parallel to u");
  }
  RegionFrame frame;
  frame.center = *center * scale_;
  frame.u = unit_u;
  frame.v = v_perp.normalized();
  frame.w = frame.u.cross(frame.v);
  return frame;
}

absl::StatusOr<std::vector<Eigen::Vector2d>> SceneParser::Polygon(const Json& object, const std::string& path) const {
  // A label's outline has a handful of corners; a cap keeps a typo (a mesh
  // pasted here) from turning every point test into thousands of edge tests.
  constexpr std::size_t kMaxCorners = 256;
  const Json& corners = object.at("polygon");
  const std::string where = path + ".polygon";
  if (!corners.is_array() || corners.size() < 3 || corners.size() > kMaxCorners) {
    return Error(where, absl::StrCat("must be an array of 3 to ", kMaxCorners, " corners [x, y] (in u, v)"));
  }
  std::vector<Eigen::Vector2d> out;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Json& c = corners[i];
    const std::string at = absl::StrCat(where, "[", i, "]");
    if (!c.is_array() || c.size() != 2 || !c[0].is_number() || !c[1].is_number()) {
      return Error(at, "must be an array of 2 numbers [x, y]");
    }
    const Eigen::Vector2d corner(c[0].get<double>(), c[1].get<double>());
    if (!corner.allFinite()) return Error(at, "must be finite");
    out.push_back(corner);
  }
  double twice_area = 0.0;  // shoelace: a polygon of no area selects nothing
  for (std::size_t i = 0; i < out.size(); ++i) {
    const Eigen::Vector2d& a = out[i];
    const Eigen::Vector2d& b = out[(i + 1) % out.size()];
    twice_area += a.x() * b.y() - b.x() * a.y();
  }
  if (std::abs(twice_area) < 1e-12) return Error(where, "encloses no area (its corners lie on a line)");
  return out;
}

absl::Status SceneParser::ParseMaterials(const Json& materials, Scene& scene) const {
  if (!materials.is_object() || materials.empty()) {
    return Error("materials", "must be a non-empty object of name -> {mu, a1, a2, sigma}");
  }
  // nlohmann::json objects iterate in key order: material indices are sorted by name.
  for (const auto& [name, m] : materials.items()) {
    const std::string path = absl::StrCat("materials.", name);
    if (name.empty()) return Error("materials", "a material has an empty name");
    if (absl::Status s = CheckKeys(m, path, {"mu", "a1", "a2", "sigma"}, {}); !s.ok()) return s;
    Material out;
    absl::StatusOr<double> mu = Number(m, path, "mu");
    absl::StatusOr<double> a1 = Number(m, path, "a1");
    absl::StatusOr<double> a2 = Number(m, path, "a2");
    absl::StatusOr<double> sigma = Number(m, path, "sigma");
    for (const auto* s : {&mu, &a1, &a2, &sigma}) {
      if (!s->ok()) return s->status();
    }
    if (*mu < 0.0 || *mu > 5.0) return Error(path + ".mu", absl::StrCat(*mu, " is not in [0, 5]"));
    if (*sigma < 0.0) return Error(path + ".sigma", absl::StrCat(*sigma, " must be >= 0 (N)"));
    // AR(2) stationarity (both roots inside the unit circle): the simulator's
    // texture would otherwise grow without bound along the drag.
    if (!(std::abs(*a2) < 1.0 && *a1 + *a2 < 1.0 && *a2 - *a1 < 1.0)) {
      return Error(path, absl::StrCat("AR(2) roughness a1 = ", *a1, ", a2 = ", *a2,
                                      " is not stationary (need |a2| < 1, a1 + a2 < 1, a2 - a1 < 1)"));
    }
    out.mu = *mu;
    out.a1 = *a1;
    out.a2 = *a2;
    out.sigma = *sigma;
    scene.material_names.push_back(name);
    scene.materials.push_back(out);
  }
  return absl::OkStatus();
}

absl::StatusOr<SceneRegion> SceneParser::ParseRegion(const Json& region, const std::string& path,
                                                     const Scene& scene) const {
  if (!region.is_object()) return Error(path, "must be an object");
  if (!region.contains("shape")) return Error(path, "missing required key 'shape'");
  absl::StatusOr<std::string> shape = String(region, path, "shape");
  if (!shape.ok()) return shape.status();
  SceneRegion out;
  if (*shape == "box") {
    if (absl::Status s = CheckKeys(region, path, {"material", "shape", "min", "max"}, {}); !s.ok()) return s;
    auto lo = Vec3(region, path, "min");
    auto hi = Vec3(region, path, "max");
    if (!lo.ok()) return lo.status();
    if (!hi.ok()) return hi.status();
    for (int i = 0; i < 3; ++i) {
      if (!((*lo)[i] < (*hi)[i])) {
        return Error(path, absl::StrCat("box min[", i, "] = ", (*lo)[i], " must be < max[", i, "] = ", (*hi)[i]));
      }
    }
    out.shape = BoxRegion{*lo * scale_, *hi * scale_};
  } else if (*shape == "sphere") {
    if (absl::Status s = CheckKeys(region, path, {"material", "shape", "center", "radius"}, {}); !s.ok()) return s;
    auto center = Vec3(region, path, "center");
    auto radius = Number(region, path, "radius");
    if (!center.ok()) return center.status();
    if (!radius.ok()) return radius.status();
    if (!(*radius > 0.0)) return Error(path + ".radius", absl::StrCat(*radius, " must be > 0"));
    out.shape = SphereRegion{*center * scale_, *radius * scale_};
  } else if (*shape == "cylinder_patch") {
    if (absl::Status s = CheckKeys(region, path, {"material", "shape", "axis_point", "axis", "angle_deg", "height"},
                                   {"radial"});
        !s.ok()) {
      return s;
    }
    CylinderPatchRegion patch;
    auto point = Vec3(region, path, "axis_point");
    auto axis = Vec3(region, path, "axis");
    auto angle = Range(region, path, "angle_deg");
    auto height = Range(region, path, "height");
    if (!point.ok()) return point.status();
    if (!axis.ok()) return axis.status();
    if (!angle.ok()) return angle.status();
    if (!height.ok()) return height.status();
    if (axis->norm() < 1e-12) return Error(path + ".axis", "must be non-zero");
    if ((*angle)[1] - (*angle)[0] > 360.0) {
      return Error(path + ".angle_deg", absl::StrCat("spans ", (*angle)[1] - (*angle)[0], " degrees (> 360)"));
    }
    patch.axis_point = *point * scale_;
    patch.axis = axis->normalized();
    Eigen::Index least;
    patch.axis.cwiseAbs().minCoeff(&least);
    const Eigen::Vector3d world = Eigen::Vector3d::Unit(least);
    patch.reference = (world - world.dot(patch.axis) * patch.axis).normalized();
    patch.angle_from_deg = (*angle)[0];
    patch.angle_to_deg = (*angle)[1];
    patch.height_from_mm = (*height)[0] * scale_;
    patch.height_to_mm = (*height)[1] * scale_;
    if (region.contains("radial")) {
      auto radial = Range(region, path, "radial");
      if (!radial.ok()) return radial.status();
      if ((*radial)[0] < 0.0) return Error(path + ".radial", "must not be negative");
      patch.radial_min_mm = (*radial)[0] * scale_;
      patch.radial_max_mm = (*radial)[1] * scale_;
    }
    out.shape = patch;
  } else if (*shape == "oriented_box") {
    if (absl::Status s = CheckKeys(region, path, {"material", "shape", "center", "u", "v", "half_size"}, {}); !s.ok()) {
      return s;
    }
    auto frame = Frame(region, path);
    auto half = Vec3(region, path, "half_size");
    if (!frame.ok()) return frame.status();
    if (!half.ok()) return half.status();
    OrientedBoxRegion box;
    box.frame = *frame;
    for (int i = 0; i < 3; ++i) {
      if (!((*half)[i] > 0.0)) {
        return Error(absl::StrCat(path, ".half_size[", i, "]"), absl::StrCat((*half)[i], " must be > 0"));
      }
    }
    box.half_size = *half * scale_;
    out.shape = box;
  } else if (*shape == "polygon_decal") {
    if (absl::Status s = CheckKeys(region, path, {"material", "shape", "center", "u", "v", "polygon", "depth"}, {});
        !s.ok()) {
      return s;
    }
    auto frame = Frame(region, path);
    auto polygon = Polygon(region, path);
    auto depth = Range(region, path, "depth");
    if (!frame.ok()) return frame.status();
    if (!polygon.ok()) return polygon.status();
    if (!depth.ok()) return depth.status();
    PolygonDecalRegion decal;
    decal.frame = *frame;
    for (const Eigen::Vector2d& corner : *polygon) decal.polygon.push_back(corner * scale_);
    decal.depth_from_mm = (*depth)[0] * scale_;
    decal.depth_to_mm = (*depth)[1] * scale_;
    out.shape = std::move(decal);
  } else {
    return Error(path + ".shape",
                 absl::StrCat("unknown shape ", Quoted(*shape),
                              " (expected 'box', 'sphere', 'cylinder_patch', 'oriented_box' or 'polygon_decal')"));
  }
  absl::StatusOr<std::string> material = String(region, path, "material");
  if (!material.ok()) return material.status();
  out.material = scene.FindMaterial(*material);
  if (out.material < 0) {
    return Error(path + ".material", absl::StrCat("unknown material ", Quoted(*material), " (defined: ",
                                                  absl::StrJoin(scene.material_names, ", "), ")"));
  }
  return out;
}

absl::StatusOr<Scene> SceneParser::Parse(std::string_view text) {
  Json root;
  try {
    root = Json::parse(text.begin(), text.end());
  } catch (const Json::parse_error& e) {
    // nlohmann reports the byte offset; its message names line and column.
    return absl::InvalidArgumentError(absl::StrCat(source_, ": invalid JSON: ", e.what()));
  }
  if (absl::Status s = CheckKeys(root, "(top level)", {"name", "mesh", "default_material", "materials"},
                                 {"units", "regions", "seed", "description", "surface"});
      !s.ok()) {
    return s;
  }
  Scene scene;
  scene.source = source_;
  auto name = String(root, "(top level)", "name");
  if (!name.ok()) return name.status();
  if (name->empty()) return Error("name", "must not be empty");
  scene.name = *name;
  if (root.contains("description") && !root["description"].is_string()) {
    return Error("description", "must be a string");
  }
  if (root.contains("units")) {
    auto units = String(root, "(top level)", "units");
    if (!units.ok()) return units.status();
    static const std::map<std::string, double> kUnits = {{"mm", 1.0}, {"cm", 10.0}, {"m", 1000.0}};
    auto it = kUnits.find(*units);
    if (it == kUnits.end()) return Error("units", absl::StrCat("unsupported ", Quoted(*units), " (mm, cm or m)"));
    scale_ = it->second;
  }
  if (root.contains("surface")) {
    auto surface = String(root, "(top level)", "surface");
    if (!surface.ok()) return surface.status();
    if (*surface != "control_mesh" && *surface != "facets") {
      return Error("surface", absl::StrCat("unsupported ", Quoted(*surface), " (control_mesh or facets)"));
    }
    scene.facets = *surface == "facets";
  }
  if (root.contains("seed")) {
    const Json& seed = root["seed"];
    if (!seed.is_number_integer() || seed.get<std::int64_t>() < 0) {
      return Error("seed", "must be a non-negative integer");
    }
    scene.seed = seed.get<std::uint64_t>();
  }
  if (absl::Status s = ParseMaterials(root["materials"], scene); !s.ok()) return s;
  auto default_material = String(root, "(top level)", "default_material");
  if (!default_material.ok()) return default_material.status();
  scene.default_material = scene.FindMaterial(*default_material);
  if (scene.default_material < 0) {
    return Error("default_material", absl::StrCat("unknown material ", Quoted(*default_material), " (defined: ",
                                                  absl::StrJoin(scene.material_names, ", "), ")"));
  }
  if (root.contains("regions")) {
    const Json& regions = root["regions"];
    if (!regions.is_array()) return Error("regions", "must be an array");
    for (size_t i = 0; i < regions.size(); ++i) {
      auto region = ParseRegion(regions[i], absl::StrCat("regions[", i, "]"), scene);
      if (!region.ok()) return region.status();
      scene.regions.push_back(*region);
    }
  }

  auto mesh_name = String(root, "(top level)", "mesh");
  if (!mesh_name.ok()) return mesh_name.status();
  if (mesh_name->empty()) return Error("mesh", "must name a mesh file");
  const std::filesystem::path mesh_path = base_dir_ / *mesh_name;
  std::ifstream in(mesh_path, std::ios::binary);
  if (!in) {
    return absl::NotFoundError(absl::StrCat(source_, ": mesh: cannot open ", mesh_path.string()));
  }
  std::ostringstream bytes;
  bytes << in.rdbuf();
  absl::StatusOr<ControlMesh> mesh = ParseControlMeshAuto(bytes.str(), mesh_path.string());
  if (!mesh.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(source_, ": mesh: ", mesh.status().message()));
  }
  scene.mesh = *std::move(mesh);
  for (auto& p : scene.mesh.positions) p *= scale_;
  return scene;
}

bool IsValidSceneName(std::string_view name) {
  if (name.empty() || name.size() > 64) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

std::filesystem::path ExecutableDir() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe.parent_path();
}

}  // namespace

bool SceneRegion::Contains(const Eigen::Vector3d& p) const {
  return std::visit(
      [&p](const auto& s) -> bool {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, BoxRegion>) {
          return (p.array() >= s.min.array()).all() && (p.array() <= s.max.array()).all();
        } else if constexpr (std::is_same_v<T, SphereRegion>) {
          return (p - s.center).squaredNorm() <= s.radius * s.radius;
        } else if constexpr (std::is_same_v<T, PolygonDecalRegion>) {
          const Eigen::Vector3d local = s.frame.Local(p);
          if (local.z() < s.depth_from_mm || local.z() > s.depth_to_mm) return false;
          const Eigen::Vector2d q = local.head<2>();
          bool inside = false;  // even-odd: count the edges a ray along +x from q crosses
          for (std::size_t i = 0, j = s.polygon.size() - 1; i < s.polygon.size(); j = i++) {
            const Eigen::Vector2d& a = s.polygon[i];
            const Eigen::Vector2d& b = s.polygon[j];
            if ((a.y() > q.y()) != (b.y() > q.y()) &&
                q.x() < a.x() + (q.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) {
              inside = !inside;
            }
          }
          return inside;
        } else if constexpr (std::is_same_v<T, OrientedBoxRegion>) {
          return (s.frame.Local(p).cwiseAbs().array() <= s.half_size.array()).all();
        } else {
          const Eigen::Vector3d d = p - s.axis_point;
          const double h = d.dot(s.axis);
          if (h < s.height_from_mm || h > s.height_to_mm) return false;
          const Eigen::Vector3d radial = d - h * s.axis;
          const double r = radial.norm();
          if (r < s.radial_min_mm || r > s.radial_max_mm) return false;
          if (r == 0.0) return false;  // on the axis: no angle
          const double angle =
              std::atan2(s.axis.cross(s.reference).dot(radial), s.reference.dot(radial)) * 180.0 / std::numbers::pi;
          // Bring the angle into [from, from + 360).
          const double a = s.angle_from_deg + std::fmod(std::fmod(angle - s.angle_from_deg, 360.0) + 360.0, 360.0);
          return a <= s.angle_to_deg;
        }
      },
      shape);
}

int Scene::MaterialIndexAt(const Eigen::Vector3d& point) const {
  for (const auto& region : regions) {
    if (region.Contains(point)) return region.material;
  }
  return default_material;
}

int Scene::FindMaterial(std::string_view name) const {
  for (size_t i = 0; i < material_names.size(); ++i) {
    if (material_names[i] == name) return static_cast<int>(i);
  }
  return -1;
}

absl::StatusOr<Scene> ParseScene(std::string_view json_text, std::string_view source,
                                 const std::filesystem::path& base_dir) {
  return SceneParser(source, base_dir).Parse(json_text);
}

absl::StatusOr<Scene> LoadSceneFiles(const std::filesystem::path& json_path) {
  std::ifstream in(json_path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat("scene file ", json_path.string(), " cannot be opened"));
  std::ostringstream text;
  text << in.rdbuf();
  return ParseScene(text.str(), json_path.string(), json_path.parent_path());
}

absl::StatusOr<Scene> LoadScene(const std::filesystem::path& dir, std::string_view name) {
  if (!IsValidSceneName(name)) {
    return absl::InvalidArgumentError(
        absl::StrCat("scene name '", std::string(name), "' must be 1-64 characters of [A-Za-z0-9_-]"));
  }
  return LoadSceneFiles(dir / absl::StrCat(std::string(name), ".json"));
}

std::vector<std::filesystem::path> SceneSearchPath() {
  std::vector<std::filesystem::path> dirs;
  if (const char* env = std::getenv("SURFMAP_SCENES"); env != nullptr) {
    for (absl::string_view part : absl::StrSplit(env, ':', absl::SkipEmpty())) dirs.emplace_back(std::string(part));
  }
  if (const std::filesystem::path exe_dir = ExecutableDir(); !exe_dir.empty()) {
    dirs.push_back((exe_dir / ".." / "share" / "surfmap" / "scenes").lexically_normal());
  }
  if (std::string_view source_dir = SURFMAP_SOURCE_SCENES_DIR; !source_dir.empty()) {
    dirs.emplace_back(std::string(source_dir));
  }
  return dirs;
}

absl::StatusOr<Scene> LoadSceneByName(std::string_view name) {
  if (!IsValidSceneName(name)) {
    return absl::InvalidArgumentError(
        absl::StrCat("scene name '", std::string(name), "' must be 1-64 characters of [A-Za-z0-9_-]"));
  }
  std::vector<std::string> searched;
  for (const auto& dir : SceneSearchPath()) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(dir / absl::StrCat(std::string(name), ".json"), ec)) {
      return LoadScene(dir, name);
    }
    searched.push_back(dir.string());
  }
  return absl::NotFoundError(absl::StrCat("scene '", std::string(name), "' not found; searched: ",
                                          searched.empty() ? "(no directories)" : absl::StrJoin(searched, ", ")));
}

MaterialField SceneMaterialField(const Scene& scene) {
  return [scene = std::make_shared<const Scene>(scene)](const Eigen::Vector3d& p) { return scene->MaterialAt(p); };
}

}  // namespace surfmap
