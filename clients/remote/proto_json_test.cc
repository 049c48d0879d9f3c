#include "clients/remote/proto_json.h"

#include <gtest/gtest.h>
#include "proto/surfmap/v1/surfmap.pb.h"

namespace surfmap::cli {
namespace {

namespace pb = ::surfmap::v1;

// Protobuf's own JSON writes int64 as "17"; ours writes 17, also nested and in
// repeated messages, and keeps Timestamps as strings.
TEST(ProtoToJsonTest, IdsAreNumbersEverywhere) {
  pb::ListJobsResponse response;
  pb::JobInfo* job = response.add_jobs();
  job->set_job_id(17);
  job->mutable_spec()->set_object_id(4);
  job->mutable_created()->set_seconds(1'795'000'000);
  const nlohmann::json j = ProtoToJson(response);
  ASSERT_TRUE(j["jobs"].is_array());
  ASSERT_EQ(j["jobs"].size(), 1u);
  EXPECT_TRUE(j["jobs"][0]["job_id"].is_number_integer());
  EXPECT_EQ(j["jobs"][0]["job_id"], 17);
  EXPECT_EQ(j["jobs"][0]["spec"]["object_id"], 4);
  EXPECT_TRUE(j["jobs"][0]["created"].is_string());
}

TEST(ProtoToJsonTest, ZeroIdsArePrintedAsNumbers) {
  pb::JobInfo job;
  const nlohmann::json j = ProtoToJson(job);
  EXPECT_EQ(j["job_id"], 0);
}

}  // namespace
}  // namespace surfmap::cli
