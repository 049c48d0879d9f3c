// Small meshes and maps for the haptics tests (header only, test code).
#pragma once

#include <cmath>
#include <numbers>

#include "server/haptics/texture_map.h"
#include "server/estimate/roughness.h"

namespace surfmap::haptics::testing {

// A flat plate in z = 0 over [0, size]^2 with (cells+1)^2 vertices, normals +z.
inline TextureMap FlatPlate(int cells, double size_mm) {
  TextureMap map;
  const int n = cells + 1;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      map.positions.emplace_back(size_mm * i / cells, size_mm * j / cells, 0.0);
      map.normals.emplace_back(0, 0, 1);
    }
  }
  for (int j = 0; j < cells; ++j) {
    for (int i = 0; i < cells; ++i) {
      const int a = j * n + i, b = a + 1, c = a + n, d = c + 1;
      map.triangles.push_back({a, b, d});
      map.triangles.push_back({a, d, c});
    }
  }
  const size_t nv = map.positions.size();
  map.mu.assign(nv, 0.0);
  map.mu_std.assign(nv, 0.0);
  return map;
}

// A UV sphere of radius r centred at the origin (rings x segments).
inline TextureMap Sphere(double r, int rings, int segments) {
  TextureMap map;
  map.positions.emplace_back(0, 0, r);
  for (int i = 1; i < rings; ++i) {
    const double th = std::numbers::pi * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double ph = 2 * std::numbers::pi * j / segments;
      map.positions.emplace_back(r * std::sin(th) * std::cos(ph), r * std::sin(th) * std::sin(ph), r * std::cos(th));
    }
  }
  map.positions.emplace_back(0, 0, -r);
  const int south = static_cast<int>(map.positions.size()) - 1;
  auto ring = [&](int i, int j) { return 1 + (i - 1) * segments + (j % segments); };
  for (int j = 0; j < segments; ++j) map.triangles.push_back({0, ring(1, j), ring(1, j + 1)});
  for (int i = 1; i + 1 < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      map.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      map.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
  }
  for (int j = 0; j < segments; ++j) map.triangles.push_back({south, ring(rings - 1, j + 1), ring(rings - 1, j)});
  for (const auto& p : map.positions) map.normals.push_back(p.normalized());
  map.mu.assign(map.positions.size(), 0.0);
  map.mu_std.assign(map.positions.size(), 0.0);
  return map;
}

// Gives every vertex with x < split_x material A and the rest material B
// (region 0 / 1), with AR(2) roughness.
struct TestMaterial {
  double mu, a1, a2, sigma;
};
inline void PaintSplit(TextureMap& map, double split_x, const TestMaterial& a, const TestMaterial& b) {
  const size_t n = map.positions.size();
  map.mu.resize(n);
  map.mu_std.assign(n, 0.01);
  map.sigma.resize(n);
  map.a1.resize(n);
  map.a2.resize(n);
  map.region.resize(n);
  map.boundary_probability.assign(n, 0.0);
  for (size_t v = 0; v < n; ++v) {
    const bool left = map.positions[v].x() < split_x;
    const TestMaterial& m = left ? a : b;
    map.mu[v] = m.mu;
    map.sigma[v] = m.sigma;
    map.a1[v] = m.a1;
    map.a2[v] = m.a2;
    map.region[v] = left ? 0 : 1;
  }
  FillReflectionFromAr(map);
  map.regions.clear();
  for (int i = 0; i < 2; ++i) {
    const TestMaterial& m = i == 0 ? a : b;
    TextureRegion r;
    r.region = i;
    r.mu = m.mu;
    r.mu_se = 0.002;
    r.piece_count = 3;
    r.roughness_piece_count = 2;
    r.ar_coefficients = {m.a1, m.a2};
    r.reflection = ArToReflection(r.ar_coefficients);
    r.sigma = m.sigma;
    r.area_mm2 = 100.0;
    map.regions.push_back(r);
  }
}

// Lloyd & Pai's rubber and masonite (clients/sim/dragsim/material.h).
inline constexpr TestMaterial kRubber{0.305, 0.60, 0.25, 0.11};
inline constexpr TestMaterial kMasonite{0.25, 1.61, -0.73, 0.16};

}  // namespace surfmap::haptics::testing
