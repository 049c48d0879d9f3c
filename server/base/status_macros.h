// Early returns for absl::Status / absl::StatusOr, one definition for every
// module (the layer below all others: header only, abseil only).
#pragma once

#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

// Returns the status of `expr` from the enclosing function when it is not OK.
#define SURFMAP_RETURN_IF_ERROR(expr)         \
  do {                                        \
    if (absl::Status _surfmap_status = (expr); \
        !_surfmap_status.ok()) {              \
      return _surfmap_status;                 \
    }                                         \
  } while (0)

#define SURFMAP_STATUS_CONCAT_INNER(a, b) a##b
#define SURFMAP_STATUS_CONCAT(a, b) SURFMAP_STATUS_CONCAT_INNER(a, b)

// `lhs = std::move(*expr)` for an OK StatusOr; returns its status otherwise.
// `lhs` may declare a variable: SURFMAP_ASSIGN_OR_RETURN(auto x, F());
#define SURFMAP_ASSIGN_OR_RETURN(lhs, expr) \
  SURFMAP_ASSIGN_OR_RETURN_IMPL(SURFMAP_STATUS_CONCAT(_surfmap_status_or_, __LINE__), lhs, expr)
#define SURFMAP_ASSIGN_OR_RETURN_IMPL(tmp, lhs, expr) \
  auto tmp = (expr);                                  \
  if (!tmp.ok()) return tmp.status();                 \
  lhs = std::move(*tmp)
