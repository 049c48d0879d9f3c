#include "server/mesh/flat_coarsen.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

namespace surfmap {
namespace {

using Triangle = std::array<int, 3>;

bool SameDirection(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  static const double kSin = std::sin(kFlatAngleTolerance);
  return a.dot(b) > 0 && a.cross(b).squaredNorm() <= kSin * kSin;
}

// area / (longest edge)^2: 0 for a degenerate triangle, 0.43 equilateral.
double Shape(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double longest = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return longest > 0 ? 0.5 * (b - a).cross(c - a).norm() / longest : 0.0;
}

bool Contains(const Triangle& t, int v) { return t[0] == v || t[1] == v || t[2] == v; }

// The mesh under collapses and flips: triangles die, vertices are replaced;
// every vertex keeps the list of its live triangles.
class Coarsener {
 public:
  explicit Coarsener(const ControlMesh& mesh)
      : positions_(mesh.positions), triangles_(mesh.triangles), alive_(mesh.triangles.size(), true),
        fans_(mesh.positions.size()) {
    for (int t = 0; t < static_cast<int>(triangles_.size()); ++t) {
      for (int v : triangles_[t]) fans_[v].push_back(t);
    }
  }

  void Run() {
    // Flips make thin fans round again, which lets blocked collapses go on;
    // both only ever remove vertices or improve angles, so this ends.
    while (CollapsePass() + FlipPass() > 0) {
    }
  }

  ControlMesh Result() const {
    ControlMesh out;
    std::vector<int> remap(positions_.size(), -1);
    for (int v = 0; v < static_cast<int>(positions_.size()); ++v) {
      if (fans_[v].empty()) continue;
      remap[v] = static_cast<int>(out.positions.size());
      out.positions.push_back(positions_[v]);
    }
    for (int t = 0; t < static_cast<int>(triangles_.size()); ++t) {
      if (!alive_[t]) continue;
      const Triangle& tri = triangles_[t];
      out.triangles.push_back({remap[tri[0]], remap[tri[1]], remap[tri[2]]});
    }
    return out;
  }

 private:
  Eigen::Vector3d Normal(int t) const {
    const Triangle& tri = triangles_[t];
    return (positions_[tri[1]] - positions_[tri[0]]).cross(positions_[tri[2]] - positions_[tri[0]]).normalized();
  }

  std::vector<int> EdgeTriangles(int v, int x) const {
    std::vector<int> out;
    for (int t : fans_[v]) {
      if (Contains(triangles_[t], x)) out.push_back(t);
    }
    return out;
  }

  std::vector<int> Neighbours(int v) const {
    std::vector<int> out;
    for (int t : fans_[v]) {
      for (int x : triangles_[t]) {
        if (x != v) out.push_back(x);
      }
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  bool IsBorderEdge(int v, int x) const { return EdgeTriangles(v, x).size() == 1; }

  bool IsBorderVertex(int v) const {
    for (int x : Neighbours(v)) {
      if (IsBorderEdge(v, x)) return true;
    }
    return false;
  }

  struct Star {
    std::vector<int> neighbours;  // sorted
    bool border = false;          // v has an edge with one triangle
    std::vector<int> candidates;  // the neighbours v may move onto with the surface kept
  };

  // The neighbours `v` may move onto with the surface kept (see the header).
  Star StarOf(int v) const {
    Star star;
    star.neighbours = Neighbours(v);
    star.candidates = Candidates(v, star.neighbours, star.border);
    return star;
  }

  std::vector<int> Candidates(int v, const std::vector<int>& neighbours, bool& border) const {
    std::vector<int> sharp;
    for (int x : neighbours) {
      const std::vector<int> on_edge = EdgeTriangles(v, x);
      border = border || on_edge.size() == 1;
      if (on_edge.size() != 2 || !SameDirection(Normal(on_edge[0]), Normal(on_edge[1]))) sharp.push_back(x);
    }
    // Every triangle at v in one plane, or in two (one each side of a
    // straight sharp edge).
    const Eigen::Vector3d first = Normal(fans_[v].front());
    std::optional<Eigen::Vector3d> second;
    for (int t : fans_[v]) {
      const Eigen::Vector3d n = Normal(t);
      if (SameDirection(n, first)) continue;
      if (!second) second = n;
      if (!SameDirection(n, *second)) return {};
    }
    if (sharp.empty()) return second ? std::vector<int>{} : neighbours;
    if (sharp.size() != 2) return {};
    const int u = sharp[0];
    const int w = sharp[1];
    const Eigen::Vector3d in = positions_[v] - positions_[u];
    const Eigen::Vector3d out = positions_[w] - positions_[v];
    if (!SameDirection(in.normalized(), out.normalized())) return {};
    return {u, w};
  }

  // The thinnest shape the triangles of `v` would have with `v` moved onto
  // `w`, or nothing when the move would change the mesh's topology, flip a
  // triangle or leave one thinner than kMinCollapsedShape.
  std::optional<double> CollapseShape(int v, const Star& star, int w) const {
    const std::vector<int> on_edge = EdgeTriangles(v, w);
    if (on_edge.empty()) return std::nullopt;
    // Link condition: v and w share no neighbour but the corners opposite
    // their edge, else the collapse pinches the surface.
    std::vector<int> opposite;
    for (int t : on_edge) {
      for (int x : triangles_[t]) {
        if (x != v && x != w) opposite.push_back(x);
      }
    }
    std::sort(opposite.begin(), opposite.end());
    std::vector<int> shared;
    const std::vector<int>& nv = star.neighbours;
    const std::vector<int> nw = Neighbours(w);
    std::set_intersection(nv.begin(), nv.end(), nw.begin(), nw.end(), std::back_inserter(shared));
    if (shared != opposite) return std::nullopt;
    // Two border vertices joined across the inside would pinch an open mesh.
    if (on_edge.size() == 2 && star.border && IsBorderVertex(w)) return std::nullopt;
    // A closed mesh is not collapsed below a tetrahedron.
    if (on_edge.size() == 2 && nv.size() == 3 && nw.size() == 3) return std::nullopt;
    double thinnest = 1.0;
    for (int t : fans_[v]) {
      if (Contains(triangles_[t], w)) continue;
      Triangle moved = triangles_[t];
      for (int& x : moved) x = x == v ? w : x;
      const Eigen::Vector3d& a = positions_[moved[0]];
      const Eigen::Vector3d& b = positions_[moved[1]];
      const Eigen::Vector3d& c = positions_[moved[2]];
      if ((b - a).cross(c - a).dot(Normal(t)) <= 0) return std::nullopt;
      thinnest = std::min(thinnest, Shape(a, b, c));
    }
    if (thinnest < kMinCollapsedShape) return std::nullopt;
    return thinnest;
  }

  void Collapse(int v, int w) {
    for (int t : EdgeTriangles(v, w)) {
      alive_[t] = false;
      for (int x : triangles_[t]) {
        std::vector<int>& fan = fans_[x];
        fan.erase(std::find(fan.begin(), fan.end(), t));
      }
    }
    for (int t : fans_[v]) {
      for (int& x : triangles_[t]) x = x == v ? w : x;
      fans_[w].push_back(t);
    }
    fans_[v].clear();
  }

  int CollapsePass() {
    int collapses = 0;
    for (int v = 0; v < static_cast<int>(positions_.size()); ++v) {
      if (fans_[v].empty()) continue;
      int best = -1;
      double best_shape = 0.0;
      const Star star = StarOf(v);
      for (int w : star.candidates) {
        const std::optional<double> shape = CollapseShape(v, star, w);
        if (shape && *shape > best_shape) best = w, best_shape = *shape;
      }
      if (best >= 0) {
        Collapse(v, best);
        ++collapses;
      }
    }
    return collapses;
  }

  // Lawson flips inside flat regions: an edge whose two triangles are
  // coplanar is flipped when its opposite angles sum to more than pi (the
  // other diagonal of the quad is the Delaunay one). The surface is kept.
  int FlipPass() {
    int flips = 0;
    for (int f = 0; f < static_cast<int>(triangles_.size()); ++f) {
      if (!alive_[f]) continue;
      for (int k = 0; k < 3; ++k) {
        const Triangle t = triangles_[f];
        const int a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
        const std::vector<int> on_edge = EdgeTriangles(a, b);
        if (on_edge.size() != 2) continue;
        const int g = on_edge[0] == f ? on_edge[1] : on_edge[0];
        int d = -1;
        for (int x : triangles_[g]) d = (x != a && x != b) ? x : d;
        if (d < 0 || !SameDirection(Normal(f), Normal(g)) || !EdgeTriangles(c, d).empty()) continue;
        if (Angle(c, a, b) + Angle(d, b, a) <= M_PI + 1e-9) continue;
        const Triangle first = {b, c, d};
        const Triangle second = {c, a, d};
        const Eigen::Vector3d n = Normal(f);
        if (Shape(positions_[b], positions_[c], positions_[d]) <= 0 ||
            Shape(positions_[c], positions_[a], positions_[d]) <= 0 ||
            (positions_[c] - positions_[b]).cross(positions_[d] - positions_[b]).dot(n) <= 0 ||
            (positions_[a] - positions_[c]).cross(positions_[d] - positions_[c]).dot(n) <= 0) {
          continue;
        }
        Replace(f, first);
        Replace(g, second);
        ++flips;
        break;  // f changed: its edges are looked at again next pass
      }
    }
    return flips;
  }

  // The angle at `apex` of the triangle (apex, p, q).
  double Angle(int apex, int p, int q) const {
    const Eigen::Vector3d u = positions_[p] - positions_[apex];
    const Eigen::Vector3d v = positions_[q] - positions_[apex];
    return std::atan2(u.cross(v).norm(), u.dot(v));
  }

  void Replace(int t, const Triangle& next) {
    for (int x : triangles_[t]) {
      std::vector<int>& fan = fans_[x];
      fan.erase(std::find(fan.begin(), fan.end(), t));
    }
    triangles_[t] = next;
    for (int x : next) fans_[x].push_back(t);
  }

  std::vector<Eigen::Vector3d> positions_;
  std::vector<Triangle> triangles_;
  std::vector<bool> alive_;
  std::vector<std::vector<int>> fans_;
};

}  // namespace

ControlMesh CoarsenFlat(const ControlMesh& mesh) {
  Coarsener coarsener(mesh);
  coarsener.Run();
  return coarsener.Result();
}

}  // namespace surfmap
