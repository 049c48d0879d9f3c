// Plan journal: one answer to a command (a fit or a failure) as a small
// record, so the service can store a plan as a checkpoint (SaveJson) plus the
// answers that followed it, instead of rewriting the whole plan per trace.
//
// Replaying the entries after the checkpoint, in order, with the service's
// command drain after each (the plan issues every site it can after every
// answer), reproduces the plan exactly: the plan is a deterministic state
// machine and the entries carry the fits with round-trip precision.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "server/estimate/line_sample.h"
#include "server/estimate/texture.h"
#include "server/plan/sampling_plan.h"

namespace surfmap {

struct PlanJournalEntry {
  enum class Kind { kFit, kFailure, kImport };
  Kind kind = Kind::kFit;
  std::uint64_t sequence = 0;  // the answered command's plan sequence
  // kFit: the drag as a line sample (path and pieces: what the plan and the
  // map need, LineSampleOf(fit)); entries written before line samples carry
  // only `fit`, replayed as RecordFit.
  std::optional<LineSample> line;
  TextureParams fit;           // kFit without a line
  std::string reason;          // kFailure
  // kImport: an imported drag (sequence 0, `line` set) and where it lies on
  // the surface (SamplingPlan::RecordImportedLineSample).
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  FailureKind failure = FailureKind::kTransient;  // kFailure
  // How many commands the service issued right after applying this answer
  // (it keeps only a few issued ahead of the rigs, command_lookahead.h). A
  // replay issues exactly as many. Absent in entries written before the
  // lookahead: those were followed by every command the plan could issue.
  std::optional<int> issued_after;
};

// {"op":"fit","sequence":n,"fit":{"mu","mu_std","reflection","sigma"}} (the
// summary texture) plus "line":{line_sample_json.h} when it has a line, or
// {"op":"failure","sequence":n,"reason":"..."} plus "kind":"unreachable" for
// an unreachable site, or {"op":"import","sequence":0,"line":{...},
// "position":[x,y,z]} for an imported drag; each with "issued":n when
// issued_after is set. A 20 mm drag's line is ~17 path points and a few
// pieces: ~1-2 KB.
std::string PlanJournalEntryToJson(const PlanJournalEntry &entry);
// INVALID_ARGUMENT naming the field for malformed text.
absl::StatusOr<PlanJournalEntry> PlanJournalEntryFromJson(std::string_view text);

// RecordLineSample (or RecordFit without a line) / RecordFailure on `plan`;
// their errors.
absl::Status ApplyPlanJournalEntry(const PlanJournalEntry &entry, SamplingPlan &plan);

}  // namespace surfmap
