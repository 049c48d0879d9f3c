#include "server/plan/line_sample_json.h"

#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

using nlohmann::json;

absl::Status Bad(const std::string& where, const std::string& what) {
  return absl::InvalidArgumentError(absl::StrCat(where, ": ", what));
}

absl::StatusOr<double> Number(const json& j, const std::string& where, const char* key) {
  auto it = j.find(key);
  if (it == j.end() || !it->is_number()) return Bad(where, absl::StrCat("\"", key, "\" is missing or not a number"));
  return it->get<double>();
}

absl::StatusOr<bool> Flag(const json& j, const std::string& where, const char* key) {
  auto it = j.find(key);
  if (it == j.end() || !it->is_boolean()) return Bad(where, absl::StrCat("\"", key, "\" is missing or not true/false"));
  return it->get<bool>();
}

absl::StatusOr<std::vector<double>> Numbers(const json& j, const std::string& where, const char* key) {
  auto it = j.find(key);
  if (it == j.end() || !it->is_array()) return Bad(where, absl::StrCat("\"", key, "\" is missing or not an array"));
  std::vector<double> out;
  for (const json& x : *it) {
    if (!x.is_number()) return Bad(where, absl::StrCat("\"", key, "\" holds a non-number"));
    out.push_back(x.get<double>());
  }
  return out;
}

}  // namespace

json LineSampleToJson(const LineSample& line) {
  json points = json::array();
  for (const Eigen::Vector3d& p : line.path_points) points.push_back({p.x(), p.y(), p.z()});
  json pieces = json::array();
  for (const LinePiece& p : line.pieces) {
    pieces.push_back({{"from", p.start_mm},
                      {"to", p.end_mm},
                      {"cs", p.starts_at_change},
                      {"ce", p.ends_at_change},
                      {"mu", p.texture.mu},
                      {"sd", p.texture.mu_std},
                      {"se", p.mu_se},
                      {"n", p.effective_pairs},
                      {"k", p.texture.reflection},
                      {"sigma", p.texture.sigma},
                      {"rows", p.roughness_rows}});
  }
  json out = {{"s", line.path_s_mm}, {"p", points}, {"pieces", pieces}};
  if (!line.pair_mu.empty()) {
    out["ps"] = line.pair_s_mm;
    out["pmu"] = line.pair_mu;
  }
  return out;
}

absl::StatusOr<LineSample> LineSampleFromJson(const json& j, const std::string& where) {
  if (!j.is_object()) return Bad(where, "must be an object");
  LineSample line;
  absl::StatusOr<std::vector<double>> s = Numbers(j, where, "s");
  if (!s.ok()) return s.status();
  line.path_s_mm = *std::move(s);
  auto points = j.find("p");
  if (points == j.end() || !points->is_array()) return Bad(where, "\"p\" is missing or not an array");
  for (std::size_t i = 0; i < points->size(); ++i) {
    const json& p = (*points)[i];
    if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number()) {
      return Bad(where, absl::StrCat("p[", i, "] must be 3 numbers"));
    }
    line.path_points.emplace_back(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
  }
  auto pieces = j.find("pieces");
  if (pieces == j.end() || !pieces->is_array()) return Bad(where, "\"pieces\" is missing or not an array");
  for (std::size_t i = 0; i < pieces->size(); ++i) {
    const json& jp = (*pieces)[i];
    const std::string at = absl::StrCat(where, ".pieces[", i, "]");
    if (!jp.is_object()) return Bad(at, "must be an object");
    LinePiece piece;
    absl::StatusOr<double> from = Number(jp, at, "from"), to = Number(jp, at, "to"), mu = Number(jp, at, "mu"),
                           sd = Number(jp, at, "sd"), se = Number(jp, at, "se"), n = Number(jp, at, "n"),
                           sigma = Number(jp, at, "sigma");
    for (const auto* x : {&from, &to, &mu, &sd, &se, &n, &sigma}) {
      if (!x->ok()) return x->status();
    }
    absl::StatusOr<bool> cs = Flag(jp, at, "cs"), ce = Flag(jp, at, "ce");
    if (!cs.ok()) return cs.status();
    if (!ce.ok()) return ce.status();
    absl::StatusOr<std::vector<double>> k = Numbers(jp, at, "k");
    if (!k.ok()) return k.status();
    piece.start_mm = *from;
    piece.end_mm = *to;
    piece.starts_at_change = *cs;
    piece.ends_at_change = *ce;
    piece.texture.mu = *mu;
    piece.texture.mu_std = *sd;
    piece.texture.reflection = *std::move(k);
    piece.texture.sigma = *sigma;
    piece.mu_se = *se;
    piece.effective_pairs = *n;
    // Absent from plans stored before roughness took part in the map's
    // merge rule: those pieces have no roughness signature until refitted.
    if (auto rows = jp.find("rows"); rows != jp.end()) {
      if (!rows->is_number_integer() || rows->get<int64_t>() < 0 || rows->get<int64_t>() > (1 << 30)) {
        return Bad(at, "\"rows\" must be a whole number in 0..2^30");
      }
      piece.roughness_rows = static_cast<int>(rows->get<int64_t>());
    }
    line.pieces.push_back(std::move(piece));
  }
  // The pair series: absent in plans saved before it was kept (and for
  // fits without pieces).
  if (j.contains("ps") || j.contains("pmu")) {
    absl::StatusOr<std::vector<double>> ps = Numbers(j, where, "ps"), pmu = Numbers(j, where, "pmu");
    if (!ps.ok()) return ps.status();
    if (!pmu.ok()) return pmu.status();
    line.pair_s_mm = *std::move(ps);
    line.pair_mu = *std::move(pmu);
  }
  if (absl::Status v = line.Validate(); !v.ok()) return Bad(where, std::string(v.message()));
  return line;
}

}  // namespace surfmap
