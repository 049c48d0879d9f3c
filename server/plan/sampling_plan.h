// The sampling plan: where a rig should probe next, as an explicit,
// serialisable state machine over sites (level, vertex) of a Loop surface
// (Lloyd & Pai 2001, section 4; METHOD.md section 4).
//
// Site states:
//   pending  -> issued (NextCommand)
//   issued   -> measured (RecordFit)
//            -> pending again (RecordFailure, up to max_retries times)
//            -> failed (RecordFailure after max_retries re-queues; keeps the reason)
//   pending  -> skipped (the budget is used up by measured sites, or Cancel)
// measured, failed and skipped are final. A vertex has at most one site.
//
// Which sites exist (options.mode):
//   kAdaptive    every vertex of coarsest_level; then, whenever both ends of an
//                edge of level k < max_level are measured and
//                TextureDistance(ends) > threshold, the vertex of level k+1
//                that splits the edge (SurfaceLevel::edge_child_vertex). Its
//                own edges at level k+1 are compared in turn as their ends get
//                measured (the other end may be an older vertex, measured under
//                its own site), and so on down to max_level.
//   kUniform     every vertex of coarsest_level, nothing more.
//   kUncertainty every vertex of coarsest_level; then, one at a time, the
//                unsampled vertex of level <= max_level with the highest
//                map uncertainty weighted by the local gradient (see
//                SamplingPlanOptions), scored on the map of the measured sites
//                with issued sites counted as pending (they lower uncertainty
//                near them). The choice is re-made after every change, so it
//                always uses the newest fits.
//
// Issue order (deterministic for a given seed and sequence of calls): lowest
// level first, then fewest failures (retries go behind fresh sites of their
// level), then a seeded shuffle of the vertices (site_order.h) that depends
// only on (seed, vertex).
//
// Several commands may be outstanding (several rigs); NextCommand returns
// nothing while all remaining work waits on outstanding measurements or the
// budget is held by issued sites.
//
// Save/restore: SaveJson() writes the complete state; Restore() validates it
// against the surface and continues exactly where it was: the same commands in
// the same order as an uninterrupted plan. Issued-but-unanswered commands stay
// issued after a restore (with their sequence numbers, so late answers are
// still accepted): deciding that a lease expired is the service's job, by
// calling RecordFailure.
//
// Not thread-safe: the caller serialises calls.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "server/estimate/texture.h"
#include "server/map/friction_map.h"
#include "server/mesh/loop_surface.h"
#include "server/plan/probe_command.h"
#include "server/plan/sampling_plan_options.h"

namespace surfmap {

enum class SiteState { kPending, kIssued, kMeasured, kFailed, kSkipped };
enum class SiteOrigin {
  kInitial,   // a vertex of the coarsest level
  kRefined,   // splits an edge whose ends differ (kAdaptive)
  kSelected,  // chosen by map uncertainty (kUncertainty)
};
std::string_view SiteStateName(SiteState state);  // "pending", "issued", ...
std::string_view SiteOriginName(SiteOrigin origin);

struct SiteRecord {
  SiteId site;
  SiteState state = SiteState::kPending;
  SiteOrigin origin = SiteOrigin::kInitial;
  int failures = 0;
  std::uint64_t sequence = 0;      // of the latest command issued for it (0 = never issued)
  std::string reason;              // why it failed or was skipped
  std::optional<TextureParams> fit;  // when measured
  // kRefined: the ends of the edge it splits and their texture distance.
  int parent_a = -1, parent_b = -1;
  double parent_distance = 0.0;
};

struct LevelProgress {
  int level = 0;
  int pending = 0, issued = 0, measured = 0, failed = 0, skipped = 0;
};

struct PlanProgress {
  std::vector<LevelProgress> levels;  // coarsest_level..max_level
  int pending = 0, issued = 0, measured = 0, failed = 0, skipped = 0;
  int budget_left = -1;  // sites that may still be issued; -1 = unlimited
  bool done = false;     // nothing pending or issued: the plan is complete
};

class SamplingPlan {
 public:
  // `levels` are the surface's levels 0..L (finest last), e.g.
  // PlanLevels(surface); they must outlive the plan. Errors
  // (INVALID_ARGUMENT): invalid options, max_level > L, null or inconsistent
  // levels (sizes of positions / normals / neighbours / edge children).
  static absl::StatusOr<SamplingPlan> Create(std::vector<const SurfaceLevel*> levels,
                                             const SamplingPlanOptions& options);

  // Continues a plan saved by SaveJson. Errors (INVALID_ARGUMENT, naming the
  // field or site): malformed JSON, another format or version, invalid
  // options, level/vertex/edge/triangle counts that differ from `levels`,
  // inconsistent sites.
  static absl::StatusOr<SamplingPlan> Restore(std::string_view json, std::vector<const SurfaceLevel*> levels);

  // The next probe command, or nothing when no site can be issued now.
  std::optional<ProbeCommand> NextCommand();

  // The fit for an issued command. Errors: NOT_FOUND for a sequence that is
  // not outstanding (unknown, answered, or superseded after a failure);
  // INVALID_ARGUMENT for a non-finite mu, negative mu_std or sigma, |k| >= 1.
  absl::Status RecordFit(std::uint64_t sequence, const TextureParams& fit);
  // Same, by site; FAILED_PRECONDITION when the site is not issued.
  absl::Status RecordFitForSite(SiteId site, const TextureParams& fit);
  // The command could not be measured (unreachable, trace rejected, lease
  // expired). Errors as for RecordFit.
  absl::Status RecordFailure(std::uint64_t sequence, std::string_view reason);
  absl::Status RecordFailureForSite(SiteId site, std::string_view reason);

  // Skips every pending site; answers to issued commands are still accepted
  // but create no new sites.
  void Cancel();

  PlanProgress Progress() const;
  bool IsComplete() const;

  std::string SaveJson() const;

  const SamplingPlanOptions& options() const { return options_; }
  // Every site, in vertex order.
  std::vector<SiteRecord> Sites() const;
  int SiteCount() const { return static_cast<int>(sites_.size()); }
  const SiteRecord* FindSite(int vertex) const;
  // The measured sites as map samples (finest-level vertex indices).
  std::vector<MapSample> MeasuredSamples() const;

 private:
  using PendingKey = std::tuple<int, int, std::uint64_t, int>;  // level, failures, shuffle key, vertex

  SamplingPlan() = default;
  static absl::Status ValidateFit(const TextureParams& fit);
  absl::Status Initialise();  // derived structures from levels_ and options_
  int NaturalLevel(int vertex) const;
  int VertexCount(int level) const { return static_cast<int>(levels_[level]->limit_positions.size()); }
  PendingKey KeyOf(const SiteRecord& r) const;
  bool BudgetUsedUpByMeasured() const;
  void AddSite(SiteRecord record);  // queues it, or skips it if the plan is cancelled or out of budget
  void SkipAllPending(std::string_view reason);
  absl::StatusOr<int> OutstandingVertex(std::uint64_t sequence) const;
  void CompareEdgesOf(int vertex);
  absl::Status RefreshSelection();  // kUncertainty
  // Keeps state_counts_ in step: -1 before a site changes state or leaves,
  // +1 after it changes or arrives.
  void CountSite(const SiteRecord& r, int delta);

  std::vector<const SurfaceLevel*> levels_;
  SamplingPlanOptions options_;
  // Per level k in [coarsest, max_level): (a << 32 | b) -> edge index, a < b.
  std::vector<std::unordered_map<std::uint64_t, int>> edge_index_;

  std::map<int, SiteRecord> sites_;  // by vertex
  std::set<PendingKey> pending_;
  std::map<std::uint64_t, int> outstanding_;  // sequence -> vertex
  std::uint64_t next_sequence_ = 1;
  bool cancelled_ = false;
  int measured_count_ = 0;
  // Sites per (level - coarsest_level, state): Progress() in O(levels), not
  // O(sites), since the service reports it with every accepted trace.
  std::vector<std::array<int, 5>> state_counts_;

  // kUncertainty: the map of the measured sites, rebuilt when they change.
  std::optional<FrictionMap> map_;
  bool map_stale_ = true;
};

// The levels of a Loop surface, as SamplingPlan::Create wants them.
inline std::vector<const SurfaceLevel*> PlanLevels(const LoopSurface& surface) {
  std::vector<const SurfaceLevel*> levels;
  for (int k = 0; k <= surface.max_level(); ++k) levels.push_back(&surface.level(k));
  return levels;
}

}  // namespace surfmap
