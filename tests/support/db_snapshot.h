// A read-only look at a surfmapd database from outside the server (sqlite3 C
// API, SQLITE_OPEN_READONLY), to check that rejected requests changed nothing.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "absl/status/statusor.h"

namespace surfmap::itest {

struct DbSnapshot {
  std::map<std::string, std::int64_t> row_counts;   // per table (sqlite_% tables excluded)
  // Compact digest of the rows whose content a bad request might corrupt
  // without adding rows: command states/owners/attempts and job states.
  std::string command_and_job_states;

  // Empty when equal; otherwise says what differs ("traces: 3 -> 4 rows").
  std::string DifferenceTo(const DbSnapshot& after) const;
};

absl::StatusOr<DbSnapshot> TakeDbSnapshot(const std::string& db_path);

}  // namespace surfmap::itest
