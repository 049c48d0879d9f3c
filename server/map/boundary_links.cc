#include "server/map/boundary_links.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

#include <Eigen/Geometry>
#include "absl/strings/str_cat.h"
#include "server/map/boundary_bridges.h"
#include "server/map/boundary_chains.h"
#include "server/map/boundary_corners.h"
#include "server/map/boundary_extensions.h"
#include "server/map/boundary_lines.h"
#include "server/map/boundary_corridor.h"
#include "server/map/boundary_curves.h"
#include "server/map/boundary_dots.h"
#include "server/map/boundary_rectangles.h"

namespace surfmap {
bool BoundaryLinkOptions::IsValid(std::string* why) const {
  auto fail = [why](std::string m) {
    if (why != nullptr) *why = std::move(m);
    return false;
  };
  const std::pair<const char*, double> lengths[] = {{"max_length_mm", max_length_mm},
                                                    {"corridor_mm", corridor_mm},
                                                    {"seed_offset_mm", seed_offset_mm},
                                                    {"corner_reach_mm", corner_reach_mm},
                                                    {"corner_side_reach_mm", corner_side_reach_mm},
                                                    {"min_corner_link_mm", min_corner_link_mm},
                                                    {"min_line_chord_mm", min_line_chord_mm},
                                                    {"max_extension_length_mm", max_extension_length_mm},
                                                    {"max_dot_radius_mm", max_dot_radius_mm},
                                                    {"max_dot_residual_mm", max_dot_residual_mm},
                                                    {"max_dot_data_offset_mm", max_dot_data_offset_mm},
                                                    {"max_dot_outlier_mm", max_dot_outlier_mm},
                                                    {"max_corner_side_residual_mm", max_corner_side_residual_mm},
                                                    {"max_bridge_mm", max_bridge_mm},
                                                    {"max_rectangle_side_mm", max_rectangle_side_mm},
                                                    {"bridge_tolerance_mm", bridge_tolerance_mm}};
  for (const auto& [name, value] : lengths) {
    if (!(std::isfinite(value) && value >= 0.0)) return fail(absl::StrCat(name, " must be >= 0 and finite"));
  }
  if (!(std::isfinite(seed_spacing_mm) && seed_spacing_mm > 0.0)) return fail("seed_spacing_mm must be > 0");
  if (!(std::isfinite(max_dot_chord_mm) && max_dot_chord_mm > 0.0)) return fail("max_dot_chord_mm must be > 0");
  if (!(std::isfinite(dot_ring_radii) && dot_ring_radii >= 1.0)) return fail("dot_ring_radii must be >= 1");
  if (min_dot_crossings_to_excuse_one < 5) {
    return fail("min_dot_crossings_to_excuse_one must be >= 5 (a circle's parameters and two checks)");
  }
  if (min_rectangle_crossings < 5) return fail("min_rectangle_crossings must be >= 5 (a rectangle's parameters)");
  for (const auto& [name, value] : {std::pair<const char*, double>{"min_crossing_cos", min_crossing_cos},
                                    {"min_extension_crossing_cos", min_extension_crossing_cos},
                                    {"max_dot_contradicted_chord_share", max_dot_contradicted_chord_share}}) {
    if (!(value >= 0.0 && value <= 1.0)) return fail(absl::StrCat(name, " must be in [0, 1]"));
  }
  for (const auto& [name, value] : {std::pair<const char*, double>{"min_corner_turn_deg", min_corner_turn_deg},
                                    {"max_corner_turn_deg", max_corner_turn_deg},
                                    {"max_corner_normal_deg", max_corner_normal_deg},
                                    {"max_extension_turn_deg", max_extension_turn_deg},
                                    {"max_line_turn_deg", max_line_turn_deg},
                                    {"max_curve_turn_deg", max_curve_turn_deg},
                                    {"min_dot_arc_deg", min_dot_arc_deg},
                                    {"min_hanging_link_angle_deg", min_hanging_link_angle_deg}}) {
    if (!(value >= 0.0 && value <= 180.0)) return fail(absl::StrCat(name, " must be in [0, 180] degrees"));
  }
  if (!(max_line_crossing_deg >= 0.0 && max_line_crossing_deg <= 90.0)) {
    return fail("max_line_crossing_deg must be in [0, 90] degrees");
  }
  return true;
}

std::vector<LabelledPoint> BoundaryLinkPoints(const std::vector<ChangeMark>& marks,
                                              const std::vector<LabelledPoint>& data,
                                              const BoundaryLinkOptions& o, int* links, int* corners,
                                              int* bridges, int* dots_drawn, int* rectangles_drawn) {
  const int n = static_cast<int>(marks.size());
  const LabelledPointGrid grid(data, std::max(1.0, o.max_length_mm / 4.0));
  // Per mark and side along the boundary: the nearest consistent partner.
  std::vector<std::array<int, 2>> nearest(n, {-1, -1});
  std::vector<std::array<double, 2>> nearest_distance(n, {std::numeric_limits<double>::infinity(),
                                                          std::numeric_limits<double>::infinity()});
  auto consistent = [&](int i, int j, Eigen::Vector3d* side_normal, int* a_out, int* b_out) {
    const ChangeMark& p = marks[i];
    const ChangeMark& q = marks[j];
    const int a = std::min(p.before, p.after), b = std::max(p.before, p.after);
    if (a == b || std::min(q.before, q.after) != a || std::max(q.before, q.after) != b || p.drag == q.drag) return false;
    const Eigen::Vector3d chord = q.position - p.position;
    const double length = chord.norm();
    if (!(length > 1e-9) || length > o.max_length_mm) return false;
    const std::optional<Eigen::Vector3d> across = AcrossChordTowardsA(p, q, a, o.min_crossing_cos);
    if (!across) return false;
    *side_normal = *across;
    *a_out = a;
    *b_out = b;
    return true;
  };
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d along = marks[i].normal.cross(marks[i].direction);  // roughly along the boundary
    for (int j = 0; j < n; ++j) {
      if (i == j) continue;
      Eigen::Vector3d towards_a;
      int a, b;
      if (!consistent(i, j, &towards_a, &a, &b)) continue;
      const Eigen::Vector3d chord = marks[j].position - marks[i].position;
      const int side = chord.dot(along) >= 0.0 ? 0 : 1;
      const double d = chord.norm();
      if (d < nearest_distance[i][side]) {
        nearest_distance[i][side] = d;
        nearest[i][side] = j;
      }
    }
  }
  std::set<std::pair<int, int>> pairs;
  for (int i = 0; i < n; ++i) {
    for (int j : nearest[i]) {
      if (j >= 0) pairs.emplace(std::min(i, j), std::max(i, j));
    }
  }
  std::vector<LabelledPoint> out;
  std::vector<DrawnLink> drawn;
  for (const auto& [i, j] : pairs) {
    Eigen::Vector3d towards_a;
    int a, b;
    if (!consistent(i, j, &towards_a, &a, &b)) continue;
    const BoundarySegment link{marks[i].position, marks[j].position, towards_a, a, b,
                               ChordBow(marks[i].position, marks[j].position, marks[i].normal, marks[j].normal)};
    if (SegmentContradicted(link, grid, o)) continue;
    drawn.push_back({i, j, a, b, towards_a});
  }
  drawn = DrawLines(marks, std::move(drawn), grid, o);
  drawn = ExtendChains(marks, std::move(drawn), grid, o);
  // A dot's circle or a small patch's rectangle replaces the chords drawn
  // between its crossings.
  std::vector<BoundaryOutline> outlines = FindDots(marks, grid, o);
  if (dots_drawn != nullptr) *dots_drawn = static_cast<int>(outlines.size());
  std::set<int> in_dots;
  for (const BoundaryOutline& dot : outlines) in_dots.insert(dot.marks.begin(), dot.marks.end());
  std::vector<BoundaryOutline> rectangles = FindRectangles(marks, grid, o, in_dots);
  if (rectangles_drawn != nullptr) *rectangles_drawn = static_cast<int>(rectangles.size());
  outlines.insert(outlines.end(), std::make_move_iterator(rectangles.begin()), std::make_move_iterator(rectangles.end()));
  std::vector<int> dot_of(n, -1);
  for (int d = 0; d < static_cast<int>(outlines.size()); ++d) {
    for (int m : outlines[d].marks) dot_of[m] = d;
  }
  std::erase_if(drawn, [&](const DrawnLink& l) { return dot_of[l.from] >= 0 && dot_of[l.from] == dot_of[l.to]; });
  // Corners between chain ends are looked for with the cutting links in
  // place, so that a cut corner's two crossings are not ends.
  std::vector<LabelledPoint> corner_points = BoundaryCornerPoints(marks, drawn, grid, o, corners);
  int cut_corners = 0;
  drawn = ReplaceCutCorners(marks, std::move(drawn), grid, o, &corner_points, &cut_corners);
  if (corners != nullptr) *corners += cut_corners;
  out = LinkSeeds(marks, drawn, grid, o);
  const std::vector<LabelledPoint> bridge_points = BoundaryBridgePoints(marks, drawn, grid, o, bridges);
  out.insert(out.end(), bridge_points.begin(), bridge_points.end());
  if (links != nullptr) *links = static_cast<int>(drawn.size());
  out.insert(out.end(), corner_points.begin(), corner_points.end());
  for (const BoundaryOutline& outline : outlines) {
    const std::size_t first = out.size();
    for (const BoundarySegment& chord : outline.chords) AppendSegmentSeeds(chord, o, &out);
    for (std::size_t k = first; k < out.size(); ++k) out[k].project_along = outline.project_along;
  }
  return out;
}

}  // namespace surfmap
