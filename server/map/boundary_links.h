// Boundaries drawn through the places drags crossed them. A change point
// found inside a drag fixes one point of a boundary to ~0.1-0.3 mm; between
// two such points of the same pair of regions the boundary runs, to first
// order, straight from one to the other. Spreading the regions from the data
// alone (label_propagation.h) puts the boundary between two crossings
// halfway between the nearest data of either side, which on a drag-sized
// feature can be millimetres off. So neighbouring crossings of the same
// boundary are linked, and the link becomes data: labelled points just
// either side of it.
//
// Two change points P and Q of regions {A, B} are linked when
//  - they are at most max_length_mm apart (a boundary that bends with a
//    radius of curvature r leaves the chord by max_length^2 / (8 r): 0.5 mm
//    for a 20 mm link on a 100 mm radius);
//  - A lies on the same side of the line PQ at both (the drags crossed the
//    same boundary the same way round), and each drag ran within
//    acos(min_crossing_cos) = 32 degrees of perpendicular to the line. The
//    planner drags across boundaries, so where the boundary itself turns by
//    more than ~60 degrees between two crossings (a patch's corner, a dot
//    smaller than a drag) the drags are not both near-perpendicular to the
//    chord and the link is not drawn: a chord across a 60-degree arc of a
//    7 mm dot misses 4 mm^2 of it, across a 90-degree arc 14 mm^2;
//  - Q is P's nearest such point on that side along the boundary, or P is
//    Q's (a chain, not a web);
//  - no data contradicts it: within corridor_mm of the segment, every data
//    point of A or B is on its own side (or within the corridor's width of
//    the line, inside the uncertainty of a change), and no other region's
//    data lies in the corridor.
// The link's points go to A within seed_offset_mm on A's side and to B on
// B's side, every seed_spacing_mm.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace surfmap {

struct ChangeMark {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();   // on the surface
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit, along the drag from `before` to `after`
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();    // unit surface normal there
  int before = -1;                                      // region on the drag before the change
  int after = -1;                                       // ... and after it
  int drag = -1;
};

struct LabelledPoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  int label = -1;
  // Nonzero: the point lies off the surface, where this line through it
  // meets the surface (boundary_outlines.h); zero: at the nearest point.
  Eigen::Vector3d project_along = Eigen::Vector3d::Zero();
};

struct BoundaryLinkOptions {
  // A little over a drag length: the planner spaces its drags about a drag
  // length apart along a boundary, so neighbouring crossings land 20-22 mm
  // apart as often as 18-20 (the bottle's patch sides: 20.5 mm). With the
  // corridor following the surface's bow (boundary_corridor.h) a 25 mm link
  // no longer cuts the torus scenes' curved boundaries, as it did before the
  // bow (docs/method.md, measured on the same drags: 25 mm, 11 runs of 60
  // better and 1 worse; 22 mm, 7 and 1; 30 mm, 10 and 5). The plan's own map
  // keeps 20 mm (PlanRegionMapOptions).
  double max_length_mm = 25.0;
  // 30 degrees and the crossings' own location error: the planner scans
  // directions in 15-degree steps and often drags exactly 30 degrees off a
  // boundary, and a crossing located 0.3 mm off turns a 10-20 mm chord by
  // 1-2 degrees, so at 30 such pairs were linked or not by that noise (the
  // bottle's patch sides, docs/method.md). 35 degrees cuts corners. The
  // plan's own map keeps 30 (PlanRegionMapOptions), as measured.
  double min_crossing_cos = 0.848;  // cos 32 degrees
  // Half-width of the strip checked for contradicting data: the map's
  // points lie every RegionMapOptions::point_spacing_mm along a drag, so a
  // drag that crosses the chord puts at least one point within this of it.
  double corridor_mm = 1.0;
  // Link points: no sparser than the finest map level's ~1-2 mm edges can
  // resolve (two per edge), and off the chord by about the change's own
  // location error (RegionMapOptions::change_location_mm), so they never
  // claim more than a crossing shows.
  double seed_spacing_mm = 0.5;
  double seed_offset_mm = 0.25;
  // Corners (boundary_corners.h): where two chains of links end and their
  // boundaries, carried straight on, meet within corner_reach_mm of both
  // ends (max_length_mm: no corner segment is longer than a link; 10 mm
  // missed most of the bottle's corners, whose last crossings lie 8-15 mm
  // from them; 20 mm, the build before links reached 25, missed the
  // bottle's seed 14 corner 22.5 mm from a side's last crossing), turning
  // by min..max_corner_turn_deg. 0 = no corners. The plan's own map keeps
  // 20 (PlanRegionMapOptions).
  double corner_reach_mm = 25.0;
  // A cut corner's sides are checked for running straight over this stretch
  // from the chord's ends (boundary_corners.h). It stays at 20 mm when the
  // corner may lie 25 mm off: over 25 mm a side took in crossings round a
  // neighbouring corner and was refused (the plate, seed 5). 0 = no cut
  // corners replaced.
  double corner_side_reach_mm = 20.0;
  double min_corner_turn_deg = 30.0;   // less: the boundary runs on (not a corner)
  // More: a hairpin or a round dot, not a corner. 155 keeps a label's
  // triangle (60-degree points turn 120) and a sliver's 30-degree point
  // (150); 120, the build before, cut them off (held_decals, seed 14: its
  // sandpaper triangle 83.5 -> 88.25 %; docs/method.md, "A label's sharp
  // point is a corner"). The plan's own map keeps 120.
  double max_corner_turn_deg = 155.0;
  // A link that cuts a corner off is replaced by the corner when the chain
  // on each side of it runs straight to within this (boundary_corners.h;
  // 0 = links never replaced): a change is located to ~0.1-0.4 mm along its
  // drag (docs/method.md), as for max_dot_residual_mm.
  double max_corner_side_residual_mm = 0.5;
  // A side with one link within corner_side_reach_mm says nothing of whether it
  // runs straight, and cutting links are often that sparse (the bottle,
  // seed 6: links of 13-17 mm each side of a corner). With this, such a
  // side is straight when the chain goes on past the reach by one more link
  // that turns from it by at most max_line_turn_deg (boundary_corners.h;
  // with lines off, 0 degrees, only a side that runs on exactly passes).
  // False: such a side never is (the build before).
  bool corner_side_checked_past_reach = true;
  // A side with one link within corner_side_reach_mm and no crossing beyond it
  // (the chain ends there) is taken as straight when the corner's other
  // side is straight by the rules above: the bottle, seeds 9 and 14, had
  // patches whose top side was crossed twice, 12-16 mm apart, and a chord
  // from the nearer crossing to the next side cut the corner off. Two
  // crossings say where the side runs, not whether it turns at them; the
  // other side's straight run says the chord's turn is a corner's. Two such
  // sides are never taken (boundary_corners.h). False: the build before.
  bool corner_side_may_end_its_chain = true;
  // A cut corner with one straight side (by the rules above, not a lone
  // link whose chain ends) and a side that shows no direction (the other
  // end's chain turns within the reach, or has no link beyond the chord) is
  // drawn square: the unknown side leaves its crossing at right angles to
  // the straight one (boundary_corners.h). False: the chord stays.
  bool square_corner_from_one_side = true;
  // A side that runs straight over two links or more and then turns by
  // min_corner_turn_deg within corner_side_reach_mm (round a small patch's
  // next corner) is taken as its straight run (boundary_corners.h). False:
  // such a side is not straight.
  bool corner_side_stops_at_next_corner = true;
  // The two ends' normals may differ by at most this: 20 mm over the
  // scenes' most curved parts (radii of curvature ~27 mm) turns ~42 degrees;
  // more is not one piece of surface to draw straight segments on.
  double max_corner_normal_deg = 60.0;
  // A chain end's direction is its last link's; over a shorter link the
  // change's ~0.3 mm location error turns it by more than ~4 degrees.
  double min_corner_link_mm = 4.0;
  // A chain whose last link is shorter than min_corner_link_mm (two drags
  // that crossed the boundary side by side, 0.7 mm apart at the bottle's
  // patch side, seed 6) still has an end: its direction is taken from the
  // first mark back along the chain at least min_corner_link_mm away, as
  // a long last link's would be. False: such an end is dropped, and with it
  // the corner, extension or bridge it would make (the build before).
  bool chain_ends_reach_past_short_links = true;
  // Chains carried on through crossings drags made obliquely
  // (boundary_extensions.h): the chord from a chain's end may turn from its
  // last link by at most max_extension_turn_deg (0 = off; a corner turns by
  // min_corner_turn_deg or more and is left to corners), and the drag must
  // cross it within acos(min_extension_crossing_cos) of perpendicular.
  // Measured on the same drags (docs/method.md): 10 degrees, 29 runs of 60
  // better and 6 worse; 20 degrees, 25 better but 12 worse, the extra ones
  // on patches' corners, where a crossing of the next side close to the
  // corner lies within 20 degrees of the chain's line.
  double max_extension_turn_deg = 10.0;
  double min_extension_crossing_cos = 0.26;  // cos 75 degrees
  // An extension may be longer than a link: the chain's line says where the
  // boundary runs, where a lone link's chord has only its two ends (before
  // the corridor followed the bow, links of 25 or 30 mm cut curved
  // boundaries: the torus scenes lost on 7-9 runs of 12). Measured on the same drags
  // (docs/method.md): 30 mm, 14 runs of 60 better and 3 worse, torus scenes
  // unchanged; 40 mm the same.
  double max_extension_length_mm = 30.0;
  // Lines of three crossings drags made obliquely (boundary_lines.h): the
  // chord may turn at the middle one by at most this (0 = off). The same
  // 10 degrees as an extension's turn: a corner turns by min_corner_turn_deg
  // or more.
  double max_line_turn_deg = 10.0;
  // A line's chords may be as short as this when its two outer crossings
  // are at least min_corner_link_mm apart. Drags sent to a drag-sized patch
  // cross its sides a few mm apart: held_vase seed 10 crossed one side of
  // its sandpaper patch three times, 4.2 and 2.5 mm apart, and another five
  // times within 4.3 mm, and no chord of 4 mm joined any of them, so both
  // sides and the corner between them were left to the random walker. Three
  // crossings spanning 4 mm fix a side's direction as well as one 4 mm
  // chord does, and each short chord still turns by at most
  // max_line_turn_deg. Over a short chord the crossings' location error
  // scatters the turn more widely: mostly that refuses true lines, and a
  // corner (min_corner_turn_deg or more) passes only with errors of about
  // half a mm. At min_corner_link_mm or more every chord needs
  // min_corner_link_mm (the build before).
  double min_line_chord_mm = 1.5;
  // Each of a line's drags must cross its chords within this many degrees
  // of perpendicular (more is grazing along the boundary, not crossing it).
  // Three crossings in a row fix the line where one chord's two cannot, so
  // a line may take a more oblique crossing than an extension
  // (min_extension_crossing_cos, 75 degrees): on held_palette through the
  // service (seed 2) the middle crossing of its brass strip's edge ran 75.5
  // degrees off. Measured on the same drags, 18 scenes x seeds 1-16
  // (docs/method.md): 80 against 75 (the build before) changed 48 jobs, 37
  // better and 11 worse, goals met 278 -> 278.
  double max_line_crossing_deg = 80.0;
  // A line may take the side of a mark from a hanging link, one whose far
  // mark has no other link, when that link runs at least this many degrees
  // off the line's chord (boundary_lines.h; 90 = never, the build before).
  // Three crossings in a row say more than one chord: on held_palette (seed
  // 2) two drags left a 7 mm strip obliquely, one through each edge, 7 mm
  // apart, and the chord between them (83 degrees off the edge's line) cut
  // the strip off; the edge's line through the next crossing was refused
  // because that chord held the side (docs/method.md). A crossing further
  // along the same boundary links along the line (a few degrees off), and
  // taking its side would leave it with no link: with any angle allowed,
  // strip_block seed 3 lost 2 points of its worst region so.
  double min_hanging_link_angle_deg = 60.0;
  // Bridges (boundary_bridges.h): two chain ends that share one region and
  // point at each other within max_line_turn_deg are joined across a
  // stretch where the region beyond them changes, up to this long (0 = off).
  // A drag length and a half either side of a patch a strip runs through:
  // big_block_m's 40 mm patch leaves 41-48 mm between the strip's chain ends.
  double max_bridge_mm = 60.0;
  // A bridge's stretch is contradicted by data on the wrong side of its
  // chord by more than this, out to twice it (boundary_bridges.h).
  double bridge_tolerance_mm = 2.0;
  // Dots (boundary_dots.h): round regions whose crossings lie on a circle of
  // at most this radius (0 = off): half the longest link, so the dot is
  // smaller than a drag and no two of its crossings are farther apart than
  // a link reaches. Drawn as chords of at most max_dot_chord_mm (the finest
  // map level's ~1-2 mm edges: a 1 mm chord of a 3 mm radius is off the
  // circle by 0.04 mm).
  double max_dot_radius_mm = 12.5;
  double max_dot_chord_mm = 1.0;
  // Every crossing within this of the dot's circle: a change is located to
  // ~0.1-0.4 mm along its drag (docs/method.md); the crossings of a square
  // patch's sides and corner lie ~0.7 mm off their best circle.
  double max_dot_residual_mm = 0.5;
  // One crossing of a dot crossed this often may lie off the circle through
  // the others by up to max_dot_outlier_mm: a change located 1 mm off along
  // its drag (the noise in one drag's forces) refused held_block's 8.5 mm
  // dot, its nine other crossings on the circle to 0.3 mm (service seed 4,
  // docs/method.md). Six: the circle is fitted through five, two more than
  // it needs. max_dot_outlier_mm at or below max_dot_residual_mm: off (the
  // build before).
  int min_dot_crossings_to_excuse_one = 6;
  double max_dot_outlier_mm = 1.5;
  // Data near the circle may lie this far on the wrong side of it before it
  // contradicts the dot: as far as its own crossings may lie off it
  // (max_dot_residual_mm), for the data of a crossing drag reach to within
  // the change's guard of its crossing. A link passes through its two
  // crossings and checks by seed_offset_mm; with that (0.25 mm, the build
  // before) a dot was refused by its own crossing drags' data. Measured on
  // the same drags, 15 scenes x 8 seeds (docs/method.md): 10 jobs changed,
  // 9 better.
  double max_dot_data_offset_mm = 0.5;
  // A drag that grazed a dot's edge (ran more than acos(min_extension_crossing_cos)
  // off its centre) refused the dot. With this, its crossing counts when it
  // lies on the circle like the others (max_dot_residual_mm), so long as three
  // crossings were made steeply: held_block seed 3's grazing crossing was
  // the one that closed the circle's 183-degree gap (docs/method.md).
  // False: the build before.
  bool dot_grazing_crossings_on_circle = true;
  // A dot's crossings must span at least this arc of its circle (the widest
  // gap between them less than 360 minus it). Three crossings on 90
  // degrees, each located to 0.2 mm, fix an 8 mm circle's far side to
  // 1.3 mm (median, simulated). Crossings that do not surround the centre
  // (180) draw the dot only when other regions' data just outside the
  // circle close the gap (boundary_dots.h): two crossings of each side near
  // a patch's corner lie on a circle about the patch's inside too, and
  // there the gap faces the patch. That drew scan_dome_m's 16 mm glass dot
  // (80 % on three jobs, 95-98.5 % as a circle; docs/method.md). 180: only
  // crossings that surround the centre (the build before).
  double min_dot_arc_deg = 90.0;
  // The ring round a dot, out to this many radii from its centre, where its
  // own region's data contradict it (the region is larger, or not round)
  // and other regions' data close a one-sided dot's gap. 1.5 (the build
  // before): a drag's length beyond a drag-sized dot's edge.
  double dot_ring_radii = 1.5;
  // A dot's chords that data contradict (max_dot_data_offset_mm) are left
  // out, and the random walker draws the edge there, while at most this
  // share of them are; more refuse the circle. A drag that grazes a dot's
  // rim blends its last piece across the edge and lands it on the wrong
  // side of one chord: held_block seed 2's 8.6 mm dot, its eight crossings
  // on the circle to 0.12 mm, was refused for one chord of 54 and mapped
  // at 82 % (docs/method.md). 0: any contradicted chord refuses the circle
  // (the build before).
  double max_dot_contradicted_chord_share = 0.125;
  // Rectangles (boundary_rectangles.h): small patches whose crossings lie on
  // the four sides of a rectangle no side of which is longer than this (0 =
  // off, the build before): a drag and a half, for a patch as long as a drag
  // is crossed once on a side as often as not. A longer patch's sides are
  // crossed often enough to be chains of links.
  double max_rectangle_side_mm = 30.0;
  // At least this many crossings: a rectangle has five parameters.
  int min_rectangle_crossings = 6;
  // A side no drag crossed clear of its corners is drawn when other
  // regions' data run along it just outside (within corridor_mm, along half
  // its length or more: boundary_rectangles.h). False: such a rectangle is
  // refused (the build before).
  bool rectangle_sides_closed_by_data = true;
  // Only data within 2 corridor_mm of the band off the rectangle's plane
  // where its crossings lie refuse it (another region inside, its own
  // outside: boundary_rectangles.cc OnPatchSheet): a label on a handle lies
  // over the handle's far side and its butt. False: data as far off the
  // plane as half its longer side (the build before).
  bool rectangle_data_on_patch_sheet = true;
  // Links drawn as curves through their chain (boundary_curves.h): a link
  // end takes the chain's direction where the chain turns there by at most
  // this (0 = every link a chord, the build before). Links pass at most
  // 2 x acos(min_crossing_cos) = 64 degrees of turn between crossings.
  double max_curve_turn_deg = 60.0;
  // Every length finite (seed spacing > 0, the others >= 0), every cosine
  // in [0, 1], every angle in [0, 180]; *why names the first that is not.
  bool IsValid(std::string* why) const;
};

// The labelled points of every accepted link, corner, bridge and dot (not
// yet on the surface: callers project them); *links, *corners, *bridges and
// *dots (if given) receive how many were drawn.
std::vector<LabelledPoint> BoundaryLinkPoints(const std::vector<ChangeMark>& marks,
                                              const std::vector<LabelledPoint>& data,
                                              const BoundaryLinkOptions& options = {}, int* links = nullptr,
                                              int* corners = nullptr, int* bridges = nullptr, int* dots = nullptr,
                                              int* rectangles = nullptr);

}  // namespace surfmap
