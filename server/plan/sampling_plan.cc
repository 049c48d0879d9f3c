#include "server/plan/sampling_plan.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "absl/strings/str_cat.h"
#include "server/geometry/segment_distance.h"
#include "server/plan/boundary_tracing.h"
#include "server/plan/drag_direction.h"
#include "server/plan/site_order.h"

namespace surfmap {
namespace {

std::uint64_t EdgeKey(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
}

}  // namespace

absl::Status SamplingPlan::ValidateFit(const TextureParams& fit) {
  if (!std::isfinite(fit.mu)) return absl::InvalidArgumentError(absl::StrCat("fit: mu is ", fit.mu));
  if (!std::isfinite(fit.mu_std) || fit.mu_std < 0) {
    return absl::InvalidArgumentError(absl::StrCat("fit: mu_std is ", fit.mu_std, " (must be finite and >= 0)"));
  }
  if (!std::isfinite(fit.sigma) || fit.sigma < 0) {
    return absl::InvalidArgumentError(absl::StrCat("fit: sigma is ", fit.sigma, " (must be finite and >= 0)"));
  }
  for (size_t j = 0; j < fit.reflection.size(); ++j) {
    if (!std::isfinite(fit.reflection[j]) || std::abs(fit.reflection[j]) >= 1.0) {
      return absl::InvalidArgumentError(absl::StrCat("fit: reflection coefficient k", j + 1, " is ",
                                                     fit.reflection[j], " (a stationary model needs |k| < 1)"));
    }
  }
  return absl::OkStatus();
}

namespace {

constexpr char kBudgetUsedUp[] = "sample budget used up";
constexpr char kCancelled[] = "cancelled";

}  // namespace

std::string_view FailureKindName(FailureKind kind) {
  return kind == FailureKind::kUnreachable ? "unreachable" : "transient";
}

std::optional<FailureKind> ParseFailureKind(std::string_view name) {
  for (FailureKind k : {FailureKind::kTransient, FailureKind::kUnreachable}) {
    if (FailureKindName(k) == name) return k;
  }
  return std::nullopt;
}

int DefaultSampleBudget(const std::vector<const SurfaceLevel*>& levels) {
  if (levels.empty() || levels.front() == nullptr) return 0;
  return static_cast<int>(1.5 * static_cast<double>(levels.front()->limit_positions.size()));
}

std::string_view SiteStateName(SiteState state) {
  switch (state) {
    case SiteState::kPending:
      return "pending";
    case SiteState::kIssued:
      return "issued";
    case SiteState::kMeasured:
      return "measured";
    case SiteState::kFailed:
      return "failed";
    case SiteState::kSkipped:
      return "skipped";
  }
  return "pending";
}

std::string_view SiteOriginName(SiteOrigin origin) {
  switch (origin) {
    case SiteOrigin::kInitial:
      return "initial";
    case SiteOrigin::kRefined:
      return "refined";
    case SiteOrigin::kSelected:
      return "selected";
  }
  return "initial";
}

absl::Status SamplingPlan::Initialise() {
  std::string why;
  if (!options_.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("SamplingPlanOptions: ", why));
  if (levels_.empty()) return absl::InvalidArgumentError("SamplingPlan: the surface has no levels");
  const int top = static_cast<int>(levels_.size()) - 1;
  if (options_.max_level > top) {
    return absl::InvalidArgumentError(absl::StrCat("SamplingPlanOptions: max_level ", options_.max_level,
                                                   " is finer than the surface's finest level ", top));
  }
  for (int k = 0; k <= top; ++k) {
    const SurfaceLevel* level = levels_[k];
    if (level == nullptr) return absl::InvalidArgumentError(absl::StrCat("SamplingPlan: level ", k, " is null"));
    const size_t nv = level->limit_positions.size();
    if (nv == 0) return absl::InvalidArgumentError(absl::StrCat("SamplingPlan: level ", k, " has no vertices"));
    if (level->limit_normals.size() != nv || level->neighbors.size() != nv) {
      return absl::InvalidArgumentError(absl::StrCat("SamplingPlan: level ", k, " has ", nv, " limit positions, ",
                                                     level->limit_normals.size(), " normals and ",
                                                     level->neighbors.size(), " neighbour rows"));
    }
    if (k > 0 && nv < levels_[k - 1]->limit_positions.size()) {
      return absl::InvalidArgumentError(
          absl::StrCat("SamplingPlan: level ", k, " has fewer vertices than level ", k - 1));
    }
  }
  budget_ = options_.sample_budget > 0 ? options_.sample_budget
            : options_.mode == PlanMode::kBoundary ? DefaultSampleBudget(levels_)
                                                   : 0;
  if (options_.mode == PlanMode::kBoundary) {
    selector_.emplace(*levels_.back(), options_.probe.segment_length_mm,
                      options_.boundary_cost_follows_property ? options_.distance : BoundarySelector::Friction(),
                      options_.misclassification_cost, options_.material_mu_risk,
                      options_.small_material_weight_max, options_.far_gain_expected);
  }
  state_counts_.assign(options_.max_level - options_.coarsest_level + 1, {});
  edge_index_.assign(options_.max_level - options_.coarsest_level, {});
  for (int k = options_.coarsest_level; k < options_.max_level; ++k) {
    const SurfaceLevel& level = *levels_[k];
    const int nv = VertexCount(k), nv_next = VertexCount(k + 1);
    if (level.edge_child_vertex.size() != level.edges.size()) {
      return absl::InvalidArgumentError(absl::StrCat("SamplingPlan: level ", k, " has ", level.edges.size(),
                                                     " edges but ", level.edge_child_vertex.size(),
                                                     " edge children"));
    }
    auto& index = edge_index_[k - options_.coarsest_level];
    index.reserve(level.edges.size());
    for (int e = 0; e < static_cast<int>(level.edges.size()); ++e) {
      const auto [a, b] = level.edges[e];
      const int child = level.edge_child_vertex[e];
      if (a < 0 || b < 0 || a >= nv || b >= nv || child < nv || child >= nv_next) {
        return absl::InvalidArgumentError(absl::StrCat("SamplingPlan: level ", k, " edge ", e, " (", a, ", ", b,
                                                       ") or its child vertex ", child, " is out of range"));
      }
      index[EdgeKey(a, b)] = e;
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<SamplingPlan> SamplingPlan::Create(std::vector<const SurfaceLevel*> levels,
                                                  const SamplingPlanOptions& options) {
  SamplingPlan plan;
  plan.levels_ = std::move(levels);
  plan.options_ = options;
  if (auto status = plan.Initialise(); !status.ok()) return status;
  const SurfaceLevel& finest = *plan.levels_.back();
  for (int v = 0; v < plan.VertexCount(options.coarsest_level); ++v) {
    SiteRecord r;
    r.site = {options.coarsest_level, v};
    if (auto why = UnreachableReason(options.reach, finest.limit_positions[v], finest.limit_normals[v])) {
      r.state = SiteState::kSkipped;
      r.reason = *why;
    }
    plan.AddSite(std::move(r));
  }
  if (auto status = plan.RefreshSelection(); !status.ok()) return status;
  return plan;
}

int SamplingPlan::NaturalLevel(int vertex) const {
  for (int k = 0; k < static_cast<int>(levels_.size()); ++k) {
    if (vertex < VertexCount(k)) return k;
  }
  return static_cast<int>(levels_.size());
}

SamplingPlan::PendingKey SamplingPlan::KeyOf(const SiteRecord& r) const {
  if (options_.issue_selected_by_gain && r.origin == SiteOrigin::kSelected && r.failures == 0 &&
      r.selection_rank > 0) {
    // Ahead of every other pending site: a selection is made only once no
    // coarsest-level site waits (RefreshBoundarySelection), and retries go
    // behind fresh sites.
    return {options_.coarsest_level, 0, static_cast<std::uint64_t>(r.selection_rank), r.site.vertex};
  }
  return {r.site.level, r.failures, SiteShuffleKey(options_.seed, r.site.vertex), r.site.vertex};
}

bool SamplingPlan::BudgetUsedUpByMeasured() const { return budget_ > 0 && measured_count_ >= budget_; }

bool SamplingPlan::Reachable(int vertex) const {
  if (!options_.reach.constrained()) return true;
  const SurfaceLevel& finest = *levels_.back();
  return !UnreachableReason(options_.reach, finest.limit_positions[vertex], finest.limit_normals[vertex]).has_value();
}

void SamplingPlan::AddSite(SiteRecord record) {
  if (record.state == SiteState::kPending) {
    if (cancelled_) {
      record.state = SiteState::kSkipped;
      record.reason = kCancelled;
    } else if (BudgetUsedUpByMeasured()) {
      record.state = SiteState::kSkipped;
      record.reason = kBudgetUsedUp;
    } else {
      pending_.insert(KeyOf(record));
    }
  }
  const int v = record.site.vertex;
  CountSite(record, +1);
  sites_.emplace(v, std::move(record));
}

void SamplingPlan::CountSite(const SiteRecord& r, int delta) {
  state_counts_[r.site.level - options_.coarsest_level][static_cast<int>(r.state)] += delta;
}

void SamplingPlan::SkipAllPending(std::string_view reason) {
  for (const auto& key : pending_) {
    SiteRecord& r = sites_.at(std::get<3>(key));
    CountSite(r, -1);
    r.state = SiteState::kSkipped;
    CountSite(r, +1);
    r.reason = std::string(reason);
  }
  pending_.clear();
}

void SamplingPlan::SkipCoveredBy(int measured_vertex) {
  const LineSample& line = *sites_.at(measured_vertex).line;
  const SurfaceLevel& finest = *levels_.back();
  // A drag that found no change settles its surroundings farther.
  const bool quiet = line.pieces.size() <= 1;
  const double share = quiet ? std::max(options_.coverage_skip_share, options_.quiet_coverage_skip_share)
                             : options_.coverage_skip_share;
  const double skip_mm = share * options_.probe.segment_length_mm;
  for (auto it = pending_.begin(); it != pending_.end();) {
    SiteRecord& r = sites_.at(std::get<3>(*it));
    bool covered = false;
    for (size_t i = 0; !covered && i + 1 < line.path_points.size(); ++i) {
      covered = DistanceToSegment(finest.limit_positions[r.site.vertex], line.path_points[i],
                                  line.path_points[i + 1]) <= skip_mm;
    }
    if (r.origin != SiteOrigin::kInitial || r.failures > 0 || !covered) {
      ++it;
      continue;
    }
    CountSite(r, -1);
    r.state = SiteState::kSkipped;
    CountSite(r, +1);
    r.reason = absl::StrCat("covered by the drag at vertex ", measured_vertex);
    it = pending_.erase(it);
  }
}

std::optional<ProbeCommand> SamplingPlan::NextCommand() {
  if (pending_.empty()) return std::nullopt;
  if (budget_ > 0 && measured_count_ + static_cast<int>(outstanding_.size()) >= budget_) {
    return std::nullopt;  // the rest of the budget is held by issued sites
  }
  const PendingKey key = *pending_.begin();
  pending_.erase(pending_.begin());
  SiteRecord& r = sites_.at(std::get<3>(key));
  CountSite(r, -1);
  r.state = SiteState::kIssued;
  CountSite(r, +1);
  r.sequence = next_sequence_++;
  outstanding_[r.sequence] = r.site.vertex;

  const SurfaceLevel& finest = *levels_.back();
  ProbeCommand command;
  command.sequence = r.sequence;
  command.site = r.site;
  command.attempt = r.failures + 1;
  command.position = finest.limit_positions[r.site.vertex];
  const Eigen::Vector3d& n = finest.limit_normals[r.site.vertex];
  command.normal = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::UnitZ();
  command.drag_direction = DirectionFor(r);
  issued_direction_[r.sequence] = command.drag_direction;
  command.probe = options_.probe;
  // A selection error can only come from the map rejecting a fit, and every
  // fit was validated by RecordFit; the command is valid either way.
  (void)RefreshSelection();
  return command;
}

absl::StatusOr<int> SamplingPlan::OutstandingVertex(std::uint64_t sequence) const {
  auto it = outstanding_.find(sequence);
  if (it == outstanding_.end()) {
    return absl::NotFoundError(absl::StrCat("command ", sequence,
                                            " is not outstanding (unknown, already answered, or superseded)"));
  }
  return it->second;
}

absl::Status SamplingPlan::RecordFit(std::uint64_t sequence, const TextureParams& fit) {
  if (auto status = ValidateFit(fit); !status.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("command ", sequence, ": ", status.message()));
  }
  auto vertex = OutstandingVertex(sequence);
  if (!vertex.ok()) return vertex.status();
  return RecordMeasurement(sequence, fit, PointLineSample(levels_.back()->limit_positions[*vertex], fit));
}

absl::Status SamplingPlan::RecordLineSample(std::uint64_t sequence, const LineSample& line) {
  if (auto status = line.Validate(); !status.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("command ", sequence, ": ", status.message()));
  }
  auto vertex = OutstandingVertex(sequence);
  if (!vertex.ok()) return vertex.status();
  return RecordMeasurement(sequence, SummaryTexture(line), line);
}

absl::Status SamplingPlan::RecordLineSampleForSite(SiteId site, const LineSample& line) {
  const SiteRecord* r = FindSite(site.vertex);
  if (r == nullptr || r->site.level != site.level || r->state != SiteState::kIssued) {
    return absl::FailedPreconditionError(
        absl::StrCat("site (level ", site.level, ", vertex ", site.vertex, ") is not issued"));
  }
  return RecordLineSample(r->sequence, line);
}

absl::Status SamplingPlan::RecordMeasurement(std::uint64_t sequence, const TextureParams& fit, LineSample line) {
  auto vertex = OutstandingVertex(sequence);
  if (!vertex.ok()) return vertex.status();
  outstanding_.erase(sequence);
  issued_direction_.erase(sequence);
  SiteRecord& r = sites_.at(*vertex);
  CountSite(r, -1);
  r.state = SiteState::kMeasured;
  CountSite(r, +1);
  r.fit = fit;
  r.line = std::move(line);
  r.reason.clear();
  ++measured_count_;
  measured_order_.push_back(*vertex);
  map_stale_ = true;
  region_map_stale_ = true;
  if (BudgetUsedUpByMeasured()) SkipAllPending(kBudgetUsedUp);
  if (options_.mode == PlanMode::kBoundary &&
      (options_.coverage_skip_share > 0.0 || options_.quiet_coverage_skip_share > 0.0)) {
    SkipCoveredBy(*vertex);
  }
  if (options_.mode == PlanMode::kAdaptive) CompareEdgesOf(*vertex);
  if (auto status = RefreshSelection(); !status.ok()) return status;
  return RefreshBoundarySelection();
}

absl::Status SamplingPlan::RecordFitForSite(SiteId site, const TextureParams& fit) {
  const SiteRecord* r = FindSite(site.vertex);
  if (r == nullptr || r->site.level != site.level || r->state != SiteState::kIssued) {
    return absl::FailedPreconditionError(
        absl::StrCat("site (level ", site.level, ", vertex ", site.vertex, ") is not issued"));
  }
  return RecordFit(r->sequence, fit);
}

absl::Status SamplingPlan::RecordFailure(std::uint64_t sequence, std::string_view reason, FailureKind kind) {
  auto vertex = OutstandingVertex(sequence);
  if (!vertex.ok()) return vertex.status();
  outstanding_.erase(sequence);
  issued_direction_.erase(sequence);
  SiteRecord& r = sites_.at(*vertex);
  CountSite(r, -1);
  ++r.failures;
  if (kind == FailureKind::kUnreachable) {
    // The rig cannot reach or drag here: retrying is pointless, and so is
    // selecting another site next to it.
    r.state = SiteState::kFailed;
    r.reason = absl::StrCat("unreachable: ", std::string(reason));
    no_go_.push_back(levels_.back()->limit_positions[r.site.vertex]);
  } else if (r.failures > options_.max_retries) {
    r.state = SiteState::kFailed;
    r.reason = absl::StrCat(std::string(reason), " (failed ", r.failures, " time", r.failures == 1 ? "" : "s", ")");
  } else {
    r.state = SiteState::kPending;
    r.reason = std::string(reason);  // the latest failure, kept for inspection
    if (cancelled_) {
      r.state = SiteState::kSkipped;
      r.reason = kCancelled;
    } else if (BudgetUsedUpByMeasured()) {
      r.state = SiteState::kSkipped;
      r.reason = kBudgetUsedUp;
    } else {
      pending_.insert(KeyOf(r));
    }
  }
  CountSite(r, +1);
  if (auto status = RefreshSelection(); !status.ok()) return status;
  return RefreshBoundarySelection();
}

absl::Status SamplingPlan::RecordFailureForSite(SiteId site, std::string_view reason, FailureKind kind) {
  const SiteRecord* r = FindSite(site.vertex);
  if (r == nullptr || r->site.level != site.level || r->state != SiteState::kIssued) {
    return absl::FailedPreconditionError(
        absl::StrCat("site (level ", site.level, ", vertex ", site.vertex, ") is not issued"));
  }
  return RecordFailure(r->sequence, reason, kind);
}

void SamplingPlan::Cancel() {
  cancelled_ = true;
  SkipAllPending(kCancelled);
}

void SamplingPlan::CompareEdgesOf(int vertex) {
  const SiteRecord& r = sites_.at(vertex);
  for (int k = r.site.level; k < options_.max_level; ++k) {
    const SurfaceLevel& level = *levels_[k];
    for (int u : level.neighbors[vertex]) {
      auto it = sites_.find(u);
      if (it == sites_.end() || it->second.state != SiteState::kMeasured) continue;
      const double d = TextureDistance(*r.fit, *it->second.fit, options_.distance);
      if (!(d > options_.threshold)) continue;
      const auto& index = edge_index_[k - options_.coarsest_level];
      auto e = index.find(EdgeKey(vertex, u));
      if (e == index.end()) continue;  // a neighbour row without an edge: nothing to split
      const int child = level.edge_child_vertex[e->second];
      if (sites_.count(child)) continue;
      SiteRecord refined;
      refined.site = {k + 1, child};
      refined.origin = SiteOrigin::kRefined;
      refined.parent_a = std::min(vertex, u);
      refined.parent_b = std::max(vertex, u);
      refined.parent_distance = d;
      if (!Reachable(child)) {
        refined.state = SiteState::kSkipped;
        refined.reason = *UnreachableReason(options_.reach, levels_.back()->limit_positions[child],
                                            levels_.back()->limit_normals[child]);
      }
      AddSite(std::move(refined));
    }
  }
}

absl::Status SamplingPlan::RefreshSelection() {
  if (options_.mode != PlanMode::kUncertainty || cancelled_) return absl::OkStatus();
  // Re-make the choice of a fresh selected site with the newest information.
  for (auto it = pending_.begin(); it != pending_.end();) {
    const int v = std::get<3>(*it);
    const SiteRecord& r = sites_.at(v);
    if (r.origin == SiteOrigin::kSelected && r.failures == 0) {
      CountSite(r, -1);
      sites_.erase(v);
      it = pending_.erase(it);
    } else {
      ++it;
    }
  }
  if (!pending_.empty() || measured_count_ == 0) return absl::OkStatus();
  if (measured_count_ + static_cast<int>(outstanding_.size()) >= budget_) return absl::OkStatus();
  if (!map_) {
    auto map = FrictionMap::Create(*levels_.back(), options_.map);
    if (!map.ok()) return map.status();
    map_ = std::move(*map);
  }
  if (map_stale_) {
    if (auto status = map_->SetSamples(MeasuredSamples()); !status.ok()) return status;
    map_stale_ = false;
  }
  std::vector<int> issued;
  for (const auto& [sequence, v] : outstanding_) issued.push_back(v);
  std::sort(issued.begin(), issued.end());
  if (auto status = map_->SetPendingVertices(std::move(issued)); !status.ok()) return status;

  // g * d is about the jump across the gap between two differing samples
  // whatever the gap's width, so a steep but narrow gap is not preferred over
  // a wide one (which would refine a few gaps depth-first).
  const double inv_s = 1.0 / std::max(map_->prior_mu_std(), 1e-12);
  const auto& mu_std = map_->mu_std();
  const auto& gradient = map_->mu_gradient();
  const auto& distance = map_->distance_to_sample_mm();
  int best = -1;
  double best_score = -1.0;
  std::uint64_t best_key = 0;
  const int candidates = VertexCount(options_.max_level);
  for (int v = 0; v < candidates; ++v) {
    if (sites_.count(v) || !Reachable(v)) continue;
    const double jump = std::isfinite(distance[v]) ? gradient[v] * distance[v] * inv_s : 0.0;
    const double score = mu_std[v] * (1.0 + options_.gradient_weight * jump);
    const std::uint64_t key = SiteShuffleKey(options_.seed, v);
    if (score > best_score || (score == best_score && key < best_key)) {
      best = v;
      best_score = score;
      best_key = key;
    }
  }
  if (best < 0 || best_score < options_.min_uncertainty_score) return absl::OkStatus();
  SiteRecord r;
  r.site = {std::max(options_.coarsest_level, NaturalLevel(best)), best};
  r.origin = SiteOrigin::kSelected;
  AddSite(std::move(r));
  return absl::OkStatus();
}

PlanProgress SamplingPlan::Progress() const {
  PlanProgress p;
  for (int k = options_.coarsest_level; k <= options_.max_level; ++k) {
    const std::array<int, 5>& n = state_counts_[k - options_.coarsest_level];
    LevelProgress l{.level = k};
    l.pending = n[static_cast<int>(SiteState::kPending)];
    l.issued = n[static_cast<int>(SiteState::kIssued)];
    l.measured = n[static_cast<int>(SiteState::kMeasured)];
    l.failed = n[static_cast<int>(SiteState::kFailed)];
    l.skipped = n[static_cast<int>(SiteState::kSkipped)];
    p.pending += l.pending, p.issued += l.issued, p.measured += l.measured;
    p.failed += l.failed, p.skipped += l.skipped;
    p.levels.push_back(l);
  }
  if (budget_ > 0) p.budget_left = std::max(0, budget_ - p.measured - p.issued);
  p.done = IsComplete();
  return p;
}

bool SamplingPlan::IsComplete() const { return pending_.empty() && outstanding_.empty(); }

std::vector<SiteRecord> SamplingPlan::Sites() const {
  std::vector<SiteRecord> out;
  out.reserve(sites_.size());
  for (const auto& [v, r] : sites_) out.push_back(r);
  return out;
}

const SiteRecord* SamplingPlan::FindSite(int vertex) const {
  auto it = sites_.find(vertex);
  return it == sites_.end() ? nullptr : &it->second;
}

std::vector<MapSample> SamplingPlan::MeasuredSamples() const {
  std::vector<MapSample> out;
  for (const auto& [v, r] : sites_) {
    if (r.state == SiteState::kMeasured) out.push_back({v, *r.fit});
  }
  return out;
}

std::vector<MapPiece> SamplingPlan::MeasuredPieces() const {
  std::vector<MapPiece> out;
  const SurfaceLevel& finest = *levels_.back();
  for (int v : measured_order_) {
    const SiteRecord& r = sites_.at(v);
    if (!r.line) continue;
    std::vector<MapPiece> pieces = MapPiecesOf(*r.line, v, finest.limit_positions[v]);
    out.insert(out.end(), std::make_move_iterator(pieces.begin()), std::make_move_iterator(pieces.end()));
  }
  // Imported drags' ids follow every vertex's, so they never merge with a site's drag.
  const int first_import_id = FirstImportDrag();
  for (size_t i = 0; i < imported_.size(); ++i) {
    std::vector<MapPiece> pieces =
        MapPiecesOf(imported_[i].line, first_import_id + static_cast<int>(i), imported_[i].position);
    out.insert(out.end(), std::make_move_iterator(pieces.begin()), std::make_move_iterator(pieces.end()));
  }
  return out;
}

absl::Status SamplingPlan::RecordImportedLineSample(const LineSample& line, const Eigen::Vector3d& position) {
  if (!position.allFinite()) return absl::InvalidArgumentError("imported drag: position is not finite");
  if (absl::Status valid = line.Validate(); !valid.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("imported drag: ", valid.message()));
  }
  imported_.push_back({line, position});
  region_map_stale_ = true;
  // A finished plan stays finished: an import adds to the map only.
  if (IsComplete() || cancelled_) return absl::OkStatus();
  return RefreshBoundarySelection();
}

absl::Status SamplingPlan::EnsureRegionMap() {
  if (!region_map_) {
    auto map = RegionMap::Create(*levels_.back(), options_.regions);
    if (!map.ok()) return map.status();
    region_map_ = std::move(*map);
    region_map_stale_ = true;
  }
  if (region_map_stale_ && HasDrags()) {
    if (auto status = region_map_->SetPieces(MeasuredPieces()); !status.ok()) return status;
    region_map_stale_ = false;
  }
  return absl::OkStatus();
}

Eigen::Vector3d SamplingPlan::DirectionFor(const SiteRecord& r) {
  const SurfaceLevel& finest = *levels_.back();
  const Eigen::Vector3d& n = finest.limit_normals[r.site.vertex];
  const Eigen::Vector3d normal = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::UnitZ();
  if (options_.mode != PlanMode::kBoundary) return TangentDragDirection(normal);
  if (auto it = selected_direction_.find(r.site.vertex); it != selected_direction_.end() && it->second.norm() > 0.5) {
    return it->second;
  }
  // Across a boundary the drags so far put within reach (when the boundary
  // is most of what a drag here could settle); where nothing is known,
  // orientations varied from site to site.
  if (HasDrags() && EnsureRegionMap().ok()) {
    // coarse_direction_by_gain: of the three varied orientations, the one
    // whose path brings the most surface nearer data (and settles the most),
    // a coverage drag laid down the middle of a gap between earlier ones.
    const auto varied = VariedDragDirections(normal, SiteShuffleKey(options_.seed, r.site.vertex));
    const BoundarySelector::DirectionChoice choice = selector_->BestDirectionAndAmong(
        *region_map_, r.site.vertex,
        options_.coarse_direction_by_gain ? std::span<const Eigen::Vector3d>(varied)
                                          : std::span<const Eigen::Vector3d>(),
        {});
    const BoundarySelection& best = choice.best;
    if (best.boundary_share >= 0.5 && best.gain > selector_->MinGain(options_.regions.merge.mu_resolution)) {
      return best.direction;
    }
    if (choice.among.vertex >= 0) return choice.among.direction;
  }
  return VariedDragDirection(normal, SiteShuffleKey(options_.seed, r.site.vertex));
}

absl::Status SamplingPlan::RefreshBoundarySelection() {
  if (options_.mode != PlanMode::kBoundary || cancelled_) return absl::OkStatus();
  // Re-make the choice of fresh selected sites with the newest information.
  for (auto it = pending_.begin(); it != pending_.end();) {
    const int v = std::get<3>(*it);
    const SiteRecord& r = sites_.at(v);
    if (r.origin == SiteOrigin::kSelected && r.failures == 0) {
      CountSite(r, -1);
      sites_.erase(v);
      it = pending_.erase(it);
    } else {
      ++it;
    }
  }
  selected_direction_.clear();
  if (!HasDrags()) return absl::OkStatus();
  // Coverage first: every reachable vertex of the coarsest level is issued
  // before any site is chosen.
  for (const auto& key : pending_) {
    if (sites_.at(std::get<3>(key)).origin == SiteOrigin::kInitial) return absl::OkStatus();
  }
  const SurfaceLevel& finest = *levels_.back();
  int selected_outstanding = 0;
  std::vector<Eigen::Vector3d> covered;
  for (const auto& [sequence, v] : outstanding_) {
    selected_outstanding += sites_.at(v).origin == SiteOrigin::kSelected;
    covered.push_back(finest.limit_positions[v]);
  }
  for (const auto& key : pending_) covered.push_back(finest.limit_positions[std::get<3>(key)]);
  const int queued = static_cast<int>(pending_.size());
  int slots = options_.lookahead - selected_outstanding - queued;
  if (budget_ > 0) slots = std::min(slots, budget_ - measured_count_ - static_cast<int>(outstanding_.size()) - queued);
  if (slots <= 0) return absl::OkStatus();
  if (auto status = EnsureRegionMap(); !status.ok()) return status;

  const int candidates = VertexCount(options_.max_level);
  const double reach = selector_->reach_mm();
  std::vector<char> candidate(candidates, 0);
  for (int v = 0; v < candidates; ++v) {
    if (sites_.count(v) || !Reachable(v)) continue;
    bool near_no_go = false;
    for (const Eigen::Vector3d& p : no_go_) near_no_go |= (finest.limit_positions[v] - p).squaredNorm() < reach * reach;
    candidate[v] = !near_no_go;
  }
  int rank = 0;  // of the choices below, in the order they are made
  if (options_.follow_boundaries) slots -= FollowBoundaries(slots, candidate, covered, rank);
  // Stop when no drag could remove more than a resolution-sized error over
  // its whole corridor.
  const double min_gain = std::max(options_.min_uncertainty_score, selector_->MinGain(options_.regions.merge.mu_resolution));
  std::vector<DragSegment> drags;
  if (options_.continuation_prior > 0.0) drags = DragWindows();
  const double h = selector_->half_window_mm();
  for (int k = 0; k < slots; ++k) {
    std::vector<DirectedCandidate> directed;
    if (options_.continuation_prior > 0.0) directed = ContinuationDrags(drags, candidate);
    const BoundarySelection choice = selector_->Select(*region_map_, candidate, covered, directed);
    if (choice.vertex < 0 || !(choice.gain > min_gain)) break;
    SiteRecord r;
    r.site = {std::max(options_.coarsest_level, NaturalLevel(choice.vertex)), choice.vertex};
    r.origin = SiteOrigin::kSelected;
    r.selection_rank = ++rank;
    AddSite(std::move(r));
    selected_direction_[choice.vertex] = choice.direction;
    candidate[choice.vertex] = 0;
    covered.push_back(finest.limit_positions[choice.vertex]);
    const Eigen::Vector3d& c = finest.limit_positions[choice.vertex];
    drags.push_back({c - h * choice.direction, c + h * choice.direction});
  }
  return absl::OkStatus();
}

BoundaryTraceOptions SamplingPlan::TraceOptions() const {
  BoundaryTraceOptions trace;
  trace.link_mm = options_.regions.links.max_length_mm;
  return trace;
}

DirectedCandidate SamplingPlan::DragForTarget(const std::vector<TraceTarget>& targets, std::size_t k,
                                              const std::vector<DragSegment>& drags,
                                              const std::vector<char>& candidate) const {
  const SurfaceLevel& finest = *levels_.back();
  const BoundaryTraceOptions trace = TraceOptions();
  const double h = selector_->half_window_mm();
  const std::vector<ChangeMark>& marks = region_map_->change_marks();
  const TraceTarget& target = targets[k];
  DirectedCandidate out;
  if (Explored(target, drags, trace)) return out;  // by a drag placed since the targets were found
  // A drag that crossed two edges of a narrow feature leaves two targets
  // a feature's width apart along its direction; one drag centred between
  // them crosses both when its window holds both with the margin.
  Eigen::Vector3d centre = target.point;
  for (std::size_t m = k + 1; m < targets.size(); ++m) {
    const TraceTarget& other = targets[m];
    if (marks[other.mark].drag != marks[target.mark].drag || other.side != target.side) continue;
    if ((other.point - target.point).norm() <= 2.0 * (h - trace.explored_mm)) {
      centre = 0.5 * (target.point + other.point);
      break;
    }
  }
  // The target is off the surface by the boundary's curvature over a step
  // (12 mm on a 20 mm radius: 3.6 mm); half a step away is another place.
  const int v = selector_->NearestVertex(centre, 0.5 * trace.step_share * trace.link_mm);
  if (v < 0 || v >= static_cast<int>(candidate.size()) || !candidate[v]) return out;
  const Eigen::Vector3d n = finest.limit_normals[v].norm() > 0 ? Eigen::Vector3d(finest.limit_normals[v].normalized())
                                                                : Eigen::Vector3d::UnitZ();
  Eigen::Vector3d direction = target.direction - target.direction.dot(n) * n;
  if (direction.norm() < 1e-6) return out;
  out.vertex = v;
  out.direction = direction.normalized();
  return out;
}

std::vector<DirectedCandidate> SamplingPlan::ContinuationDrags(const std::vector<DragSegment>& drags,
                                                               const std::vector<char>& candidate) const {
  const BoundaryTraceOptions trace = TraceOptions();
  const std::vector<ChangeMark>& marks = region_map_->change_marks();
  const std::vector<TraceTarget> targets = OpenTraceTargets(marks, drags, trace);
  const double corridor = 0.5 * selector_->reach_mm();  // a quarter of the drag length (boundary_selection.h)
  std::vector<DirectedCandidate> out;
  for (std::size_t k = 0; k < targets.size(); ++k) {
    DirectedCandidate drag = DragForTarget(targets, k, drags, candidate);
    if (drag.vertex < 0) continue;
    const double error = ContinuationError(targets[k], marks[targets[k].mark], *region_map_,
                                           selector_->half_window_mm(), corridor);
    drag.extra_gain = options_.continuation_prior * error;
    if (drag.extra_gain <= 0.0) continue;
    // Two targets of one narrow feature share a drag: their errors add up.
    auto same = std::find_if(out.begin(), out.end(), [&](const DirectedCandidate& d) {
      return d.vertex == drag.vertex && std::abs(d.direction.dot(drag.direction)) > 0.99;
    });
    if (same != out.end()) {
      same->extra_gain += drag.extra_gain;
    } else {
      out.push_back(drag);
    }
  }
  return out;
}

std::vector<DragSegment> SamplingPlan::DragWindows() const {
  std::vector<DragSegment> out;
  auto add_path = [&](const LineSample& line) {
    for (size_t i = 0; i + 1 < line.path_points.size(); ++i) out.push_back({line.path_points[i], line.path_points[i + 1]});
  };
  for (int v : measured_order_) {
    if (const SiteRecord& r = sites_.at(v); r.line) add_path(*r.line);
  }
  for (const ImportedDrag& d : imported_) add_path(d.line);
  const SurfaceLevel& finest = *levels_.back();
  const double h = selector_->half_window_mm();
  auto add_centre = [&](int v, const Eigen::Vector3d* direction) {
    const Eigen::Vector3d& c = finest.limit_positions[v];
    if (direction == nullptr) {
      out.push_back({c, c});  // direction not known yet: where it is
    } else {
      out.push_back({c - h * *direction, c + h * *direction});
    }
  };
  for (const auto& [sequence, v] : outstanding_) {
    auto it = issued_direction_.find(sequence);
    add_centre(v, it == issued_direction_.end() ? nullptr : &it->second);
  }
  for (const auto& key : pending_) {
    const int v = std::get<3>(key);
    auto it = selected_direction_.find(v);
    add_centre(v, it == selected_direction_.end() ? nullptr : &it->second);
  }
  return out;
}

int SamplingPlan::FollowBoundaries(int slots, std::vector<char>& candidate, std::vector<Eigen::Vector3d>& covered,
                                   int& rank) {
  if (slots <= 0) return 0;
  const SurfaceLevel& finest = *levels_.back();
  const double h = selector_->half_window_mm();
  std::vector<DragSegment> drags = DragWindows();
  const std::vector<TraceTarget> targets = OpenTraceTargets(region_map_->change_marks(), drags, TraceOptions());
  int added = 0;
  for (size_t k = 0; k < targets.size() && added < slots; ++k) {
    const DirectedCandidate drag = DragForTarget(targets, k, drags, candidate);
    if (drag.vertex < 0) continue;
    const int v = drag.vertex;
    SiteRecord r;
    r.site = {std::max(options_.coarsest_level, NaturalLevel(v)), v};
    r.origin = SiteOrigin::kSelected;
    r.selection_rank = ++rank;
    AddSite(std::move(r));
    if (sites_.at(v).state != SiteState::kPending) break;  // skipped: out of budget or cancelled
    selected_direction_[v] = drag.direction;
    candidate[v] = 0;
    covered.push_back(finest.limit_positions[v]);
    drags.push_back({finest.limit_positions[v] - h * drag.direction, finest.limit_positions[v] + h * drag.direction});
    ++added;
  }
  return added;
}

}  // namespace surfmap
