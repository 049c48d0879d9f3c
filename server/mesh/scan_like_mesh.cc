#include "server/mesh/scan_like_mesh.h"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <random>

#include <Eigen/Geometry>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/mesh/primitive_meshes.h"

namespace surfmap {
namespace {

void AppendNumber(std::string& out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, result.ptr);
}

void AppendU32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

void AppendF32(std::string& out, double v) { AppendU32(out, std::bit_cast<std::uint32_t>(static_cast<float>(v))); }

Eigen::Vector3d FacetNormal(const ControlMesh& mesh, const std::array<int, 3>& t) {
  const Eigen::Vector3d& a = mesh.positions[t[0]];
  return (mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a).normalized();
}

}  // namespace

absl::StatusOr<ControlMesh> MakeScanLikeMesh(const ScanLikeOptions& options) {
  absl::StatusOr<ControlMesh> sphere = MakeIcosphere(1.0, options.subdivisions);
  if (!sphere.ok()) return sphere.status();
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> noise(0.0, options.noise_mm);
  for (Eigen::Vector3d& p : sphere->positions) {
    const Eigen::Vector3d u = p.normalized();
    // Bumps: a few smooth waves over the direction, so the surface is not a
    // quadric a simplifier could represent exactly.
    const double bump = options.bump_mm * (std::sin(3.0 * u.x() + 1.0) * std::cos(2.0 * u.y()) +
                                           0.5 * std::sin(4.0 * u.z() + 2.0 * u.x()));
    const Eigen::Vector3d on_ellipsoid = u.cwiseProduct(options.radii);
    p = on_ellipsoid + u * (bump + noise(rng));
  }
  return sphere;
}

std::string WriteObjScaled(const ControlMesh& mesh, double mm_per_unit, int stray_vertices) {
  std::string out = absl::StrFormat("# scan-like test mesh, %d vertices + %d stray, units: %g mm per unit\n",
                                    mesh.positions.size(), stray_vertices, mm_per_unit);
  for (const Eigen::Vector3d& p : mesh.positions) {
    out += 'v';
    for (int i = 0; i < 3; ++i) {
      out += ' ';
      AppendNumber(out, p[i] / mm_per_unit);
    }
    out += '\n';
  }
  for (int s = 0; s < stray_vertices; ++s) {
    // Off the surface, inside the bounding box, as a scanner's floaters are.
    absl::StrAppendFormat(&out, "v %g %g %g\n", 0.001 * s / mm_per_unit, 0.5 / mm_per_unit, -0.25 / mm_per_unit);
  }
  for (const auto& t : mesh.triangles) absl::StrAppendFormat(&out, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
  return out;
}

std::string WriteStlBinary(const ControlMesh& mesh, double mm_per_unit) {
  std::string out(80, ' ');
  std::memcpy(out.data(), "surfmap scan-like test mesh", 27);
  AppendU32(out, static_cast<std::uint32_t>(mesh.triangles.size()));
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d n = FacetNormal(mesh, t);
    for (int i = 0; i < 3; ++i) AppendF32(out, n[i]);
    for (const int v : t)
      for (int i = 0; i < 3; ++i) AppendF32(out, mesh.positions[v][i] / mm_per_unit);
    out.push_back(0);
    out.push_back(0);
  }
  return out;
}

std::string WriteStlAscii(const ControlMesh& mesh, double mm_per_unit) {
  std::string out = "solid scan\n";
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d n = FacetNormal(mesh, t);
    absl::StrAppendFormat(&out, "  facet normal %.6e %.6e %.6e\n    outer loop\n", n.x(), n.y(), n.z());
    for (const int v : t) {
      out += "      vertex";
      for (int i = 0; i < 3; ++i) {
        out += ' ';
        AppendNumber(out, mesh.positions[v][i] / mm_per_unit);
      }
      out += '\n';
    }
    out += "    endloop\n  endfacet\n";
  }
  out += "endsolid scan\n";
  return out;
}

}  // namespace surfmap
