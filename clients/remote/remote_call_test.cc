#include "clients/remote/remote_call.h"

#include <gtest/gtest.h>

namespace surfmap::cli {
namespace {

TEST(FormatRpcErrorTest, NamesRpcCodeAndMessage) {
  EXPECT_EQ(FormatRpcError("GetJob", grpc::Status(grpc::StatusCode::NOT_FOUND, "job 7 does not exist")),
            "surfmap: GetJob: NOT_FOUND: job 7 does not exist");
  EXPECT_EQ(FormatRpcError("SubmitTrace", grpc::Status(grpc::StatusCode::UNAVAILABLE, "down"), "surfmap-rig"),
            "surfmap-rig: SubmitTrace: UNAVAILABLE: down");
}

TEST(StatusCodeNameTest, CanonicalNames) {
  EXPECT_EQ(StatusCodeName(grpc::StatusCode::INVALID_ARGUMENT), "INVALID_ARGUMENT");
  EXPECT_EQ(StatusCodeName(grpc::StatusCode::FAILED_PRECONDITION), "FAILED_PRECONDITION");
  EXPECT_EQ(StatusCodeName(grpc::StatusCode::RESOURCE_EXHAUSTED), "RESOURCE_EXHAUSTED");
  EXPECT_EQ(StatusCodeName(grpc::StatusCode::UNAUTHENTICATED), "UNAUTHENTICATED");
}

TEST(IsRetryableTest, OnlyTransportTrouble) {
  EXPECT_TRUE(IsRetryable(grpc::StatusCode::UNAVAILABLE));
  EXPECT_TRUE(IsRetryable(grpc::StatusCode::DEADLINE_EXCEEDED));
  EXPECT_FALSE(IsRetryable(grpc::StatusCode::INVALID_ARGUMENT));
  EXPECT_FALSE(IsRetryable(grpc::StatusCode::FAILED_PRECONDITION));
  EXPECT_FALSE(IsRetryable(grpc::StatusCode::PERMISSION_DENIED));
}

TEST(PrepareContextTest, SetsDeadlineOnlyWhenAsked) {
  RemoteOptions options;
  options.timeout_s = 5;
  grpc::ClientContext with;
  PrepareContext(options, &with);
  const auto left = with.deadline() - std::chrono::system_clock::now();
  EXPECT_GT(left, std::chrono::seconds(3));
  EXPECT_LE(left, std::chrono::seconds(5));
  grpc::ClientContext without;
  PrepareContext(options, &without, /*with_deadline=*/false);
  EXPECT_GT(without.deadline() - std::chrono::system_clock::now(), std::chrono::hours(24 * 365));
}

}  // namespace
}  // namespace surfmap::cli
