#include "server/map/boundary_curves.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include <Eigen/Geometry>

namespace surfmap {
namespace {

// The cubic Hermite curve p0 -> p1 with end derivatives m0, m1 (per unit
// parameter).
struct Hermite {
  Eigen::Vector3d p0, p1, m0, m1;
  Eigen::Vector3d At(double s) const {
    const double s2 = s * s, s3 = s2 * s;
    return (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * m1;
  }
};

// The boundary's direction at a mark of a chain, and how the chain turns
// there: `turn` is the sine of the turn, positive to the left of travel
// (about the mark's normal), for travel prev -> at -> other.
struct ChainTangent {
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit, from prev towards other
  double turn = 0.0;
};

// The chain's tangent at mark `at` of link at -> other, from the chord
// prev -> other across it (prev: `at`'s neighbour on its other link), in
// `at`'s tangent plane; nullopt where `at` is not joined on both sides
// exactly once or the chain turns there by more than max_turn_deg.
std::optional<ChainTangent> TangentAt(const std::vector<ChangeMark>& marks,
                                      const std::vector<std::vector<int>>& neighbours, int at, int other,
                                      double max_turn_deg) {
  if (max_turn_deg <= 0.0 || neighbours[at].size() != 2) return std::nullopt;
  const int prev = neighbours[at][0] == other ? neighbours[at][1] : neighbours[at][0];
  if (prev == other) return std::nullopt;
  const Eigen::Vector3d& x = marks[at].position;
  const Eigen::Vector3d in = x - marks[prev].position, out = marks[other].position - x;
  if (!(in.norm() > 1e-9 && out.norm() > 1e-9)) return std::nullopt;
  const double turn = std::acos(std::clamp(in.normalized().dot(out.normalized()), -1.0, 1.0));
  if (turn > max_turn_deg * std::numbers::pi / 180.0) return std::nullopt;
  const Eigen::Vector3d& n = marks[at].normal;
  Eigen::Vector3d t = marks[other].position - marks[prev].position;
  t -= t.dot(n) * n;
  if (!(t.norm() > 1e-9)) return std::nullopt;
  return ChainTangent{t.normalized(), n.dot(in.normalized().cross(out.normalized()))};
}

// Turns smaller than this (sine) are the change's own location error over a
// link (~0.3 mm over >= 10 mm): the chain runs straight there.
constexpr double kStraightTurn = 0.035;  // ~2 degrees

// The curve of `link` as short segments, each with its own side vector;
// empty where the chord is drawn instead: unless the chain gives both ends a
// direction and turns the same way at both, the way an arc does. A crossing
// located off its boundary makes the chain zigzag (one way into it, the
// other way out), and a curve through it would carry its error into the
// neighbouring links, where a chord keeps it to its own two.
std::vector<BoundarySegment> CurveSegments(const std::vector<ChangeMark>& marks,
                                           const std::vector<std::vector<int>>& neighbours, const DrawnLink& link,
                                           double max_turn_deg) {
  const ChangeMark& p = marks[link.from];
  const ChangeMark& q = marks[link.to];
  const Eigen::Vector3d chord = q.position - p.position;
  const double length = chord.norm();
  if (!(length > 1e-9)) return {};
  const std::optional<ChainTangent> at_p = TangentAt(marks, neighbours, link.from, link.to, max_turn_deg);
  const std::optional<ChainTangent> at_q = TangentAt(marks, neighbours, link.to, link.from, max_turn_deg);
  if (!at_p || !at_q) return {};
  // at_q was taken travelling q -> p: its turn, travelling p -> q, is -turn.
  const double turn_p = at_p->turn, turn_q = -at_q->turn;
  const bool straight = std::abs(turn_p) < kStraightTurn && std::abs(turn_q) < kStraightTurn;
  if (!straight && turn_p * turn_q <= 0.0) return {};
  const Hermite curve{p.position, q.position, length * at_p->direction, -length * at_q->direction};
  // Short enough that each piece is straight to well within the corridor:
  // a 2 mm piece of a curve of radius 5 mm leaves its chord by 0.1 mm.
  constexpr double kPieceMm = 2.0;
  const int pieces = std::max(1, static_cast<int>(std::ceil(length / kPieceMm)));
  std::vector<BoundarySegment> out;
  out.reserve(pieces);
  for (int k = 0; k < pieces; ++k) {
    const double s0 = static_cast<double>(k) / pieces, s1 = static_cast<double>(k + 1) / pieces;
    const Eigen::Vector3d n0 = ((1.0 - s0) * p.normal + s0 * q.normal).normalized();
    const Eigen::Vector3d n1 = ((1.0 - s1) * p.normal + s1 * q.normal).normalized();
    const Eigen::Vector3d a = curve.At(s0), b = curve.At(s1);
    Eigen::Vector3d side = (b - a).cross(n0 + n1);
    if (!(side.norm() > 1e-12)) return {};
    side.normalize();
    if (side.dot(link.towards_a) < 0.0) side = -side;
    // A curve that turns its side away from a's side has folded: not drawn.
    if (side.dot(link.towards_a) < 0.2) return {};
    out.push_back({a, b, side, link.a, link.b, ChordBow(a, b, n0, n1)});
  }
  return out;
}

}  // namespace

std::vector<LabelledPoint> LinkSeeds(const std::vector<ChangeMark>& marks, const std::vector<DrawnLink>& links,
                                     const LabelledPointGrid& data, const BoundaryLinkOptions& o, int* curved) {
  std::vector<std::vector<int>> neighbours(marks.size());
  for (const DrawnLink& l : links) {
    neighbours[l.from].push_back(l.to);
    neighbours[l.to].push_back(l.from);
  }
  std::vector<LabelledPoint> out;
  int drawn_curved = 0;
  for (const DrawnLink& l : links) {
    std::vector<BoundarySegment> pieces = CurveSegments(marks, neighbours, l, o.max_curve_turn_deg);
    const bool contradicted = std::any_of(pieces.begin(), pieces.end(), [&](const BoundarySegment& s) {
      return SegmentContradicted(s, data, o);
    });
    if (pieces.empty() || contradicted) {
      AppendSegmentSeeds({marks[l.from].position, marks[l.to].position, l.towards_a, l.a, l.b}, o, &out);
      continue;
    }
    ++drawn_curved;
    // Each piece's seeds, without repeating the shared ends.
    for (std::size_t k = 0; k < pieces.size(); ++k) {
      std::vector<LabelledPoint> seeds;
      AppendSegmentSeeds(pieces[k], o, &seeds);
      out.insert(out.end(), seeds.begin() + (k == 0 ? 0 : 2), seeds.end());
    }
  }
  if (curved != nullptr) *curved = drawn_curved;
  return out;
}

}  // namespace surfmap
