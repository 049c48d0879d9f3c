// The planner on real Loop surfaces (OpenSubdiv refinement, server/mesh).
#include <cmath>

#include <gtest/gtest.h>
#include "server/mesh/loop_surface.h"
#include "server/mesh/primitive_meshes.h"
#include "server/plan/plan_test_support.h"
#include "server/plan/sampling_plan.h"

namespace surfmap {
namespace {

using testing::DriveToEnd;
using testing::SynthesiseFit;

TEST(LoopSurfacePlanTest, AdaptiveRefinesAlongTheBoundaryOfARefinedPlate) {
  auto mesh = MakeGridPlate(100.0, 60.0, 9, 5);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  for (auto& p : mesh->positions) p.x() += 3.0;  // boundary x = 0 off the vertices
  auto surface = LoopSurface::Create(*mesh, 3);
  ASSERT_TRUE(surface.ok()) << surface.status();
  SamplingPlanOptions o;
  o.max_level = 3;
  o.threshold = 1.0;
  auto plan = SamplingPlan::Create(PlanLevels(**surface), o);
  ASSERT_TRUE(plan.ok()) << plan.status();
  const SurfaceLevel& finest = (*surface)->finest();
  // Commands use the surface's own drag direction rule.
  {
    auto probe = SamplingPlan::Create(PlanLevels(**surface), o);
    while (auto c = probe->NextCommand()) {
      EXPECT_TRUE(c->drag_direction.isApprox((*surface)->DefaultDragDirection(c->site.vertex), 1e-9))
          << "vertex " << c->site.vertex;
      EXPECT_TRUE(c->position.isApprox(finest.limit_positions[c->site.vertex]));
    }
  }
  DriveToEnd(*plan, finest, 2);
  ASSERT_TRUE(plan->IsComplete());
  int refined = 0;
  for (const SiteRecord& r : plan->Sites()) {
    if (r.origin != SiteOrigin::kRefined) continue;
    ++refined;
    const double parent_width = (100.0 / 9.0) / std::pow(2.0, r.site.level - 1);
    EXPECT_LE(std::abs(finest.limit_positions[r.site.vertex].x()), parent_width)
        << "vertex " << r.site.vertex << " level " << r.site.level;
  }
  EXPECT_GE(refined, 3 * 11);
}

TEST(LoopSurfacePlanTest, UncertaintyModeRunsOnACurvedSurfaceAndRestores) {
  auto sphere = MakeIcosphere(40.0, 1);  // 42 control vertices
  ASSERT_TRUE(sphere.ok());
  auto surface = LoopSurface::Create(*sphere, 3);
  ASSERT_TRUE(surface.ok()) << surface.status();
  SamplingPlanOptions o;
  o.mode = PlanMode::kUncertainty;
  o.max_level = 2;
  o.sample_budget = 70;
  auto plan = SamplingPlan::Create(PlanLevels(**surface), o);
  ASSERT_TRUE(plan.ok()) << plan.status();
  std::deque<ProbeCommand> queue;
  testing::Drive(*plan, (*surface)->finest(), 2, queue, 50);
  auto restored = SamplingPlan::Restore(plan->SaveJson(), PlanLevels(**surface));
  ASSERT_TRUE(restored.ok()) << restored.status();
  testing::Drive(*restored, (*surface)->finest(), 2, queue);
  EXPECT_TRUE(restored->IsComplete());
  EXPECT_EQ(restored->Progress().measured, 70);
  for (const SiteRecord& r : restored->Sites()) {
    EXPECT_LE(r.site.vertex, static_cast<int>((*surface)->level(2).limit_positions.size()));
  }
}

}  // namespace
}  // namespace surfmap
