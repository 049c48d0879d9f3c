#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include "clients/mapsim/mapping_report.h"
#include "clients/mapsim/mapping_run.h"
#include "clients/sim/rig/scene.h"

namespace surfmap::mapsim {
namespace {

TEST(MappingRunTest, RejectsInvalidOptions) {
  MappingRunOptions o;
  o.mode = PlanMode::kUncertainty;  // needs a budget
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("sample_budget"), std::string::npos) << why;
  o.mode = PlanMode::kAdaptive;
  o.coarsest_level = 3;
  o.finest_level = 2;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("coarsest_level"), std::string::npos) << why;
  o = MappingRunOptions{};
  o.uniform_spread = true;  // a uniform design: with kBoundary it names the mismatch
  o.sample_budget = 10;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("uniform_spread"), std::string::npos) << why;
  o.mode = PlanMode::kUniform;
  EXPECT_TRUE(o.IsValid(&why)) << why;
  EXPECT_EQ(RunModeName(o), "uniform-spread");
  o.uniform_spread = false;
  EXPECT_EQ(RunModeName(o), "uniform");
  o = MappingRunOptions{};
  o.reach.max_angle_deg = 0.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("reach"), std::string::npos) << why;
}

}  // namespace
}  // namespace surfmap::mapsim
