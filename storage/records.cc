#include "storage/records.h"

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace surfmap {

std::string_view JobStateName(JobState state) {
  switch (state) {
    case JobState::kRunning: return "running";
    case JobState::kPaused: return "paused";
    case JobState::kCompleted: return "completed";
    case JobState::kCancelled: return "cancelled";
  }
  return "unknown";
}

absl::StatusOr<JobState> ParseJobState(std::string_view name) {
  for (JobState s : {JobState::kRunning, JobState::kPaused, JobState::kCompleted,
                     JobState::kCancelled}) {
    if (JobStateName(s) == name) return s;
  }
  return absl::InvalidArgumentError(absl::StrCat("unknown job state '", std::string(name), "'"));
}

bool IsJobTransitionAllowed(JobState from, JobState to) {
  const bool from_open = from == JobState::kRunning || from == JobState::kPaused;
  return from_open && from != to;
}

std::string_view CommandStateName(CommandState state) {
  switch (state) {
    case CommandState::kPending: return "pending";
    case CommandState::kLeased: return "leased";
    case CommandState::kDone: return "done";
    case CommandState::kFailed: return "failed";
  }
  return "unknown";
}

absl::StatusOr<CommandState> ParseCommandState(std::string_view name) {
  for (CommandState s : {CommandState::kPending, CommandState::kLeased, CommandState::kDone,
                         CommandState::kFailed}) {
    if (CommandStateName(s) == name) return s;
  }
  return absl::InvalidArgumentError(absl::StrCat("unknown command state '", std::string(name), "'"));
}

}  // namespace surfmap
