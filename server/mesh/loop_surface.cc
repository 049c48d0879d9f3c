#include "server/mesh/loop_surface.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opensubdiv/far/error.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/sdc/crease.h>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/mesh/triangle_bvh.h"

namespace surfmap {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

namespace {

constexpr int kMaxLevel = 6;
// A path step never needs more than this many points.
constexpr double kMaxPathSteps = 1e6;
// A stepped-to point whose projection moved it sideways along an open
// boundary by more than this fraction of the step has left the surface.
constexpr double kWalkOffFraction = 0.02;
// A drag step across which the normal turns by more than 10 degrees crosses
// a sharp edge: a smooth surface turns ~1 degree per 0.25 mm step at 13 mm
// radius (the most curved scene), a CAD part's edge 45-90 degrees.
const double kSharpTurnCos = std::cos(10.0 * 3.14159265358979323846 / 180.0);

// OpenSubdiv reports errors through a process-wide callback. Each Create
// installs a capture buffer for its own thread, so concurrent Creates on
// different threads do not see each other's messages.
thread_local std::string* tls_osd_errors = nullptr;

void CaptureOsdError(Far::ErrorType type, const char* message) {
  if (tls_osd_errors == nullptr) return;
  if (!tls_osd_errors->empty()) tls_osd_errors->append("; ");
  tls_osd_errors->append(message != nullptr ? message : "(no message)");
}

// Warnings (e.g. about unusual but legal topology) are not failures; keep them
// off the server's stdout.
void IgnoreOsdWarning(const char*) {}

class OsdErrorCapture {
 public:
  OsdErrorCapture() : previous_(tls_osd_errors) {
    static std::once_flag installed;
    std::call_once(installed, [] {
      Far::SetErrorCallback(&CaptureOsdError);
      Far::SetWarningCallback(&IgnoreOsdWarning);
    });
    tls_osd_errors = &errors_;
  }
  ~OsdErrorCapture() { tls_osd_errors = previous_; }
  OsdErrorCapture(const OsdErrorCapture&) = delete;
  OsdErrorCapture& operator=(const OsdErrorCapture&) = delete;

  const std::string& errors() const { return errors_; }

 private:
  std::string errors_;
  std::string* previous_;
};

// PrimvarRefiner writes through `dst[i].Clear()` and
// `dst[i].AddWithWeight(src[j], w)`: these views let it work directly in the
// levels' Eigen arrays (no staging copies: on large meshes memory first-touch
// is a large part of Create's cost).
class Vec3Ref {
 public:
  explicit Vec3Ref(Eigen::Vector3d* p) : p_(p) {}
  void Clear(void* = nullptr) const { p_->setZero(); }
  void AddWithWeight(const Vec3Ref& src, double weight) const { *p_ += weight * *src.p_; }

 private:
  Eigen::Vector3d* p_;
};

class Vec3View {
 public:
  explicit Vec3View(Eigen::Vector3d* data) : data_(data) {}
  Vec3Ref operator[](int i) const { return Vec3Ref(data_ + i); }

 private:
  Eigen::Vector3d* data_;
};

// Unit normal of a triangle of `positions` (zero for a degenerate one).
Eigen::Vector3d TriangleNormal(const std::vector<Eigen::Vector3d>& positions, const std::array<int, 3>& t) {
  const Eigen::Vector3d& a = positions[t[0]];
  const Eigen::Vector3d n = (positions[t[1]] - a).cross(positions[t[2]] - a);
  const double norm = n.norm();
  return norm > 0 ? Eigen::Vector3d(n / norm) : Eigen::Vector3d::Zero();
}

}  // namespace

struct LoopSurface::Impl {
  int max_level = 0;
  std::vector<SurfaceLevel> levels;
  TriangleBvh finest_tree;  // over levels.back()'s limit positions and triangles
  // Per finest triangle: bit i set when edge (v[i], v[i+1]) lies on an open
  // boundary.
  std::vector<std::uint8_t> finest_boundary_edges;
};

LoopSurface::LoopSurface() : impl_(std::make_unique<Impl>()) {}
LoopSurface::~LoopSurface() = default;

int LoopSurface::max_level() const { return impl_->max_level; }

const SurfaceLevel& LoopSurface::level(int k) const {
  // Out-of-range levels are clamped rather than crashing (see the header).
  return impl_->levels[std::clamp(k, 0, impl_->max_level)];
}

absl::StatusOr<std::unique_ptr<LoopSurface>> LoopSurface::Create(const ControlMesh& control, int max_level) {
  return Create(control, max_level, LimitProjection());
}

int LevelWithinTriangleLimit(const ControlMesh& control, int wanted) {
  int level = std::clamp(wanted, 0, kMaxLevel);
  while (level > 0 && (static_cast<std::int64_t>(control.triangles.size()) << (2 * level)) > kMaxFinestTriangles) {
    --level;
  }
  return level;
}

absl::StatusOr<std::unique_ptr<LoopSurface>> LoopSurface::Create(const ControlMesh& control, int max_level,
                                                                 const LimitProjection& projection) {
  return Create(control, max_level, projection, Edges::kSmooth);
}

absl::StatusOr<std::unique_ptr<LoopSurface>> LoopSurface::Create(const ControlMesh& control, int max_level,
                                                                 const LimitProjection& projection, Edges edges) {
  if (max_level < 0 || max_level > kMaxLevel) {
    return absl::InvalidArgumentError(
        absl::StrFormat("subdivision level %d is out of range 0..%d", max_level, kMaxLevel));
  }
  if (absl::Status valid = ValidateControlMesh(control); !valid.ok()) return valid;
  const std::int64_t finest_triangles = static_cast<std::int64_t>(control.triangles.size()) << (2 * max_level);
  if (finest_triangles > kMaxFinestTriangles) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "refining %d control triangles to level %d gives %d triangles, more than the limit %d",
        control.triangles.size(), max_level, finest_triangles, kMaxFinestTriangles));
  }

  OsdErrorCapture osd_errors;
  const int num_control_vertices = static_cast<int>(control.positions.size());
  const int num_control_faces = static_cast<int>(control.triangles.size());
  std::vector<int> verts_per_face(num_control_faces, 3);
  std::vector<int> face_vertices;
  face_vertices.reserve(3 * num_control_faces);
  for (const auto& t : control.triangles) face_vertices.insert(face_vertices.end(), t.begin(), t.end());

  Far::TopologyDescriptor descriptor;
  descriptor.numVertices = num_control_vertices;
  descriptor.numFaces = num_control_faces;
  descriptor.numVertsPerFace = verts_per_face.data();
  descriptor.vertIndicesPerFace = face_vertices.data();
  std::vector<int> crease_pairs;
  std::vector<float> crease_weights;
  if (edges == Edges::kSharp) {
    std::vector<std::array<int, 2>> unique_edges;
    unique_edges.reserve(3 * control.triangles.size());
    for (const auto& t : control.triangles) {
      for (int i = 0; i < 3; ++i) unique_edges.push_back({std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])});
    }
    std::sort(unique_edges.begin(), unique_edges.end());
    unique_edges.erase(std::unique(unique_edges.begin(), unique_edges.end()), unique_edges.end());
    for (const auto& e : unique_edges) crease_pairs.insert(crease_pairs.end(), e.begin(), e.end());
    crease_weights.assign(unique_edges.size(), Sdc::Crease::SHARPNESS_INFINITE);
    descriptor.numCreases = static_cast<int>(unique_edges.size());
    descriptor.creaseVertexIndexPairs = crease_pairs.data();
    descriptor.creaseWeights = crease_weights.data();
  }

  Sdc::Options sdc_options;
  // EDGE_AND_CORNER keeps the corners of open meshes on the surface (a
  // boundary vertex with a single face stays put; EDGE_ONLY would round it
  // off), so a plate's sampled region covers the whole plate up to its
  // corners. Boundary edges are interpolated either way; closed meshes are
  // unaffected.
  sdc_options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  std::unique_ptr<Far::TopologyRefiner> refiner(
      Factory::Create(descriptor, Factory::Options(Sdc::SCHEME_LOOP, sdc_options)));
  if (refiner == nullptr || !osd_errors.errors().empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("OpenSubdiv rejected the control mesh: ",
                     osd_errors.errors().empty() ? "no reason given" : osd_errors.errors()));
  }
  Far::TopologyRefiner::UniformOptions uniform(max_level);
  uniform.orderVerticesFromFacesFirst = false;  // children of vertices first: the numbering contract
  uniform.fullTopologyInLastLevel = true;       // PrimvarRefiner::Limit needs the finest vertex neighbourhoods
  refiner->RefineUniform(uniform);
  if (!osd_errors.errors().empty()) {
    return absl::InternalError(absl::StrCat("OpenSubdiv refinement failed: ", osd_errors.errors()));
  }

  auto surface = std::unique_ptr<LoopSurface>(new LoopSurface());
  Impl& impl = *surface->impl_;
  impl.max_level = max_level;
  impl.levels.resize(max_level + 1);

  // Check the numbering contract rather than trust it: vertex v's child is v,
  // edge e's child is V_k + e.
  for (int k = 0; k < max_level; ++k) {
    const Far::TopologyLevel& level = refiner->GetLevel(k);
    const int num_vertices = level.GetNumVertices();
    for (int v = 0; v < num_vertices; ++v) {
      if (level.GetVertexChildVertex(v) != v) {
        return absl::InternalError(absl::StrFormat(
            "OpenSubdiv numbering: vertex %d of level %d has child %d", v, k, level.GetVertexChildVertex(v)));
      }
    }
    for (int e = 0; e < level.GetNumEdges(); ++e) {
      if (level.GetEdgeChildVertex(e) != num_vertices + e) {
        return absl::InternalError(absl::StrFormat("OpenSubdiv numbering: edge %d of level %d has child %d", e, k,
                                                   level.GetEdgeChildVertex(e)));
      }
    }
  }

  // Topology and refined positions per level, written in place.
  const Far::PrimvarRefinerReal<double> primvar(*refiner);
  for (int k = 0; k <= max_level; ++k) {
    const Far::TopologyLevel& topology = refiner->GetLevel(k);
    SurfaceLevel& level = impl.levels[k];
    const int num_vertices = topology.GetNumVertices();
    level.positions.resize(num_vertices);
    if (k == 0) {
      level.positions = control.positions;
    } else {
      Vec3View src(impl.levels[k - 1].positions.data());
      Vec3View dst(level.positions.data());
      primvar.Interpolate(k, src, dst);
    }
    level.triangles.resize(topology.GetNumFaces());
    for (int f = 0; f < topology.GetNumFaces(); ++f) {
      const Far::ConstIndexArray fv = topology.GetFaceVertices(f);
      level.triangles[f] = {fv[0], fv[1], fv[2]};
    }
    level.edges.resize(topology.GetNumEdges());
    for (int e = 0; e < topology.GetNumEdges(); ++e) {
      const Far::ConstIndexArray ev = topology.GetEdgeVertices(e);
      level.edges[e] = {std::min(ev[0], ev[1]), std::max(ev[0], ev[1])};
    }
    level.neighbors.resize(num_vertices);
    for (int v = 0; v < num_vertices; ++v) {
      const Far::ConstIndexArray ve = topology.GetVertexEdges(v);
      std::vector<int>& around = level.neighbors[v];
      around.resize(ve.size());
      for (int i = 0; i < ve.size(); ++i) {
        const std::array<int, 2>& edge = level.edges[ve[i]];
        around[i] = edge[0] == v ? edge[1] : edge[0];
      }
      std::sort(around.begin(), around.end());
    }
    if (k < max_level) {
      level.edge_child_vertex.resize(level.edges.size());
      for (int e = 0; e < static_cast<int>(level.edges.size()); ++e) level.edge_child_vertex[e] = num_vertices + e;
    }
    if (k > 0) {
      const int num_parent_vertices = refiner->GetLevel(k - 1).GetNumVertices();
      level.parent_edge.assign(num_vertices, -1);
      for (int v = num_parent_vertices; v < num_vertices; ++v) level.parent_edge[v] = v - num_parent_vertices;
    }
  }

  // Limit positions and tangents at the finest level (the first tangent goes
  // straight into limit_normals, which becomes the normal below). A vertex's
  // limit is the same at every level, so coarser levels copy a prefix.
  SurfaceLevel& finest = impl.levels[max_level];
  const int num_finest = static_cast<int>(finest.positions.size());
  finest.limit_positions.resize(num_finest);
  finest.limit_normals.resize(num_finest);
  {
    std::vector<Eigen::Vector3d> tangent2(num_finest);
    Vec3View src(finest.positions.data());
    Vec3View position(finest.limit_positions.data());
    Vec3View tangent1_view(finest.limit_normals.data());
    Vec3View tangent2_view(tangent2.data());
    primvar.Limit(src, position, tangent1_view, tangent2_view);
    if (!osd_errors.errors().empty()) {
      return absl::InternalError(absl::StrCat("OpenSubdiv limit evaluation failed: ", osd_errors.errors()));
    }
    // Normal = tangent1 x tangent2, which OpenSubdiv orients by the face
    // winding (counter-clockwise from outside gives outward). As a safeguard
    // the sign is checked against the limit triangles around the vertex, which
    // also stand in where the tangents degenerate.
    const Far::TopologyLevel& topology = refiner->GetLevel(max_level);
    for (int v = 0; v < num_finest; ++v) {
      const Eigen::Vector3d& t1 = finest.limit_normals[v];
      const Eigen::Vector3d& t2 = tangent2[v];
      Eigen::Vector3d from_faces = Eigen::Vector3d::Zero();
      const Far::ConstIndexArray vf = topology.GetVertexFaces(v);
      for (int i = 0; i < vf.size(); ++i) {
        const auto& t = finest.triangles[vf[i]];
        const Eigen::Vector3d& a = finest.limit_positions[t[0]];
        from_faces += (finest.limit_positions[t[1]] - a).cross(finest.limit_positions[t[2]] - a);
      }
      Eigen::Vector3d n = t1.cross(t2);
      if (!(n.norm() > 1e-9 * t1.norm() * t2.norm()) || n.norm() == 0.0) n = from_faces;
      if (n.dot(from_faces) < 0) n = -n;
      const double norm = n.norm();
      finest.limit_normals[v] = norm > 0 ? Eigen::Vector3d(n / norm) : Eigen::Vector3d::UnitZ();
    }

    // Open-boundary edges of the finest level, for TraceDragPath.
    impl.finest_boundary_edges.assign(finest.triangles.size(), 0);
    for (std::size_t f = 0; f < finest.triangles.size(); ++f) {
      const auto& t = finest.triangles[f];
      for (int i = 0; i < 3; ++i) {
        const Far::Index e = topology.FindEdge(t[i], t[(i + 1) % 3]);
        if (e >= 0 && topology.GetEdgeFaces(e).size() == 1) impl.finest_boundary_edges[f] |= 1u << i;
      }
    }
  }
  refiner.reset();  // release OpenSubdiv's tables before the search tree is built
  if (projection) {
    for (int v = 0; v < num_finest; ++v) projection(finest.limit_positions[v], finest.limit_normals[v]);
  }

  for (int k = 0; k < max_level; ++k) {
    SurfaceLevel& level = impl.levels[k];
    const auto count = static_cast<std::ptrdiff_t>(level.positions.size());
    level.limit_positions.assign(finest.limit_positions.begin(), finest.limit_positions.begin() + count);
    level.limit_normals.assign(finest.limit_normals.begin(), finest.limit_normals.begin() + count);
  }
  impl.finest_tree = TriangleBvh(&finest.limit_positions, &finest.triangles);
  return surface;
}

SurfacePoint LoopSurface::ClosestPoint(const Eigen::Vector3d& query) const {
  const ClosestTriangle hit = impl_->finest_tree.Closest(query);
  SurfacePoint out;
  if (hit.triangle < 0) return out;
  const SurfaceLevel& finest = this->finest();
  const auto& t = finest.triangles[hit.triangle];
  out.triangle = hit.triangle;
  out.barycentric = hit.barycentric;
  out.position = hit.position;
  out.distance = std::sqrt(hit.squared_distance);
  const Eigen::Vector3d n = hit.barycentric[0] * finest.limit_normals[t[0]] +
                            hit.barycentric[1] * finest.limit_normals[t[1]] +
                            hit.barycentric[2] * finest.limit_normals[t[2]];
  const double norm = n.norm();
  out.normal = norm > 1e-12 ? Eigen::Vector3d(n / norm) : TriangleNormal(finest.limit_positions, t);
  return out;
}

absl::StatusOr<SurfacePath> LoopSurface::TraceDragPath(const Eigen::Vector3d& start, const Eigen::Vector3d& direction,
                                                       double length_mm, double step_mm) const {
  if (!start.allFinite()) return absl::InvalidArgumentError("drag start is not finite");
  if (!direction.allFinite() || direction.norm() == 0.0) {
    return absl::InvalidArgumentError("drag direction is zero or not finite");
  }
  if (!(length_mm > 0.0) || !std::isfinite(length_mm)) {
    return absl::InvalidArgumentError(absl::StrFormat("drag length %g mm must be positive", length_mm));
  }
  if (!(step_mm > 0.0) || !std::isfinite(step_mm)) {
    return absl::InvalidArgumentError(absl::StrFormat("drag step %g mm must be positive", step_mm));
  }
  if (length_mm / step_mm > kMaxPathSteps) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "drag of %g mm in steps of %g mm needs more than %g steps", length_mm, step_mm, kMaxPathSteps));
  }

  SurfacePoint here = ClosestPoint(start);
  const Eigen::Vector3d unit_direction = direction.normalized();
  Eigen::Vector3d tangent = unit_direction - unit_direction.dot(here.normal) * here.normal;
  // Within ~0.06 degrees of the normal the tangent direction is meaningless.
  if (tangent.norm() < 1e-3) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "drag direction (%g, %g, %g) is along the surface normal at the start", direction.x(), direction.y(),
        direction.z()));
  }
  tangent.normalize();

  SurfacePath path;
  path.points.push_back(here.position);
  path.normals.push_back(here.normal);
  // The last steps shrink to hit the length; stop once what is left is
  // negligible (projection makes each chord a little shorter than asked).
  const double tolerance = 1e-9 * length_mm;
  while (length_mm - path.length_mm > tolerance) {
    const double step = std::min(step_mm, length_mm - path.length_mm);
    const Eigen::Vector3d target = here.position + step * tangent;
    const SurfacePoint next = ClosestPoint(target);

    // Walking off an open boundary: the projection lands on a boundary edge
    // and pulls the target back sideways, within the surface's plane.
    const std::uint8_t boundary = impl_->finest_boundary_edges[next.triangle];
    if (boundary != 0) {
      bool on_boundary = false;
      for (int i = 0; i < 3; ++i) {
        // Edge (v[i], v[i+1]) is where the weight of the opposite vertex is 0.
        if ((boundary & (1u << i)) && next.barycentric[(i + 2) % 3] <= 1e-12) on_boundary = true;
      }
      const Eigen::Vector3d face_normal = TriangleNormal(finest().limit_positions, finest().triangles[next.triangle]);
      const Eigen::Vector3d pulled = target - next.position;
      const double sideways = (pulled - pulled.dot(face_normal) * face_normal).norm();
      if (on_boundary && sideways > kWalkOffFraction * step) {
        return absl::OutOfRangeError(absl::StrFormat(
            "drag path leaves the surface at its open boundary after %.3f of %.3f mm, near (%.3f, %.3f, %.3f)",
            path.length_mm, length_mm, next.position.x(), next.position.y(), next.position.z()));
      }
    }

    const double chord = (next.position - here.position).norm();
    if (!(chord > 1e-6 * step)) {
      return absl::InternalError(absl::StrFormat("drag path is stuck after %.3f of %.3f mm", path.length_mm,
                                                 length_mm));
    }
    path.length_mm += chord;
    path.points.push_back(next.position);
    path.normals.push_back(next.normal);
    // Parallel transport: drop the component along the new normal, keep unit
    // length. Where the normal turns sharply within a step (a CAD part's
    // edge, on a surface whose normals are not smoothed across it), turn the
    // tangent with it first: projecting alone would shed its component
    // across the edge, and an oblique drag would bend to run along the edge.
    // If the surface turned so sharply that nothing is left, keep walking
    // along the chord.
    Eigen::Vector3d carried = tangent;
    if (here.normal.dot(next.normal) < kSharpTurnCos) {
      carried = Eigen::Quaterniond::FromTwoVectors(here.normal, next.normal) * tangent;
    }
    Eigen::Vector3d transported = carried - carried.dot(next.normal) * next.normal;
    if (transported.norm() < 1e-9) transported = next.position - here.position;
    tangent = transported.normalized();
    here = next;
  }
  return path;
}

Eigen::Vector3d LoopSurface::DefaultDragDirection(int finest_vertex) const {
  const SurfaceLevel& finest = this->finest();
  if (finest_vertex < 0 || finest_vertex >= static_cast<int>(finest.limit_normals.size())) {
    return Eigen::Vector3d::Zero();
  }
  const Eigen::Vector3d& n = finest.limit_normals[finest_vertex];
  int axis = 0;
  n.cwiseAbs().minCoeff(&axis);  // first of equals on ties: deterministic
  const Eigen::Vector3d a = Eigen::Vector3d::Unit(axis);
  return (a - a.dot(n) * n).normalized();
}

}  // namespace surfmap
