#include "clients/remote/map_json.h"

#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "clients/remote/proto_json.h"
#include "absl/strings/str_cat.h"

namespace surfmap::cli {
namespace {

namespace pb = ::surfmap::v1;
using nlohmann::json;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

json Number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json Vec(const pb::Vec3& v) { return json::array({Number(v.x()), Number(v.y()), Number(v.z())}); }

template <typename Repeated>
json Numbers(const Repeated& values) {
  json out = json::array();
  for (double v : values) out.push_back(Number(v));
  return out;
}

// A message as JSON (proto_json.h: snake_case names, zeros kept, ids as numbers).
json MessageJson(const google::protobuf::Message& message) { return ProtoToJson(message); }

json Summary(const pb::MapLevel& map) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, sum = 0.0, unc_sum = 0.0;
  int known = 0, unc_known = 0;
  for (double mu : map.mu()) {
    if (!std::isfinite(mu)) continue;
    lo = std::min(lo, mu);
    hi = std::max(hi, mu);
    sum += mu;
    ++known;
  }
  for (double u : map.mu_uncertainty()) {
    if (!std::isfinite(u)) continue;
    unc_sum += u;
    ++unc_known;
  }
  std::map<int, int> per_level;
  double sample_lo = std::numeric_limits<double>::infinity(), sample_hi = -sample_lo;
  for (const pb::Sample& s : map.samples()) {
    ++per_level[s.site().level()];
    sample_lo = std::min(sample_lo, s.fit().friction().mu());
    sample_hi = std::max(sample_hi, s.fit().friction().mu());
  }
  json levels = json::object();
  for (const auto& [level, n] : per_level) levels[std::to_string(level)] = n;
  json summary = {{"samples", map.samples_size()},
                  {"samples_per_level", levels},
                  {"vertices_with_mu", known},
                  {"mu_min", known ? Number(lo) : json(nullptr)},
                  {"mu_max", known ? Number(hi) : json(nullptr)},
                  {"mu_mean", known ? Number(sum / known) : json(nullptr)},
                  {"mu_uncertainty_mean", unc_known ? Number(unc_sum / unc_known) : json(nullptr)},
                  {"sample_mu_min", map.samples_size() ? Number(sample_lo) : json(nullptr)},
                  {"sample_mu_max", map.samples_size() ? Number(sample_hi) : json(nullptr)}};
  return summary;
}

// (absl::string_view is not std::string_view in this abseil build: concatenate std::strings.)
absl::Status Invalid(std::string_view source, std::string_view path, std::string_view problem) {
  return absl::InvalidArgumentError(std::string(source) + ": " + std::string(path) + ": " + std::string(problem));
}

absl::StatusOr<std::vector<double>> ReadNumbers(const json& parent, const char* key, std::string_view path,
                                                std::string_view source, bool required) {
  std::vector<double> out;
  auto it = parent.find(key);
  if (it == parent.end()) {
    if (required) return Invalid(source, path, "missing");
    return out;
  }
  if (!it->is_array()) return Invalid(source, path, "must be an array");
  out.reserve(it->size());
  for (size_t i = 0; i < it->size(); ++i) {
    const json& v = (*it)[i];
    if (v.is_null()) {
      out.push_back(kNaN);
    } else if (v.is_number()) {
      out.push_back(v.get<double>());
    } else {
      return Invalid(source, std::string(path) + "[" + std::to_string(i) + "]", "must be a number or null");
    }
  }
  return out;
}

absl::StatusOr<std::array<double, 3>> ReadTriple(const json& v, std::string_view path, std::string_view source) {
  if (!v.is_array() || v.size() != 3) return Invalid(source, path, "must be an array of 3 numbers");
  std::array<double, 3> out{};
  for (int k = 0; k < 3; ++k) {
    if (v[k].is_null()) {
      out[k] = kNaN;
    } else if (v[k].is_number()) {
      out[k] = v[k].get<double>();
    } else {
      return Invalid(source, path, "must be an array of 3 numbers");
    }
  }
  return out;
}

}  // namespace

json MapToJson(const pb::GetMapResponse& response, const pb::JobInfo* job) {
  const pb::MapLevel& map = response.map();
  json vertices = {{"mu", Numbers(map.mu())},
                   {"mu_uncertainty", Numbers(map.mu_uncertainty())},
                   {"sigma", Numbers(map.sigma())},
                   {"a1", Numbers(map.a1())},
                   {"a2", Numbers(map.a2())}};
  json out = {{"format", kMapJsonFormat},
              {"job_id", map.job_id()},
              {"level", map.level()},
              {"vertex_count", map.vertex_count()}};
  if (response.has_mesh()) {
    json positions = json::array(), normals = json::array(), triangles = json::array();
    for (const pb::Vec3& p : response.mesh().positions()) positions.push_back(Vec(p));
    for (const pb::Vec3& n : response.mesh().normals()) normals.push_back(Vec(n));
    const auto& idx = response.mesh().triangle_indices();
    for (int i = 0; i + 2 < idx.size(); i += 3) triangles.push_back(json::array({idx[i], idx[i + 1], idx[i + 2]}));
    vertices["position"] = std::move(positions);
    vertices["normal"] = std::move(normals);
    out["triangles"] = std::move(triangles);
  }
  out["vertices"] = std::move(vertices);
  json samples = json::array();
  for (const pb::Sample& s : map.samples()) {
    samples.push_back({{"trace_id", s.trace_id()},
                       {"command_id", s.command_id()},
                       {"site", {{"level", s.site().level()}, {"vertex", s.site().vertex()}}},
                       {"position", Vec(s.position())},
                       {"drag_direction", Vec(s.drag_direction())},
                       {"segment_length_mm", Number(s.segment_length_mm())},
                       {"mu", Number(s.fit().friction().mu())},
                       {"mu_std", Number(s.fit().friction().mu_std())},
                       {"fit", MessageJson(s.fit())}});
  }
  out["samples"] = std::move(samples);
  // The material regions, each with the drag pieces behind its estimates
  // (MapRegion.pieces), and each vertex's region (-1: no data reachable).
  json regions = json::array();
  for (const pb::MapRegion& r : map.regions()) regions.push_back(MessageJson(r));
  out["regions"] = std::move(regions);
  json region_of_vertex = json::array();
  for (int r : map.region()) region_of_vertex.push_back(r);
  out["vertices"]["region"] = std::move(region_of_vertex);
  out["summary"] = Summary(map);
  if (job != nullptr) out["job"] = MessageJson(*job);
  return out;
}

absl::StatusOr<MapDocument> MapDocumentFromJson(const json& j, std::string_view source) {
  if (!j.is_object()) return Invalid(source, "$", "must be a JSON object");
  if (!j.contains("format") || j["format"] != kMapJsonFormat) {
    return Invalid(source, "format", "must be \"" + std::string(kMapJsonFormat) + "\" (not a surfmap map file?)");
  }
  MapDocument doc;
  if (!j.contains("vertex_count") || !j["vertex_count"].is_number_integer()) {
    return Invalid(source, "vertex_count", "missing or not an integer");
  }
  const size_t n = j["vertex_count"].get<size_t>();
  if (j.contains("job_id") && j["job_id"].is_number_integer()) doc.job_id = j["job_id"].get<std::int64_t>();
  if (j.contains("level") && j["level"].is_number_integer()) doc.level = j["level"].get<int>();
  if (!j.contains("vertices") || !j["vertices"].is_object()) return Invalid(source, "vertices", "missing");
  const json& v = j["vertices"];
  absl::StatusOr<std::vector<double>> mu = ReadNumbers(v, "mu", "vertices.mu", source, true);
  if (!mu.ok()) return mu.status();
  if (mu->size() != n) {
    return Invalid(source, "vertices.mu", absl::StrCat("has ", mu->size(), " values, vertex_count is ", n));
  }
  doc.mu = *std::move(mu);
  absl::StatusOr<std::vector<double>> unc =
      ReadNumbers(v, "mu_uncertainty", "vertices.mu_uncertainty", source, false);
  if (!unc.ok()) return unc.status();
  if (!unc->empty() && unc->size() != n) {
    return Invalid(source, "vertices.mu_uncertainty", absl::StrCat("has ", unc->size(), " values, vertex_count is ", n));
  }
  doc.mu_uncertainty = *std::move(unc);
  for (auto [key, out] : {std::pair<const char*, std::vector<double>*>{"a1", &doc.a1}, {"a2", &doc.a2},
                          {"sigma", &doc.sigma}}) {
    absl::StatusOr<std::vector<double>> values = ReadNumbers(v, key, absl::StrCat("vertices.", key), source, false);
    if (!values.ok()) return values.status();
    if (!values->empty() && values->size() != n) {
      return Invalid(source, absl::StrCat("vertices.", key),
                     absl::StrCat("has ", values->size(), " values, vertex_count is ", n));
    }
    *out = *std::move(values);
  }
  if (v.contains("position")) {
    const json& pos = v["position"];
    if (!pos.is_array() || pos.size() != n) {
      return Invalid(source, "vertices.position", absl::StrCat("must be an array of vertex_count (", n, ") points"));
    }
    for (size_t i = 0; i < n; ++i) {
      absl::StatusOr<std::array<double, 3>> p = ReadTriple(pos[i], absl::StrCat("vertices.position[", i, "]"), source);
      if (!p.ok()) return p.status();
      doc.positions.push_back(*p);
    }
  }
  if (j.contains("triangles")) {
    const json& tris = j["triangles"];
    if (!tris.is_array()) return Invalid(source, "triangles", "must be an array");
    for (size_t i = 0; i < tris.size(); ++i) {
      const json& t = tris[i];
      if (!t.is_array() || t.size() != 3 || !t[0].is_number_integer() || !t[1].is_number_integer() ||
          !t[2].is_number_integer()) {
        return Invalid(source, absl::StrCat("triangles[", i, "]"), "must be 3 integers");
      }
      doc.triangles.push_back({t[0].get<int>(), t[1].get<int>(), t[2].get<int>()});
    }
  }
  if (j.contains("samples")) {
    const json& samples = j["samples"];
    if (!samples.is_array()) return Invalid(source, "samples", "must be an array");
    for (size_t i = 0; i < samples.size(); ++i) {
      const json& s = samples[i];
      const std::string path = absl::StrCat("samples[", i, "]");
      if (!s.is_object()) return Invalid(source, path, "must be an object");
      MapSampleRecord r;
      if (s.contains("trace_id") && s["trace_id"].is_number_integer()) r.trace_id = s["trace_id"].get<std::int64_t>();
      if (s.contains("site") && s["site"].is_object()) {
        r.site_level = s["site"].value("level", 0);
        r.site_vertex = s["site"].value("vertex", 0);
      }
      if (!s.contains("position")) return Invalid(source, path + ".position", "missing");
      absl::StatusOr<std::array<double, 3>> p = ReadTriple(s["position"], path + ".position", source);
      if (!p.ok()) return p.status();
      r.position = *p;
      if (s.contains("drag_direction")) {
        absl::StatusOr<std::array<double, 3>> d = ReadTriple(s["drag_direction"], path + ".drag_direction", source);
        if (!d.ok()) return d.status();
        r.drag_direction = *d;
      }
      auto number = [&](const char* key) {
        return s.contains(key) && s[key].is_number() ? s[key].get<double>() : kNaN;
      };
      r.segment_length_mm = number("segment_length_mm");
      r.mu = number("mu");
      r.mu_std = number("mu_std");
      doc.samples.push_back(r);
    }
  }
  return doc;
}

}  // namespace surfmap::cli
