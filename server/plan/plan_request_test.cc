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

}  // namespace
}  // namespace surfmap
