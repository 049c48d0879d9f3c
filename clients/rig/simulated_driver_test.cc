#include "clients/rig/simulated_driver.h"

#include <sstream>

#include <gtest/gtest.h>
#include "clients/sim/rig/scene.h"
#include "clients/sim/rig/simulated_rig.h"
#include "clients/rig/driver_protocol.h"

namespace surfmap::rig {
namespace {

std::unique_ptr<SimulatedRig> PlateRig() {
  absl::StatusOr<Scene> scene = LoadSceneByName("plate");
  EXPECT_TRUE(scene.ok()) << scene.status();
  auto rig = SimulatedRig::Create(*std::move(scene));
  EXPECT_TRUE(rig.ok()) << rig.status();
  return std::move(*rig);
}

TEST(SimulatedDriverTest, AnswersEachCommandWithTheSimulatedRigsTrace) {
  std::unique_ptr<SimulatedRig> rig = PlateRig();
  ProbeRequest reachable;
  reachable.command_id = 31;
  reachable.position = Eigen::Vector3d(0, 0, 0);
  ProbeRequest far = reachable;
  far.command_id = 32;
  far.position = Eigen::Vector3d(0, 0, 500);  // far above the plate
  std::istringstream in(FormatCommandMessage(reachable) + "\n\n" + FormatCommandMessage(far) + "\n");
  std::ostringstream out, errors;
  EXPECT_EQ(ServeSimulatedDriver(*rig, "sim plate", in, out, errors), 0) << errors.str();
  std::istringstream lines(out.str());
  std::string ready, first, second;
  std::getline(lines, ready);
  std::getline(lines, first);
  std::getline(lines, second);
  EXPECT_EQ(ParseReadyMessage(ready)->driver, "sim plate");
  auto trace = ParseDriverReply(first, 31);
  ASSERT_TRUE(trace.ok()) << trace.status();
  ASSERT_EQ(trace->type, DriverReply::Type::kTrace);
  // Exactly what the rig measures for this command (seeded by the command id).
  DragTrace direct = *rig->Execute(reachable);
  ASSERT_EQ(trace->trace.samples.size(), direct.samples.size());
  for (size_t i = 0; i < direct.samples.size(); ++i) {
    EXPECT_EQ(trace->trace.samples[i].position, direct.samples[i].position) << i;
    EXPECT_EQ(trace->trace.samples[i].force, direct.samples[i].force) << i;
  }
  auto failure = ParseDriverReply(second, 32);
  ASSERT_TRUE(failure.ok()) << failure.status();
  EXPECT_EQ(failure->type, DriverReply::Type::kFailure);
  EXPECT_EQ(failure->kind, surfmap::v1::FAILURE_KIND_UNREACHABLE);
  EXPECT_EQ(failure->reason.rfind("simulated rig: ", 0), 0u) << failure->reason;
}

TEST(SimulatedDriverTest, AMalformedCommandEndsItNamingTheLine) {
  std::unique_ptr<SimulatedRig> rig = PlateRig();
  std::istringstream in("\n{\"type\":\"command\"}\n");
  std::ostringstream out, errors;
  EXPECT_EQ(ServeSimulatedDriver(*rig, "sim", in, out, errors), 2);
  EXPECT_EQ(errors.str(), "surfmap-rig simulate-drag: stdin line 2: command: field 'protocol' must be an integer\n");
}

}  // namespace
}  // namespace surfmap::rig
