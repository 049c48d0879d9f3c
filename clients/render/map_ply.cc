#include "clients/render/map_ply.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

// %.9g round-trips a float; "nan" for unknown values (strtod/scanf read it).
void AppendFloat(std::string& out, double v) {
  if (std::isnan(v)) {
    out += "nan";
    return;
  }
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.9g", static_cast<double>(static_cast<float>(v)));
  out += buf;
}

}  // namespace

absl::StatusOr<std::string> WriteMapPly(const MapMesh& mesh, const MapPlyOptions& options) {
  if (absl::Status s = ValidateMapMesh(mesh); !s.ok()) return s;
  const auto [data_lo, data_hi] = FiniteValueRange(mesh.values);
  const double lo = options.value_min.value_or(data_lo);
  const double hi = options.value_max.value_or(data_hi);
  if ((options.value_min && !std::isfinite(*options.value_min)) ||
      (options.value_max && !std::isfinite(*options.value_max))) {
    return absl::InvalidArgumentError("PLY colour range bounds must be finite");
  }
  if (options.value_min && options.value_max && lo > hi) {
    return absl::InvalidArgumentError(absl::StrCat("PLY colour range value_min ", lo, " > value_max ", hi));
  }
  const std::vector<Eigen::Vector3d> normals = mesh.normals.empty() ? ComputeVertexNormals(mesh) : mesh.normals;

  std::string out;
  out.reserve(mesh.positions.size() * 96 + mesh.triangles.size() * 24 + 512);
  out += "ply\nformat ascii 1.0\n";
  out += "comment surfmap friction map; mu = coefficient of friction, mu_std its standard deviation; mm\n";
  if (!options.comment.empty()) {
    std::string c = options.comment;
    std::replace(c.begin(), c.end(), '\n', ' ');
    std::replace(c.begin(), c.end(), '\r', ' ');
    absl::StrAppend(&out, "comment ", c, "\n");
  }
  absl::StrAppend(&out, "element vertex ", mesh.positions.size(), "\n");
  out +=
      "property float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\n"
      "property float mu\nproperty float mu_std\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  absl::StrAppend(&out, "element face ", mesh.triangles.size(), "\n");
  out += "property list uchar int vertex_indices\nend_header\n";

  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Eigen::Vector3d& p = mesh.positions[i];
    const Eigen::Vector3d& n = normals[i];
    const double value = mesh.values[i];
    const double uncertainty = mesh.uncertainties.empty() ? 0.0 : mesh.uncertainties[i];
    const Rgb c = std::isnan(value) ? options.no_data_color
                                    : MapColor(options.color_map, NormalizeToRange(value, lo, hi));
    for (double v : {p.x(), p.y(), p.z(), n.x(), n.y(), n.z(), value, uncertainty}) {
      AppendFloat(out, v);
      out += ' ';
    }
    absl::StrAppend(&out, c[0], " ", c[1], " ", c[2], "\n");
  }
  for (const auto& t : mesh.triangles) absl::StrAppend(&out, "3 ", t[0], " ", t[1], " ", t[2], "\n");
  return out;
}

}  // namespace surfmap
