// The one place where internal absl::Status values become grpc::Status.
#pragma once

#include <grpcpp/support/status.h>
#include "absl/status/status.h"

namespace surfmap {

grpc::Status ToGrpcStatus(const absl::Status& status);

}  // namespace surfmap
