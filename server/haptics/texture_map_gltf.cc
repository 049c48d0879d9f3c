#include "server/haptics/texture_map_gltf.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include <tiny_gltf.h>

#include "absl/strings/str_cat.h"
#include "server/haptics/texture_model_json.h"

namespace surfmap::haptics {
namespace {

constexpr double kMetresPerMm = 1e-3;
constexpr float kUnknown = -1.0f;

// nlohmann::json -> tinygltf::Value (for the extras).
tinygltf::Value ToValue(const nlohmann::json& j) {
  if (j.is_object()) {
    tinygltf::Value::Object o;
    for (auto it = j.begin(); it != j.end(); ++it) o[it.key()] = ToValue(it.value());
    return tinygltf::Value(std::move(o));
  }
  if (j.is_array()) {
    tinygltf::Value::Array a;
    for (const auto& e : j) a.push_back(ToValue(e));
    return tinygltf::Value(std::move(a));
  }
  if (j.is_boolean()) return tinygltf::Value(j.get<bool>());
  if (j.is_number_integer()) return tinygltf::Value(j.get<int>());
  if (j.is_number()) return tinygltf::Value(j.get<double>());
  if (j.is_string()) return tinygltf::Value(j.get<std::string>());
  return tinygltf::Value();  // null
}

nlohmann::json ToJson(const tinygltf::Value& v) {
  if (v.IsObject()) {
    nlohmann::json o = nlohmann::json::object();
    for (const auto& key : v.Keys()) o[key] = ToJson(v.Get(key));
    return o;
  }
  if (v.IsArray()) {
    nlohmann::json a = nlohmann::json::array();
    for (size_t i = 0; i < v.ArrayLen(); ++i) a.push_back(ToJson(v.Get(static_cast<int>(i))));
    return a;
  }
  if (v.IsBool()) return v.Get<bool>();
  if (v.IsInt()) return v.Get<int>();
  if (v.IsNumber()) return v.GetNumberAsDouble();
  if (v.IsString()) return v.Get<std::string>();
  return nullptr;
}

// Appends `bytes` to buffer 0 as a new buffer view (4-byte aligned) and an
// accessor over it; returns the accessor index.
int AddAccessor(tinygltf::Model& model, const void* bytes, size_t size, int count, int component, int type,
                int target) {
  tinygltf::Buffer& buffer = model.buffers[0];
  while (buffer.data.size() % 4 != 0) buffer.data.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.data.size();
  view.byteLength = size;
  view.target = target;
  const auto* p = static_cast<const unsigned char*>(bytes);
  buffer.data.insert(buffer.data.end(), p, p + size);
  model.bufferViews.push_back(view);
  tinygltf::Accessor accessor;
  accessor.bufferView = static_cast<int>(model.bufferViews.size()) - 1;
  accessor.componentType = component;
  accessor.count = count;
  accessor.type = type;
  model.accessors.push_back(accessor);
  return static_cast<int>(model.accessors.size()) - 1;
}

float KnownOr(double v) { return std::isfinite(v) ? static_cast<float>(v) : kUnknown; }

}  // namespace

absl::StatusOr<std::string> WriteTextureGltf(const TextureMap& map, bool binary) {
  if (absl::Status s = ValidateTextureMap(map); !s.ok()) return s;
  const size_t n = map.positions.size();
  if (n > std::numeric_limits<std::uint32_t>::max()) return absl::InvalidArgumentError("too many vertices for glTF");
  absl::StatusOr<nlohmann::json> regions = TextureModelToJson(map);
  if (!regions.ok()) return regions.status();

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "surfmap";
  model.buffers.emplace_back();
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  const int count = static_cast<int>(n);

  std::vector<float> xyz(3 * n);
  std::vector<double> lo(3, std::numeric_limits<double>::infinity()), hi(3, -std::numeric_limits<double>::infinity());
  for (size_t v = 0; v < n; ++v) {
    for (int a = 0; a < 3; ++a) {
      xyz[3 * v + a] = static_cast<float>(map.positions[v][a] * kMetresPerMm);
      lo[a] = std::min(lo[a], static_cast<double>(xyz[3 * v + a]));
      hi[a] = std::max(hi[a], static_cast<double>(xyz[3 * v + a]));
    }
  }
  const int position = AddAccessor(model, xyz.data(), xyz.size() * sizeof(float), count,
                                   TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER);
  model.accessors[position].minValues = lo;  // required for POSITION
  model.accessors[position].maxValues = hi;
  primitive.attributes["POSITION"] = position;
  if (!map.normals.empty()) {
    for (size_t v = 0; v < n; ++v) {
      // NORMAL must be unit length in float (the validator checks): normalise
      // after rounding; a degenerate normal becomes +z.
      Eigen::Vector3f f = map.normals[v].cast<float>();
      f = f.norm() > 0 ? Eigen::Vector3f(f.normalized()) : Eigen::Vector3f::UnitZ();
      for (int a = 0; a < 3; ++a) xyz[3 * v + a] = f[a];
    }
    primitive.attributes["NORMAL"] = AddAccessor(model, xyz.data(), xyz.size() * sizeof(float), count,
                                                 TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3,
                                                 TINYGLTF_TARGET_ARRAY_BUFFER);
  }
  std::vector<float> scalar(n);
  auto add_scalar = [&](const std::string& name, auto value_of) {
    for (size_t v = 0; v < n; ++v) scalar[v] = value_of(v);
    primitive.attributes[name] = AddAccessor(model, scalar.data(), n * sizeof(float), count,
                                             TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR,
                                             TINYGLTF_TARGET_ARRAY_BUFFER);
  };
  add_scalar("_MU", [&](size_t v) { return KnownOr(map.mu[v]); });
  add_scalar("_MU_STD", [&](size_t v) { return KnownOr(map.mu_std[v]); });
  auto rough_known = [&](size_t v) { return !map.sigma.empty() && std::isfinite(map.sigma[v]); };
  if (!map.sigma.empty()) add_scalar("_SIGMA", [&](size_t v) { return KnownOr(map.sigma[v]); });
  if (!map.a1.empty()) {
    add_scalar("_A1", [&](size_t v) { return rough_known(v) && std::isfinite(map.a1[v]) ? float(map.a1[v]) : 0.0f; });
  }
  if (!map.a2.empty()) {
    add_scalar("_A2", [&](size_t v) { return rough_known(v) && std::isfinite(map.a2[v]) ? float(map.a2[v]) : 0.0f; });
  }
  for (int j = 0; j < map.ar_order; ++j) {
    add_scalar(absl::StrCat("_K", j + 1), [&](size_t v) {
      const double k = map.ReflectionAt(static_cast<int>(v), j);
      return rough_known(v) && std::isfinite(k) ? static_cast<float>(k) : 0.0f;
    });
  }
  if (!map.region.empty()) add_scalar("_REGION", [&](size_t v) { return static_cast<float>(map.region[v]); });
  if (!map.boundary_probability.empty()) {
    add_scalar("_BOUNDARY_PROBABILITY", [&](size_t v) { return KnownOr(map.boundary_probability[v]); });
  }
  std::vector<std::uint32_t> indices;
  indices.reserve(3 * map.triangles.size());
  for (const auto& t : map.triangles) {
    for (int c : t) indices.push_back(static_cast<std::uint32_t>(c));
  }
  primitive.indices = AddAccessor(model, indices.data(), indices.size() * sizeof(std::uint32_t),
                                  static_cast<int>(indices.size()), TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                  TINYGLTF_TYPE_SCALAR, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  model.buffers[0].data.resize((model.buffers[0].data.size() + 3) / 4 * 4, 0);

  tinygltf::Mesh mesh;
  mesh.name = absl::StrCat("surfmap job ", map.job_id, " level ", map.level);
  mesh.primitives.push_back(std::move(primitive));
  nlohmann::json extras;
  extras["format"] = kTextureGltfFormat;
  extras["job_id"] = map.job_id;
  extras["level"] = map.level;
  extras["grid_step_mm"] = map.grid_step_mm;
  extras["position_units"] = "m";
  extras["map_units"] = (*regions)["units"];
  extras["unknown_value"] = kUnknown;
  extras["ar_order"] = map.ar_order;
  extras["texture_model"] = *std::move(regions);
  tinygltf::Value::Object wrapper;
  wrapper["surfmap"] = ToValue(extras);
  mesh.extras = tinygltf::Value(std::move(wrapper));
  model.meshes.push_back(std::move(mesh));
  tinygltf::Node node;
  node.mesh = 0;
  node.name = "surfmap_map";
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model.scenes.push_back(scene);
  model.defaultScene = 0;

  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/!binary, binary)) {
    return absl::InternalError("tinygltf could not write the model");
  }
  return out.str();
}

absl::StatusOr<TextureMap> ReadTextureGltf(std::string_view bytes, std::string_view source) {
  auto fail = [&](const std::string& what) { return absl::InvalidArgumentError(absl::StrCat(std::string(source), ": ", what)); };
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  const bool glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  const bool ok = glb ? loader.LoadBinaryFromMemory(&model, &err, &warn,
                                                    reinterpret_cast<const unsigned char*>(bytes.data()),
                                                    static_cast<unsigned int>(bytes.size()))
                      : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(),
                                                   static_cast<unsigned int>(bytes.size()), "");
  if (!ok) return fail(absl::StrCat("tinygltf: ", err));
  if (model.meshes.size() != 1 || model.meshes[0].primitives.size() != 1) return fail("expected one mesh, one primitive");
  const tinygltf::Primitive& prim = model.meshes[0].primitives[0];
  const tinygltf::Value& extras = model.meshes[0].extras;
  if (!extras.Has("surfmap")) return fail("no extras.surfmap");
  const nlohmann::json meta = ToJson(extras.Get("surfmap"));
  if (meta.value("format", "") != kTextureGltfFormat) return fail("extras.surfmap.format is not a surfmap texture glTF");

  // Reads a tightly packed accessor of `components` floats (or uint32 indices).
  auto read = [&](int index, int components, auto* out) -> absl::Status {
    using T = typename std::remove_pointer_t<decltype(out)>::value_type;
    if (index < 0 || index >= static_cast<int>(model.accessors.size())) return fail("bad accessor index");
    const tinygltf::Accessor& acc = model.accessors[index];
    const tinygltf::BufferView& view = model.bufferViews[acc.bufferView];
    const tinygltf::Buffer& buffer = model.buffers[view.buffer];
    const size_t size = acc.count * components * sizeof(T);
    const size_t offset = view.byteOffset + acc.byteOffset;
    if (offset + size > buffer.data.size()) return fail("accessor runs past its buffer");
    out->resize(acc.count * components);
    std::memcpy(out->data(), buffer.data.data() + offset, size);
    return absl::OkStatus();
  };
  auto attribute = [&](const std::string& name) { auto it = prim.attributes.find(name); return it == prim.attributes.end() ? -1 : it->second; };

  TextureMap map;
  map.job_id = meta.value("job_id", std::int64_t{0});
  map.level = meta.value("level", 0);
  map.grid_step_mm = meta.value("grid_step_mm", 0.1);
  std::vector<float> f;
  if (absl::Status s = read(attribute("POSITION"), 3, &f); !s.ok()) return s;
  const size_t n = f.size() / 3;
  map.positions.resize(n);
  for (size_t v = 0; v < n; ++v) map.positions[v] = Eigen::Vector3d(f[3 * v], f[3 * v + 1], f[3 * v + 2]) / kMetresPerMm;
  if (attribute("NORMAL") >= 0) {
    if (absl::Status s = read(attribute("NORMAL"), 3, &f); !s.ok()) return s;
    map.normals.resize(n);
    for (size_t v = 0; v < n; ++v) map.normals[v] = Eigen::Vector3d(f[3 * v], f[3 * v + 1], f[3 * v + 2]);
  }
  auto scalar = [&](const std::string& name, std::vector<double>* out, bool negative_unknown) -> absl::Status {
    if (attribute(name) < 0) return absl::OkStatus();
    if (absl::Status s = read(attribute(name), 1, &f); !s.ok()) return s;
    if (f.size() != n) return fail(absl::StrCat(name, ": ", f.size(), " values for ", n, " vertices"));
    out->resize(n);
    for (size_t v = 0; v < n; ++v) (*out)[v] = negative_unknown && f[v] < 0 ? std::nan("") : f[v];
    return absl::OkStatus();
  };
  for (auto [name, out, unknown] : {std::tuple{"_MU", &map.mu, true}, std::tuple{"_MU_STD", &map.mu_std, true},
                                    std::tuple{"_SIGMA", &map.sigma, true}, std::tuple{"_A1", &map.a1, false},
                                    std::tuple{"_A2", &map.a2, false},
                                    std::tuple{"_BOUNDARY_PROBABILITY", &map.boundary_probability, true}}) {
    if (absl::Status s = scalar(name, out, unknown); !s.ok()) return s;
  }
  map.ar_order = meta.value("ar_order", 0);
  map.reflection.assign(n * map.ar_order, 0.0);
  std::vector<double> k;
  for (int j = 0; j < map.ar_order; ++j) {
    const std::string name = absl::StrCat("_K", j + 1);
    if (attribute(name) < 0) return fail(absl::StrCat("no attribute ", name));
    if (absl::Status s = scalar(name, &k, false); !s.ok()) return s;
    for (size_t v = 0; v < n; ++v) map.reflection[v * map.ar_order + j] = k[v];
  }
  if (attribute("_REGION") >= 0) {
    std::vector<double> region;
    if (absl::Status s = scalar("_REGION", &region, false); !s.ok()) return s;
    map.region.resize(n);
    for (size_t v = 0; v < n; ++v) map.region[v] = static_cast<int>(std::lround(region[v]));
  }
  std::vector<std::uint32_t> indices;
  if (absl::Status s = read(prim.indices, 1, &indices); !s.ok()) return s;
  if (indices.size() % 3 != 0) return fail("index count is not a multiple of 3");
  map.triangles.resize(indices.size() / 3);
  for (size_t t = 0; t < map.triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) map.triangles[t][c] = static_cast<int>(indices[3 * t + c]);
  }
  if (meta.contains("texture_model")) {
    absl::StatusOr<TextureModel> model_json = TextureModelFromJson(meta["texture_model"], source);
    if (!model_json.ok()) return model_json.status();
    map.regions = std::move(model_json->regions);
  }
  if (absl::Status s = ValidateTextureMap(map); !s.ok()) return fail(std::string(s.message()));
  return map;
}

}  // namespace surfmap::haptics
