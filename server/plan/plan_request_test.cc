#include "server/plan/plan_request.h"

#include <string>

#include <gtest/gtest.h>

namespace surfmap {
namespace {

TEST(PlanRequestTest, CarriesEveryRequestedFieldAndKeepsThePlanDefaultsForTheRest) {
  PlanRequest r;
  r.mode = PlanMode::kUncertainty;
  r.coarsest_level = 1;
  r.finest_level = 4;
  r.threshold = 2.5;
  r.property = TextureProperty::kRoughness;
  r.budget = 77;
  r.max_retries = 5;
  r.probe.segment_length_mm = 12.0;
  r.probe.speed_mm_per_s = 6.0;
  r.probe.normal_force_n = 3.0;
  r.seed = 42;
  r.reach.max_angle_deg = 60.0;
  const SamplingPlanOptions o = PlanOptionsFor(r);
  EXPECT_EQ(o.mode, PlanMode::kUncertainty);
  EXPECT_EQ(o.coarsest_level, 1);
  EXPECT_EQ(o.max_level, 4);
  EXPECT_EQ(o.threshold, 2.5);
  EXPECT_EQ(o.distance.property, TextureProperty::kRoughness);
  EXPECT_EQ(o.sample_budget, 77);
  EXPECT_EQ(o.max_retries, 5);
  EXPECT_EQ(o.probe.segment_length_mm, 12.0);
  EXPECT_EQ(o.probe.speed_mm_per_s, 6.0);
  EXPECT_EQ(o.probe.normal_force_n, 3.0);
  EXPECT_EQ(o.seed, 42u);
  EXPECT_EQ(o.reach.max_angle_deg, 60.0);

  const SamplingPlanOptions defaults;
  EXPECT_EQ(o.lookahead, defaults.lookahead);
  EXPECT_EQ(o.gradient_weight, defaults.gradient_weight);
  EXPECT_EQ(o.distance.mu_scale, defaults.distance.mu_scale);
  std::string why;
  EXPECT_TRUE(o.IsValid(&why)) << why;
}

// One set of defaults: a request that names nothing gives exactly the plan's
// own defaults in every field it carries.
TEST(PlanRequestTest, AnEmptyRequestPlansWithTheDefaultPlanOptions) {
  const SamplingPlanOptions o = PlanOptionsFor(PlanRequest{});
  const SamplingPlanOptions defaults;
  EXPECT_EQ(o.mode, defaults.mode);
  EXPECT_EQ(o.coarsest_level, defaults.coarsest_level);
  EXPECT_EQ(o.max_level, defaults.max_level);
  EXPECT_EQ(o.threshold, defaults.threshold);
  EXPECT_EQ(o.distance.property, defaults.distance.property);
  EXPECT_EQ(o.sample_budget, defaults.sample_budget);
  EXPECT_EQ(o.max_retries, defaults.max_retries);
  EXPECT_EQ(o.probe.segment_length_mm, defaults.probe.segment_length_mm);
  EXPECT_EQ(o.probe.speed_mm_per_s, defaults.probe.speed_mm_per_s);
  EXPECT_EQ(o.probe.normal_force_n, defaults.probe.normal_force_n);
  EXPECT_EQ(o.seed, defaults.seed);
  EXPECT_EQ(o.reach.approach_direction.has_value(), defaults.reach.approach_direction.has_value());
  EXPECT_EQ(o.reach.max_angle_deg, defaults.reach.max_angle_deg);
  EXPECT_EQ(o.reach.support_point.has_value(), defaults.reach.support_point.has_value());
  EXPECT_EQ(o.reach.support_normal.has_value(), defaults.reach.support_normal.has_value());
  EXPECT_EQ(o.reach.support_clearance_mm, defaults.reach.support_clearance_mm);
}

}  // namespace
}  // namespace surfmap
