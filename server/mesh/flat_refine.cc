#include "server/mesh/flat_refine.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <queue>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

using Edge = std::pair<int, int>;  // lower index first

Edge EdgeOf(int a, int b) { return a < b ? Edge{a, b} : Edge{b, a}; }

// Triangles with the edges each lies on, kept in step as edges are split.
class SplittableMesh {
 public:
  explicit SplittableMesh(const ControlMesh& mesh) : positions_(mesh.positions) {
    for (const auto& t : mesh.triangles) Add(t);
  }

  double Length(const Edge& e) const { return (positions_[e.first] - positions_[e.second]).norm(); }
  bool Exists(const Edge& e) const { return faces_of_.count(e) > 0; }
  int vertices() const { return static_cast<int>(positions_.size()); }
  const std::map<Edge, std::vector<int>>& edges() const { return faces_of_; }

  // Splits `e` at its midpoint; returns the new vertex m, and in `thirds`
  // the third vertex c of each triangle that was on it. Each, (a, b, c) in
  // its own winding with a -> b along e, becomes (a, m, c) and (m, b, c).
  int Split(const Edge& e, std::vector<int>& thirds) {
    thirds.clear();
    const int m = static_cast<int>(positions_.size());
    positions_.push_back(0.5 * (positions_[e.first] + positions_[e.second]));
    const std::vector<int> faces = faces_of_.at(e);
    for (int f : faces) {
      std::array<int, 3> t = triangles_[f];
      Remove(f);
      int k = 0;
      while (EdgeOf(t[k], t[(k + 1) % 3]) != e) ++k;
      const int a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
      thirds.push_back(c);
      triangles_[f] = {a, m, c};  // reuses the slot: triangle order stays stable
      Register(f);
      Add({m, b, c});
    }
    return m;
  }

  ControlMesh Result() const {
    ControlMesh out;
    out.positions = positions_;
    out.triangles = triangles_;
    return out;
  }

 private:
  void Add(const std::array<int, 3>& t) {
    triangles_.push_back(t);
    Register(static_cast<int>(triangles_.size()) - 1);
  }
  void Register(int f) {
    const auto& t = triangles_[f];
    for (int k = 0; k < 3; ++k) faces_of_[EdgeOf(t[k], t[(k + 1) % 3])].push_back(f);
  }
  void Remove(int f) {
    const auto& t = triangles_[f];
    for (int k = 0; k < 3; ++k) {
      auto it = faces_of_.find(EdgeOf(t[k], t[(k + 1) % 3]));
      std::vector<int>& faces = it->second;
      faces.erase(std::find(faces.begin(), faces.end(), f));
      if (faces.empty()) faces_of_.erase(it);
    }
  }

  std::vector<Eigen::Vector3d> positions_;
  std::vector<std::array<int, 3>> triangles_;
  std::map<Edge, std::vector<int>> faces_of_;
};

}  // namespace

double FacetedRefineEdgeMm(double area_mm2, int max_vertices) {
  constexpr double kEdgeMm = 2.0;
  // Bisection leaves edges between a third and all of the length: measured,
  // 3.3 x area / length^2 vertices on a box at 2 mm and 3.9 at 11 mm; 4 is
  // the bound used.
  return std::max(kEdgeMm, std::sqrt(4.0 * std::max(area_mm2, 0.0) / std::max(max_vertices, 1)));
}

absl::StatusOr<ControlMesh> RefineFlat(const ControlMesh& mesh, double max_edge_mm, int max_vertices) {
  if (!(max_edge_mm > 0.0) || !std::isfinite(max_edge_mm)) {
    return absl::InvalidArgumentError(absl::StrCat("edge length to refine to must be > 0 mm, got ", max_edge_mm));
  }
  SplittableMesh work(mesh);
  // Longest first; ties by the edge, so the result does not depend on
  // anything but the mesh.
  using Item = std::tuple<double, int, int>;
  std::priority_queue<Item> longest;
  auto push = [&](const Edge& e) {
    const double length = work.Length(e);
    if (length > max_edge_mm) longest.emplace(length, -e.first, -e.second);
  };
  for (const auto& [e, faces] : work.edges()) push(e);
  std::vector<int> thirds;
  while (!longest.empty()) {
    const auto [length, a, b] = longest.top();
    longest.pop();
    const Edge e{-a, -b};
    if (!work.Exists(e)) continue;  // split already, by way of a longer one
    if (work.vertices() >= max_vertices) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "refining the facets to edges of ", max_edge_mm, " mm needs more than ", max_vertices,
          " vertices (the mesh has ", mesh.positions.size(), "); its longest edge left is ", length, " mm"));
    }
    const int m = work.Split(e, thirds);
    push(EdgeOf(e.first, m));
    push(EdgeOf(m, e.second));
    for (int c : thirds) push(EdgeOf(m, c));
  }
  return work.Result();
}

}  // namespace surfmap
