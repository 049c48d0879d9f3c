#include "server/haptics/texture_map_gltf.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
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
  if (!meta.is_object()) return fail("extras.surfmap is not an object");
  if (!meta.contains("format") || !meta["format"].is_string() || meta["format"].get<std::string>() != kTextureGltfFormat) {
    return fail("extras.surfmap.format is not a surfmap texture glTF");
  }
  // The metadata's numbers, type- and range-checked (json::value would throw
  // on a string where a number belongs). Absent keys keep the default.
  auto meta_int = [&](const char* key, std::int64_t lo, std::int64_t hi, auto* out) -> absl::Status {
    if (!meta.contains(key)) return absl::OkStatus();
    const nlohmann::json& j = meta[key];
    if (!j.is_number_integer()) return fail(absl::StrCat("extras.surfmap.", key, " is not an integer"));
    // An unsigned above int64's range would wrap in get<int64_t>().
    const bool too_big = j.is_number_unsigned() && j.get<std::uint64_t>() > static_cast<std::uint64_t>(hi);
    if (too_big || j.get<std::int64_t>() < lo || j.get<std::int64_t>() > hi) {
      return fail(absl::StrCat("extras.surfmap.", key, " = ", j.dump(), " is outside ", lo, "..", hi));
    }
    const std::int64_t value = j.get<std::int64_t>();
    *out = static_cast<std::remove_pointer_t<decltype(out)>>(value);
    return absl::OkStatus();
  };

  // The bytes of accessor `index`: its element type must be `type` with a
  // component type in `components`, and every element (with the view's
  // stride) must lie inside its buffer view and buffer. The file's counts
  // are checked against the bytes present before anything is sized from them.
  struct Span {
    const unsigned char* data = nullptr;
    size_t count = 0, stride = 0;
    int component_type = 0;
  };
  auto locate = [&](int index, const std::string& name, int type, std::initializer_list<int> components,
                    Span* span) -> absl::Status {
    if (index < 0 || index >= static_cast<int>(model.accessors.size())) {
      return fail(absl::StrCat(name, ": accessor ", index, " does not exist"));
    }
    const tinygltf::Accessor& acc = model.accessors[index];
    const std::string what = absl::StrCat(name, " (accessor ", index, ")");
    if (acc.sparse.isSparse) return fail(absl::StrCat(what, ": sparse accessors are not read"));
    if (acc.type != type) return fail(absl::StrCat(what, ": type ", acc.type, ", expected ", type));
    if (std::find(components.begin(), components.end(), acc.componentType) == components.end()) {
      return fail(absl::StrCat(what, ": componentType ", acc.componentType, " is not one this reader takes"));
    }
    if (acc.bufferView < 0 || acc.bufferView >= static_cast<int>(model.bufferViews.size())) {
      return fail(absl::StrCat(what, ": bufferView ", acc.bufferView, " does not exist"));
    }
    const tinygltf::BufferView& view = model.bufferViews[acc.bufferView];
    if (view.buffer < 0 || view.buffer >= static_cast<int>(model.buffers.size())) {
      return fail(absl::StrCat(what, ": buffer ", view.buffer, " does not exist"));
    }
    const std::vector<unsigned char>& buffer = model.buffers[view.buffer].data;
    const size_t element = static_cast<size_t>(tinygltf::GetComponentSizeInBytes(acc.componentType)) *
                           static_cast<size_t>(tinygltf::GetNumComponentsInType(acc.type));
    const size_t stride = view.byteStride == 0 ? element : view.byteStride;
    // glTF strides are 4..252 bytes; a smaller one would overlap elements.
    if (stride < element || stride > 252) return fail(absl::StrCat(what, ": byteStride ", view.byteStride, " for ", element, "-byte elements"));
    if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset) {
      return fail(absl::StrCat(what, ": buffer view runs past its buffer"));
    }
    if (acc.byteOffset > view.byteLength) return fail(absl::StrCat(what, ": byteOffset past its buffer view"));
    const size_t room = view.byteLength - acc.byteOffset;
    // count <= room / stride + 1 keeps (count - 1) * stride + element <= room without overflow.
    if (acc.count > 0 && (acc.count - 1 > room / stride || (acc.count - 1) * stride + element > room)) {
      return fail(absl::StrCat(what, ": ", acc.count, " elements run past its buffer view"));
    }
    *span = Span{buffer.data() + view.byteOffset + acc.byteOffset, acc.count, stride, acc.componentType};
    return absl::OkStatus();
  };
  // A float accessor of `components` per element (SCALAR or VEC3).
  auto read = [&](int index, const std::string& name, int components, std::vector<float>* out) -> absl::Status {
    Span span;
    const int type = components == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_SCALAR;
    if (absl::Status s = locate(index, name, type, {TINYGLTF_COMPONENT_TYPE_FLOAT}, &span); !s.ok()) return s;
    out->resize(span.count * components);
    for (size_t e = 0; e < span.count; ++e) {
      std::memcpy(out->data() + e * components, span.data + e * span.stride, components * sizeof(float));
    }
    return absl::OkStatus();
  };
  // Triangle indices: unsigned 8-, 16- or 32-bit, as glTF allows.
  auto read_indices = [&](int index, std::vector<std::uint32_t>* out) -> absl::Status {
    Span span;
    if (absl::Status s = locate(index, "indices", TINYGLTF_TYPE_SCALAR,
                                {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                 TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                                &span);
        !s.ok()) {
      return s;
    }
    out->resize(span.count);
    for (size_t e = 0; e < span.count; ++e) {
      const unsigned char* p = span.data + e * span.stride;
      if (span.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) {
        (*out)[e] = *p;
      } else if (span.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
        std::uint16_t i16;
        std::memcpy(&i16, p, sizeof(i16));
        (*out)[e] = i16;
      } else {
        std::memcpy(&(*out)[e], p, sizeof(std::uint32_t));
      }
    }
    return absl::OkStatus();
  };
  auto attribute = [&](const std::string& name) { auto it = prim.attributes.find(name); return it == prim.attributes.end() ? -1 : it->second; };

  TextureMap map;
  constexpr std::int64_t kIntMax = std::numeric_limits<int>::max();
  if (absl::Status s = meta_int("job_id", std::numeric_limits<std::int64_t>::min(),
                                std::numeric_limits<std::int64_t>::max(), &map.job_id);
      !s.ok()) {
    return s;
  }
  if (absl::Status s = meta_int("level", 0, kIntMax, &map.level); !s.ok()) return s;
  map.grid_step_mm = 0.1;
  if (meta.contains("grid_step_mm")) {
    if (!meta["grid_step_mm"].is_number()) return fail("extras.surfmap.grid_step_mm is not a number");
    map.grid_step_mm = meta["grid_step_mm"].get<double>();
  }
  std::vector<float> f;
  if (absl::Status s = read(attribute("POSITION"), "POSITION", 3, &f); !s.ok()) return s;
  const size_t n = f.size() / 3;
  map.positions.resize(n);
  for (size_t v = 0; v < n; ++v) map.positions[v] = Eigen::Vector3d(f[3 * v], f[3 * v + 1], f[3 * v + 2]) / kMetresPerMm;
  if (attribute("NORMAL") >= 0) {
    if (absl::Status s = read(attribute("NORMAL"), "NORMAL", 3, &f); !s.ok()) return s;
    if (f.size() != 3 * n) return fail(absl::StrCat("NORMAL: ", f.size() / 3, " normals for ", n, " vertices"));
    map.normals.resize(n);
    for (size_t v = 0; v < n; ++v) map.normals[v] = Eigen::Vector3d(f[3 * v], f[3 * v + 1], f[3 * v + 2]);
  }
  auto scalar = [&](const std::string& name, std::vector<double>* out, bool negative_unknown) -> absl::Status {
    if (attribute(name) < 0) return absl::OkStatus();
    if (absl::Status s = read(attribute(name), name, 1, &f); !s.ok()) return s;
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
  // Same bound as ValidateTextureMap, checked here because the order sizes
  // the reflection array; every _Kj must be present before it is allocated.
  if (absl::Status s = meta_int("ar_order", 0, 20, &map.ar_order); !s.ok()) return s;
  for (int j = 0; j < map.ar_order; ++j) {
    const std::string name = absl::StrCat("_K", j + 1);
    if (attribute(name) < 0) return fail(absl::StrCat("no attribute ", name));
  }
  map.reflection.assign(n * map.ar_order, 0.0);
  std::vector<double> k;
  for (int j = 0; j < map.ar_order; ++j) {
    const std::string name = absl::StrCat("_K", j + 1);
    if (absl::Status s = scalar(name, &k, false); !s.ok()) return s;
    for (size_t v = 0; v < n; ++v) map.reflection[v * map.ar_order + j] = k[v];
  }
  if (attribute("_REGION") >= 0) {
    std::vector<double> region;
    if (absl::Status s = scalar("_REGION", &region, false); !s.ok()) return s;
    map.region.resize(n);
    for (size_t v = 0; v < n; ++v) {
      // -1 is unassigned; the range check keeps lround's result an int.
      if (!(region[v] >= -1 && region[v] < static_cast<double>(n))) {
        return fail(absl::StrCat("_REGION of vertex ", v, " = ", region[v], " is outside -1..", n - 1));
      }
      map.region[v] = static_cast<int>(std::lround(region[v]));
    }
  }
  std::vector<std::uint32_t> indices;
  if (absl::Status s = read_indices(prim.indices, &indices); !s.ok()) return s;
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
