#include "server/mesh/loop_surface.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <string>

#include <Eigen/Geometry>
#include <opensubdiv/far/error.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/mesh/triangle_bvh.h"

namespace surfmap {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

namespace {

constexpr int kMaxLevel = 6;
// Refinement output cap: the finest level costs ~250 bytes per triangle with
// its topology, limit data and search tree, so 4M triangles is ~1 GB.
constexpr std::int64_t kMaxFinestTriangles = std::int64_t{1} << 22;
// A path step never needs more than this many points.
constexpr double kMaxPathSteps = 1e6;
// A stepped-to point whose projection moved it sideways along an open
// boundary by more than this fraction of the step has left the surface.
constexpr double kWalkOffFraction = 0.02;

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

// The primvar type OpenSubdiv's PrimvarRefiner interpolates.
struct Point3 {
  double x = 0, y = 0, z = 0;
  void Clear(void* = nullptr) { x = y = z = 0; }
  void AddWithWeight(const Point3& src, double weight) {
    x += weight * src.x;
    y += weight * src.y;
    z += weight * src.z;
  }
  Eigen::Vector3d ToEigen() const { return {x, y, z}; }
};

}  // namespace

struct LoopSurface::Impl {
  int max_level = 0;
  std::vector<SurfaceLevel> levels;
  TriangleBvh finest_tree;
  // Per finest triangle: unit normal of the flat triangle (limit positions) and
  // bit i set when edge (v[i], v[i+1]) lies on an open boundary.
  std::vector<Eigen::Vector3d> finest_face_normals;
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

  Sdc::Options sdc_options;
  // EDGE_AND_CORNER keeps the corners of open meshes (a plate's corners,
  // valence-2 boundary vertices) on the surface: the measured region then
  // covers the whole part instead of a rounded-off inset. Closed meshes are
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

  // Refined positions of all levels, back to back.
  std::vector<std::size_t> level_offset(max_level + 2, 0);
  for (int k = 0; k <= max_level; ++k) level_offset[k + 1] = level_offset[k] + refiner->GetLevel(k).GetNumVertices();
  std::vector<Point3> refined(level_offset.back());
  for (int v = 0; v < num_control_vertices; ++v) {
    refined[v] = {control.positions[v].x(), control.positions[v].y(), control.positions[v].z()};
  }
  Far::PrimvarRefinerReal<double> primvar(*refiner);
  for (int k = 1; k <= max_level; ++k) {
    Point3* src = refined.data() + level_offset[k - 1];
    Point3* dst = refined.data() + level_offset[k];
    primvar.Interpolate(k, src, dst);
  }
  // Limit positions and tangents at the finest level; a vertex's limit is the
  // same at every level, so coarser levels copy a prefix.
  const int num_finest = refiner->GetLevel(max_level).GetNumVertices();
  std::vector<Point3> limit(num_finest), tangent1(num_finest), tangent2(num_finest);
  primvar.Limit(refined.data() + level_offset[max_level], limit, tangent1, tangent2);
  if (!osd_errors.errors().empty()) {
    return absl::InternalError(absl::StrCat("OpenSubdiv limit evaluation failed: ", osd_errors.errors()));
  }

  for (int k = 0; k <= max_level; ++k) {
    const Far::TopologyLevel& topology = refiner->GetLevel(k);
    SurfaceLevel& level = impl.levels[k];
    const int num_vertices = topology.GetNumVertices();
    level.positions.resize(num_vertices);
    level.limit_positions.resize(num_vertices);
    for (int v = 0; v < num_vertices; ++v) {
      level.positions[v] = refined[level_offset[k] + v].ToEigen();
      level.limit_positions[v] = limit[v].ToEigen();
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
      around.reserve(ve.size());
      for (int i = 0; i < ve.size(); ++i) {
        const std::array<int, 2>& edge = level.edges[ve[i]];
        around.push_back(edge[0] == v ? edge[1] : edge[0]);
      }
      std::sort(around.begin(), around.end());
    }
    if (k < max_level) {
      level.edge_child_vertex.resize(level.edges.size());
      for (int e = 0; e < static_cast<int>(level.edges.size()); ++e) level.edge_child_vertex[e] = num_vertices + e;
    }
    if (k > 0) {
      const int num_parent_vertices = refiner->GetLevel(k - 1).GetNumVertices();
      level.parent_edge.resize(num_vertices, -1);
      for (int v = num_parent_vertices; v < num_vertices; ++v) level.parent_edge[v] = v - num_parent_vertices;
    }
  }

  // Normals: the cross product of the limit tangents. Its sign is checked
  // against the area-weighted normal of the finest limit triangles around the
  // vertex, which follows the counter-clockwise-from-outside winding; the
  // latter also stands in where the tangents degenerate.
  SurfaceLevel& finest = impl.levels[max_level];
  std::vector<Eigen::Vector3d> face_sum(num_finest, Eigen::Vector3d::Zero());
  impl.finest_face_normals.resize(finest.triangles.size());
  for (std::size_t f = 0; f < finest.triangles.size(); ++f) {
    const auto& t = finest.triangles[f];
    const Eigen::Vector3d& a = finest.limit_positions[t[0]];
    const Eigen::Vector3d twice_area_normal =
        (finest.limit_positions[t[1]] - a).cross(finest.limit_positions[t[2]] - a);
    for (int i = 0; i < 3; ++i) face_sum[t[i]] += twice_area_normal;
    const double norm = twice_area_normal.norm();
    impl.finest_face_normals[f] = norm > 0 ? Eigen::Vector3d(twice_area_normal / norm) : Eigen::Vector3d::UnitZ();
  }
  std::vector<Eigen::Vector3d> normals(num_finest);
  for (int v = 0; v < num_finest; ++v) {
    const Eigen::Vector3d from_tangents = tangent1[v].ToEigen().cross(tangent2[v].ToEigen());
    const Eigen::Vector3d& from_faces = face_sum[v];
    Eigen::Vector3d n = from_tangents;
    const double scale = tangent1[v].ToEigen().norm() * tangent2[v].ToEigen().norm();
    if (!(n.norm() > 1e-9 * scale) || scale == 0.0) n = from_faces;
    if (n.dot(from_faces) < 0) n = -n;
    const double norm = n.norm();
    normals[v] = norm > 0 ? Eigen::Vector3d(n / norm) : Eigen::Vector3d::UnitZ();
  }
  for (int k = 0; k <= max_level; ++k) {
    SurfaceLevel& level = impl.levels[k];
    level.limit_normals.assign(normals.begin(), normals.begin() + level.limit_positions.size());
  }

  // Open-boundary edges of the finest level, for TraceDragPath.
  {
    const Far::TopologyLevel& topology = refiner->GetLevel(max_level);
    impl.finest_boundary_edges.assign(finest.triangles.size(), 0);
    for (std::size_t f = 0; f < finest.triangles.size(); ++f) {
      const auto& t = finest.triangles[f];
      for (int i = 0; i < 3; ++i) {
        const Far::Index e = topology.FindEdge(t[i], t[(i + 1) % 3]);
        if (e >= 0 && topology.GetEdgeFaces(e).size() == 1) impl.finest_boundary_edges[f] |= 1u << i;
      }
    }
  }
  impl.finest_tree = TriangleBvh(finest.limit_positions, finest.triangles);
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
  out.normal = norm > 1e-12 ? Eigen::Vector3d(n / norm) : impl_->finest_face_normals[hit.triangle];
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
      const Eigen::Vector3d& face_normal = impl_->finest_face_normals[next.triangle];
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
    // length. If the surface turned so sharply that nothing is left, keep
    // walking along the chord.
    Eigen::Vector3d transported = tangent - tangent.dot(next.normal) * next.normal;
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
