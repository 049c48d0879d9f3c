// The sampling plan: where a rig should probe next, as an explicit,
// serialisable state machine over sites (level, vertex) of a Loop surface
// (Lloyd & Pai 2001, section 4; docs/method.md section 5).
//
// Site states:
//   pending  -> issued (NextCommand)
//   issued   -> measured (RecordLineSample, RecordFit)
//            -> pending again (RecordFailure, transient, up to max_retries times)
//            -> failed (RecordFailure after max_retries re-queues, or at once when
//               the rig reports the site unreachable; keeps the reason)
//   pending  -> skipped (the budget is used up by measured sites, or Cancel)
//   (new)    -> skipped at once when options.reach says a rig cannot reach it
//               (reason "unreachable: ...")
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
//   kBoundary    every vertex of coarsest_level (drag orientations varied
//                from site to site, or across a boundary the data so far
//                puts within reach); once none of them is pending, up to
//                `lookahead` sites at a time chosen by BoundarySelector
//                (boundary_selection.h) on the RegionMap of every measured
//                drag's pieces, until the budget (DefaultSampleBudget when
//                none is given) is used or no drag could remove more than
//                a resolution-sized error over its reach. Each is dragged
//                across the boundary it was placed for. The choices are
//                re-made when a fit or a failure comes in.
//
// Issue order (deterministic for a given seed and sequence of calls): lowest
// level first, then fewest failures (retries go behind fresh sites of their
// level), then a seeded shuffle of the vertices (site_order.h) that depends
// only on (seed, vertex). With options.issue_selected_by_gain, a boundary
// plan's fresh selected sites go first, in the order they were chosen.
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
#include "server/estimate/line_sample.h"
#include "server/map/region_map.h"
#include "server/plan/boundary_selection.h"
#include "server/plan/boundary_tracing.h"
#include "server/plan/probe_command.h"
#include "server/plan/sampling_plan_options.h"

namespace surfmap {

enum class SiteState { kPending, kIssued, kMeasured, kFailed, kSkipped };
// Why a command was not measured: kTransient (a trace rejected, a lease
// expired, a rig fault: the site is retried up to max_retries times) or
// kUnreachable (the rig cannot reach or drag there: final at once, and the
// boundary plan avoids its neighbourhood).
enum class FailureKind { kTransient, kUnreachable };
std::string_view FailureKindName(FailureKind kind);  // "transient", "unreachable"
std::optional<FailureKind> ParseFailureKind(std::string_view name);
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
  // kSelected sites of a boundary plan: 1 for the first choice of the
  // selection that added it (the largest gain), 2 for the next, ...; 0 for
  // other sites. SamplingPlanOptions::issue_selected_by_gain issues by it.
  int selection_rank = 0;
  std::uint64_t sequence = 0;      // of the latest command issued for it (0 = never issued)
  std::string reason;              // why it failed or was skipped
  std::optional<TextureParams> fit;  // when measured (SummaryTexture of the line sample)
  std::optional<LineSample> line;    // when measured: the drag's path and pieces
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
  // Commands issued and not yet answered.
  int OutstandingCount() const { return static_cast<int>(outstanding_.size()); }
  // Whether a command depends on the drags measured before it is issued:
  // kBoundary aims each drag across the map as it stands then and skips
  // coarse sites that earlier drags covered (coverage_skip_share). The
  // other modes' coarse passes are fixed in advance, so issuing them at
  // once loses nothing.
  bool DecidesAtIssue() const { return options_.mode == PlanMode::kBoundary; }

  // The drag measured for an issued command: its path and pieces
  // (LineSampleOf(fit)). The site's `fit` becomes SummaryTexture(line).
  // Errors: NOT_FOUND for a sequence that is not outstanding (unknown,
  // answered, or superseded after a failure); INVALID_ARGUMENT for a line
  // sample that LineSample::Validate rejects.
  absl::Status RecordLineSample(std::uint64_t sequence, const LineSample& line);
  absl::Status RecordLineSampleForSite(SiteId site, const LineSample& line);
  // The fit for an issued command, as one texture (the form before line
  // samples): a point sample at the site (PointLineSample). Errors: as
  // above; INVALID_ARGUMENT for a non-finite mu, negative mu_std or sigma,
  // |k| >= 1.
  absl::Status RecordFit(std::uint64_t sequence, const TextureParams& fit);
  // Same, by site; FAILED_PRECONDITION when the site is not issued.
  absl::Status RecordFitForSite(SiteId site, const TextureParams& fit);
  // The command could not be measured. Errors as for RecordFit.
  absl::Status RecordFailure(std::uint64_t sequence, std::string_view reason,
                             FailureKind kind = FailureKind::kTransient);
  absl::Status RecordFailureForSite(SiteId site, std::string_view reason,
                                    FailureKind kind = FailureKind::kTransient);

  // A drag recorded elsewhere and imported into the job (not the answer to a
  // command): its pieces join the map and the boundary plan's choices, but
  // it marks no site measured, counts against no budget and is not a point
  // sample of kUncertainty's map. `position` is where it lies on the surface
  // (the piece position of a line without a path). INVALID_ARGUMENT for a
  // line sample that LineSample::Validate rejects or a non-finite position.
  absl::Status RecordImportedLineSample(const LineSample& line, const Eigen::Vector3d& position);
  int ImportedCount() const { return static_cast<int>(imported_.size()); }

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
  // The pieces of every measured drag, drags in the order they were
  // measured (drag id = the site's vertex), then of every imported drag in
  // import order (drag id = FirstImportDrag() + import index), for a
  // RegionMap.
  std::vector<MapPiece> MeasuredPieces() const;
  // The drag id of the first imported drag: the plan's finest level's vertex
  // count, so that imports never share a site's id.
  int FirstImportDrag() const { return static_cast<int>(levels_.back()->limit_positions.size()); }
  const std::vector<int>& measured_order() const { return measured_order_; }
  // The sample budget in force: options.sample_budget, or for kBoundary
  // without one DefaultSampleBudget(levels); 0 = unlimited.
  int budget() const { return budget_; }

 private:
  using PendingKey = std::tuple<int, int, std::uint64_t, int>;  // level, failures, shuffle key, vertex

  SamplingPlan() = default;
  static absl::Status ValidateFit(const TextureParams& fit);
  absl::Status RecordMeasurement(std::uint64_t sequence, const TextureParams& fit, LineSample line);
  bool Reachable(int vertex) const;
  Eigen::Vector3d DirectionFor(const SiteRecord& r);
  absl::Status RefreshBoundarySelection();  // kBoundary
  // kBoundary with follow_boundaries: queues up to `slots` drags that follow
  // boundaries found so far (boundary_tracing.h); returns how many.
  // `rank` counts the selection's choices (SiteRecord::selection_rank).
  int FollowBoundaries(int slots, std::vector<char>& candidate, std::vector<Eigen::Vector3d>& covered, int& rank);
  // The drag that explores targets[k] (centred between it and its twin
  // across a narrow feature when one window holds both): vertex -1 when no
  // candidate vertex is near enough.
  DirectedCandidate DragForTarget(const std::vector<TraceTarget>& targets, std::size_t k,
                                  const std::vector<DragSegment>& drags, const std::vector<char>& candidate) const;
  // kBoundary with continuation_prior > 0: a drag for every open target
  // (boundary_tracing.h) with continuation_prior x ContinuationError as its
  // extra gain, to compete with the map's own choices.
  std::vector<DirectedCandidate> ContinuationDrags(const std::vector<DragSegment>& drags,
                                                   const std::vector<char>& candidate) const;
  BoundaryTraceOptions TraceOptions() const;
  // The data windows of measured and imported drags (their paths) and of
  // issued and queued ones (where their direction is known).
  std::vector<DragSegment> DragWindows() const;
  absl::Status EnsureRegionMap();
  absl::Status Initialise();  // derived structures from levels_ and options_
  int NaturalLevel(int vertex) const;
  int VertexCount(int level) const { return static_cast<int>(levels_[level]->limit_positions.size()); }
  PendingKey KeyOf(const SiteRecord& r) const;
  bool BudgetUsedUpByMeasured() const;
  void AddSite(SiteRecord record);  // queues it, or skips it if the plan is cancelled or out of budget
  void SkipAllPending(std::string_view reason);
  // kBoundary with coverage_skip_share (quiet_coverage_skip_share for a drag
  // that found no change): skips the pending coarsest-level sites the drag
  // just measured at `measured_vertex` passed near.
  void SkipCoveredBy(int measured_vertex);
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

  int budget_ = 0;                   // see budget()
  std::vector<int> measured_order_;  // vertices, in the order their drags were recorded
  struct ImportedDrag {
    LineSample line;
    Eigen::Vector3d position;
  };
  std::vector<ImportedDrag> imported_;  // in import order
  bool HasDrags() const { return measured_count_ > 0 || !imported_.empty(); }
  // Sites the rig reported unreachable: no site is selected within reach of them.
  std::vector<Eigen::Vector3d> no_go_;
  // kBoundary: the map of the measured drags' pieces and the selector on
  // the finest level; the directions chosen for the pending selected sites.
  std::optional<RegionMap> region_map_;
  bool region_map_stale_ = true;
  std::optional<BoundarySelector> selector_;
  std::map<int, Eigen::Vector3d> selected_direction_;
  // The drag direction of each outstanding command (by sequence); not saved:
  // after a restore those drags count as points in DragWindows.
  std::map<std::uint64_t, Eigen::Vector3d> issued_direction_;
};

// The default sample budget of a boundary plan: 1.5 x the number of control
// vertices (level 0). Every control vertex is measured once for coverage, and
// half as many drags again go to the boundaries they found: on the paper's
// bottle (82 control vertices, three patches) its threshold rule took 100.
int DefaultSampleBudget(const std::vector<const SurfaceLevel*>& levels);

// The levels of a Loop surface, as SamplingPlan::Create wants them.
inline std::vector<const SurfaceLevel*> PlanLevels(const LoopSurface& surface) {
  std::vector<const SurfaceLevel*> levels;
  for (int k = 0; k <= surface.max_level(); ++k) levels.push_back(&surface.level(k));
  return levels;
}

}  // namespace surfmap
