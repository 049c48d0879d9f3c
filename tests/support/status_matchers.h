// gtest helpers for absl and gRPC statuses: failures print the status text.
#pragma once

#include "gtest/gtest.h"
#include "tests/support/surfmap_client.h"

#define ITEST_ASSERT_OK(expr)                                        \
  do {                                                               \
    const auto& _itest_status = (expr);                              \
    ASSERT_TRUE(_itest_status.ok()) << #expr << ": " << _itest_status; \
  } while (0)

#define ITEST_EXPECT_OK(expr)                                        \
  do {                                                               \
    const auto& _itest_status = (expr);                              \
    EXPECT_TRUE(_itest_status.ok()) << #expr << ": " << _itest_status; \
  } while (0)

// For absl::StatusOr<T>: assigns the value or fails the test.
#define ITEST_ASSERT_OK_AND_ASSIGN(lhs, expr)                                   \
  auto lhs##_or = (expr);                                                       \
  ASSERT_TRUE(lhs##_or.ok()) << #expr << ": " << lhs##_or.status();             \
  auto lhs = std::move(*lhs##_or)

#define GRPC_ASSERT_OK(expr)                                                     \
  do {                                                                           \
    const grpc::Status _itest_grpc = (expr);                                     \
    ASSERT_TRUE(_itest_grpc.ok()) << #expr << ": " << ::surfmap::itest::Describe(_itest_grpc); \
  } while (0)

#define GRPC_EXPECT_OK(expr)                                                     \
  do {                                                                           \
    const grpc::Status _itest_grpc = (expr);                                     \
    EXPECT_TRUE(_itest_grpc.ok()) << #expr << ": " << ::surfmap::itest::Describe(_itest_grpc); \
  } while (0)
