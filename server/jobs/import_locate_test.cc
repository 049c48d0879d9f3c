// Locating an imported drag on a surface and the implied command's checks:
// a simulated drag on a plane and on a sphere is found where it was made and
// passes the leased trace's checks; the same drag lifted off the surface is
// refused by the surface check.
#include "server/jobs/import_locate.h"

#include <cmath>

#include "gtest/gtest.h"
#include "server/base/testing/status_matchers.h"
#include "clients/sim/dragsim/drag_simulator.h"
#include "server/estimate/fit_trace.h"
#include "server/jobs/trace_plausibility.h"
#include "server/mesh/primitive_meshes.h"

namespace surfmap {
namespace {

using ::surfmap::status_matchers::IsOk;
using ::surfmap::status_matchers::StatusIs;

std::unique_ptr<LoopSurface> Surface(absl::StatusOr<ControlMesh> mesh, int level) {
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  absl::StatusOr<std::unique_ptr<LoopSurface>> surface = LoopSurface::Create(*mesh, level);
  EXPECT_TRUE(surface.ok()) << surface.status();
  return std::move(*surface);
}

// A seeded glass drag of `length` mm along the limit surface from `start` in `direction`.
DragTrace DragOn(const LoopSurface& surface, const Eigen::Vector3d& start, const Eigen::Vector3d& direction,
                 double length) {
  absl::StatusOr<SurfacePath> path = surface.TraceDragPath(start, direction, length, 0.05);
  EXPECT_TRUE(path.ok()) << path.status();
  DragGeometry geometry{path->points, path->normals};
  DragSimOptions options;
  options.seed = 7;
  options.length_mm = length * 0.999;  // the polyline's chord error
  absl::StatusOr<DragSimResult> result = SimulateDrag(geometry, UniformMaterial(kGlass), options);
  EXPECT_TRUE(result.ok()) << result.status();
  return result->trace;
}

// The implied command passes every check a leased trace goes through, and the fit's normal is the surface's.
void ExpectPlausible(const DragTrace& trace, const LoopSurface& surface, const LocatedDrag& located) {
  const TraceLimits limits;
  const SurfaceDistance farthest = FarthestFromSurface(trace, surface);
  EXPECT_THAT(CheckTraceNearSurface(farthest.max_mm, farthest.sample, limits), IsOk());
  EXPECT_THAT(CheckTraceAgainstCommand(trace, located.command, limits), IsOk());
  absl::StatusOr<TraceFit> fit = FitTrace(trace, FitOptions{});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_THAT(CheckFitAgainstCommand(trace, *fit, located.command, limits), IsOk());
  EXPECT_NEAR(fit->friction.mu, kGlass.mu, 0.03);
}

TEST(LocateImportedDragTest, ADragOnAPlaneIsFoundAtItsMiddleAlongItsDirection) {
  std::unique_ptr<LoopSurface> plate = Surface(MakeGridPlate(200, 150, 6, 4), 2);
  const Eigen::Vector3d direction = Eigen::Vector3d(1, 1, 0).normalized();
  const DragTrace trace = DragOn(*plate, Eigen::Vector3d(-20, 5, 0), direction, 20.0);
  ProbeParameters probe;
  absl::StatusOr<LocatedDrag> located = LocateImportedDrag(trace, *plate, probe);
  ASSERT_TRUE(located.ok()) << located.status();
  const ProbeCommand& c = located->command;
  const Eigen::Vector3d middle = Eigen::Vector3d(-20, 5, 0) + 10.0 * direction;
  EXPECT_LT((c.position - middle).norm(), 0.3) << c.position.transpose();
  EXPECT_GT(std::abs(c.normal.z()), 0.999);
  EXPECT_GT(c.drag_direction.dot(direction), 0.999);
  EXPECT_NEAR(c.drag_direction.dot(c.normal), 0.0, 1e-9);
  EXPECT_LT(FarthestFromSurface(trace, *plate).max_mm, 0.1);
  EXPECT_EQ(c.site.level, plate->max_level());
  EXPECT_LT((plate->finest().limit_positions[c.site.vertex] - c.position).norm(), 10.0);
  EXPECT_EQ(c.probe.segment_length_mm, probe.segment_length_mm);  // the job's drag, not the file's
  ExpectPlausible(trace, *plate, *located);
}

TEST(LocateImportedDragTest, ADragOnASphereHasTheSurfaceNormalAtItsMiddle) {
  std::unique_ptr<LoopSurface> ball = Surface(MakeIcosphere(40, 2), 2);
  const Eigen::Vector3d start = ball->ClosestPoint(Eigen::Vector3d(30, 0, 30)).position;
  const DragTrace trace = DragOn(*ball, start, Eigen::Vector3d(0, 1, 0), 20.0);
  absl::StatusOr<LocatedDrag> located = LocateImportedDrag(trace, *ball, ProbeParameters{});
  ASSERT_TRUE(located.ok()) << located.status();
  const ProbeCommand& c = located->command;
  // On the surface, its normal there (outward: away from the centre), the drag tangent.
  const SurfacePoint there = ball->ClosestPoint(c.position);
  EXPECT_LT(there.distance, 1e-6);
  EXPECT_GT(c.normal.dot(there.normal), 0.9999);
  EXPECT_GT(c.normal.dot(c.position.normalized()), 0.99);
  EXPECT_NEAR(c.drag_direction.dot(c.normal), 0.0, 1e-9);
  EXPECT_GT(c.drag_direction.y(), 0.9);
  EXPECT_LT(FarthestFromSurface(trace, *ball).max_mm, 0.1);
  ExpectPlausible(trace, *ball, *located);
}

TEST(LocateImportedDragTest, ADragAboveTheSurfaceIsRefusedByTheSurfaceCheck) {
  std::unique_ptr<LoopSurface> plate = Surface(MakeGridPlate(200, 150, 6, 4), 2);
  DragTrace trace = DragOn(*plate, Eigen::Vector3d(-10, 0, 0), Eigen::Vector3d::UnitX(), 20.0);
  for (DragSample& s : trace.samples) s.position.z() += 15.0;  // another frame, 15 mm up
  absl::StatusOr<LocatedDrag> located = LocateImportedDrag(trace, *plate, ProbeParameters{});
  ASSERT_TRUE(located.ok()) << located.status();
  const SurfaceDistance farthest = FarthestFromSurface(trace, *plate);
  EXPECT_NEAR(farthest.max_mm, 15.0, 0.1);
  // The command checks alone measure from a site on the surface: they would pass it.
  EXPECT_THAT(CheckTraceAgainstCommand(trace, located->command, TraceLimits{}), IsOk());
  const absl::Status refused =
      CheckTraceNearSurface(farthest.max_mm, farthest.sample, TraceLimits{});
  EXPECT_THAT(refused, StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_EQ(PlausibilityCheckName(refused), "surface");
  EXPECT_NE(refused.message().find("from the object's surface; the limit is 10.0 mm"), std::string_view::npos)
      << refused;
}

TEST(LocateImportedDragTest, ATraceWithoutAForwardPassOrWithANonFinitePositionIsMalformed) {
  std::unique_ptr<LoopSurface> plate = Surface(MakeGridPlate(200, 150, 6, 4), 1);
  DragTrace only_reverse;
  only_reverse.samples.push_back({0.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 5), DragPhase::kReverse});
  EXPECT_THAT(LocateImportedDrag(only_reverse, *plate, ProbeParameters{}).status(),
              StatusIs(absl::StatusCode::kInvalidArgument));
  DragTrace not_finite;
  not_finite.samples.push_back({0.0, Eigen::Vector3d(NAN, 0, 0), Eigen::Vector3d(0, 0, 5), DragPhase::kForward});
  EXPECT_THAT(LocateImportedDrag(not_finite, *plate, ProbeParameters{}).status(),
              StatusIs(absl::StatusCode::kInvalidArgument));
}

}  // namespace
}  // namespace surfmap
