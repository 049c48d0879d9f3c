#include "server/service/proto_builders.h"

#include "server/service/provenance_proto.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "absl/strings/str_cat.h"
#include "server/estimate/roughness.h"
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include "server/codec/fit_json.h"
#include "server/estimate/fit_trace.h"
#include "server/jobs/command_json.h"
#include "server/jobs/job_reads.h"
#include "server/service/proto_conversion.h"
#include "server/service/region_pieces_proto.h"

namespace surfmap {

pb::JobProgress ProgressToProto(const PlanProgress& p, const LeasedCounts* leased) {
  pb::JobProgress out;
  out.set_measured(p.measured);
  out.set_pending(p.pending);
  out.set_issued(p.issued);
  out.set_failed(p.failed);
  out.set_skipped(p.skipped);
  out.set_budget_left(p.budget_left);
  out.set_complete(p.done);
  for (const LevelProgress& l : p.levels) {
    pb::LevelProgress* level = out.add_levels();
    level->set_level(l.level);
    level->set_measured(l.measured);
    level->set_pending(l.pending);
    level->set_issued(l.issued);
    level->set_failed(l.failed);
    if (leased != nullptr) {
      auto it = leased->by_level.find(l.level);
      level->set_leased(it == leased->by_level.end() ? 0 : it->second);
    }
  }
  if (leased != nullptr) out.set_leased(leased->total);
  return out;
}

pb::JobInfo JobInfoToProto(const JobSnapshot& job) {
  pb::JobInfo out;
  out.set_job_id(job.record.id);
  *out.mutable_spec() = JobParamsToProto(job.params);
  out.set_state(JobStateToProto(job.record.state));
  *out.mutable_progress() = ProgressToProto(job.progress, job.leased ? &*job.leased : nullptr);
  *out.mutable_created() = TimestampFromUnixMs(job.record.created_unix_ms);
  *out.mutable_updated() = TimestampFromUnixMs(job.record.updated_unix_ms);
  FillMetadata(job.record.metadata_json, 0, out.mutable_provenance(), nullptr);
  return out;
}

pb::ObjectInfo ObjectInfoToProto(const ObjectRecord& o) {
  pb::ObjectInfo out;
  out.set_object_id(o.id);
  out.set_name(o.name);
  out.set_format(o.mesh_format == "ply" ? pb::MESH_FORMAT_PLY : pb::MESH_FORMAT_OBJ);
  out.set_control_vertex_count(static_cast<int32_t>(o.control_vertices));
  out.set_control_face_count(static_cast<int32_t>(o.control_faces));
  *out.mutable_created() = TimestampFromUnixMs(o.created_unix_ms);
  out.set_surface(o.surface == "facets" ? pb::OBJECT_SURFACE_FACETS : pb::OBJECT_SURFACE_CONTROL_MESH);
  FillMetadata(o.metadata_json, 0, out.mutable_provenance(), nullptr);
  return out;
}

pb::PlanEstimate PlanEstimateToProto(const PlanEstimate& e, bool simplified) {
  pb::PlanEstimate out;
  out.set_level0_sites(e.level0_sites);
  out.set_expected_sites(e.expected_sites);
  out.set_max_sites(e.max_sites);
  out.set_control_spacing_mm(e.control_spacing_mm);
  out.set_simplified(simplified);
  out.set_control_vertices(e.control_vertices);
  out.set_seconds_per_drag(e.seconds_per_drag);
  out.set_approach_s(e.approach_s);
  auto duration = [](double seconds) {
    google::protobuf::Duration d;
    d.set_seconds(static_cast<int64_t>(seconds));
    d.set_nanos(static_cast<int32_t>((seconds - static_cast<double>(d.seconds())) * 1e9));
    return d;
  };
  *out.mutable_level0_time() = duration(e.level0_seconds);
  *out.mutable_expected_time() = duration(e.expected_seconds);
  return out;
}

absl::StatusOr<pb::Sample> BuildSample(const SampleRecord& record, const ProbeCommand* decoded_probe,
                                       const TraceFit* decoded_fit) {
  const TraceRecord& trace = record.trace;
  const CommandRecord& command = record.command;
  ProbeCommand parsed_probe;
  if (decoded_probe == nullptr) {
    absl::StatusOr<ProbeCommand> probe = ProbeCommandFromJson(command.command_json);
    if (!probe.ok()) {
      return absl::DataLossError(absl::StrCat("stored command ", command.id, " of trace ", trace.id,
                                              " cannot be read: ", probe.status().message()));
    }
    parsed_probe = std::move(*probe);
    decoded_probe = &parsed_probe;
  }
  absl::StatusOr<pb::Fit> fit_proto = FitToProto(record.fit, decoded_fit);
  if (!fit_proto.ok()) return fit_proto.status();
  pb::Sample s;
  s.set_trace_id(trace.id);
  s.set_command_id(command.id);
  s.set_job_id(command.job_id);
  s.mutable_site()->set_level(command.site_level);
  s.mutable_site()->set_vertex(static_cast<int32_t>(command.site_vertex));
  *s.mutable_position() = ToProto(decoded_probe->position);
  *s.mutable_drag_direction() = ToProto(decoded_probe->drag_direction);
  s.set_segment_length_mm(decoded_probe->probe.segment_length_mm);
  *s.mutable_fit() = std::move(*fit_proto);
  *s.mutable_received() = TimestampFromUnixMs(trace.received_unix_ms);
  s.set_rig_id(command.lease_owner);  // a done command's last lessee measured it
  FillMetadata(trace.metadata_json, trace.received_unix_ms, s.mutable_provenance(), s.mutable_import());
  if (s.import().source().empty()) s.clear_import();  // a leased trace
  return s;
}

absl::StatusOr<pb::Sample> BuildSample(const AcceptedSample& accepted, const ProbeCommand* probe,
                                       const TraceFit* decoded_fit) {
  SampleRecord record;
  record.trace.id = accepted.trace_id;
  record.trace.command_id = accepted.command.id;
  record.trace.job_id = accepted.command.job_id;
  record.trace.received_unix_ms = accepted.received_unix_ms;
  record.trace.metadata_json = accepted.metadata_json;
  record.command = accepted.command;
  record.fit = accepted.fit;
  return BuildSample(record, probe, decoded_fit);
}

absl::Status AppendSamples(const std::vector<SampleRecord>& samples,
                           google::protobuf::RepeatedPtrField<pb::Sample>* out) {
  out->Reserve(out->size() + static_cast<int>(samples.size()));
  for (const SampleRecord& record : samples) {
    absl::StatusOr<pb::Sample> sample = BuildSample(record);
    if (!sample.ok()) return sample.status();
    *out->Add() = std::move(*sample);
  }
  return absl::OkStatus();
}

absl::Status AddRecomputedSeries(JobReads& reads, const SampleRecord& record, pb::Sample* sample) {
  FitOptions options;
  absl::StatusOr<TraceFit> fit = reads.RecomputeFit(record, &options);
  if (!fit.ok()) return fit.status();
  AddFitSeries(*fit, options.step_mm, sample->mutable_fit());
  return absl::OkStatus();
}

namespace {

// The map's material regions with their pooled estimates and areas (on the
// map level: each triangle's area shared equally by its corners).
void FillRegions(const RegionMap& map, pb::MapLevel* out) {
  const SurfaceLevel& level = map.level();
  std::vector<double> area(map.regions().size(), 0.0);
  for (const auto& t : level.triangles) {
    const auto& x = level.limit_positions;
    const double third = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).norm() / 6.0;
    for (int i = 0; i < 3; ++i) {
      const int r = map.region()[t[i]];
      if (r >= 0) area[r] += third;
    }
  }
  for (int r = 0; r < static_cast<int>(map.regions().size()); ++r) {
    const TextureRegion& region = map.regions()[r];
    pb::MapRegion* o = out->add_regions();
    o->set_region(r);
    o->set_mu(region.statistics.mu);
    o->set_mu_se(region.statistics.mu_se);
    o->set_mu_spread(region.statistics.spread);
    o->set_piece_count(static_cast<int>(region.pieces.size()));
    o->set_roughness_piece_count(region.roughness_pieces);
    if (region.has_roughness()) {
      o->mutable_reflection()->Assign(region.reflection.begin(), region.reflection.end());
      const std::vector<double> a = ReflectionToAr(region.reflection);
      o->mutable_ar_coefficients()->Assign(a.begin(), a.end());
      o->set_sigma(region.sigma);
    }
    o->set_area_mm2(area[r]);
    o->set_material(region.material);
    o->set_own_mu(region.own_statistics.mu);
    o->set_own_mu_se(region.own_statistics.mu_se);
  }
}

}  // namespace

absl::Status FillMapLevel(const MapSnapshot& snapshot, int level, const std::vector<SampleRecord>& samples,
                          int64_t job_id, pb::MapLevel* out) {
  const SurfaceLevel& surface_level = snapshot.surface->level(level);
  const int n = static_cast<int>(surface_level.limit_positions.size());
  out->set_job_id(job_id);
  out->set_level(level);
  out->set_vertex_count(n);
  if (snapshot.map) {
    // A coarser level's vertices are a prefix of the map level's.
    const RegionMap& map = *snapshot.map;
    out->mutable_mu()->Assign(map.mu().begin(), map.mu().begin() + n);
    out->mutable_mu_uncertainty()->Assign(map.mu_std().begin(), map.mu_std().begin() + n);
    out->mutable_region()->Assign(map.region().begin(), map.region().begin() + n);
    out->mutable_boundary_probability()->Assign(map.boundary_probability().begin(),
                                                map.boundary_probability().begin() + n);
    if (map.roughness_order() > 0) {
      // 0 where the vertex's region has no roughness (no pure piece long
      // enough for a fit): the arrays stay per vertex.
      std::vector<double> k(map.roughness_order());
      for (int v = 0; v < n; ++v) {
        for (int j = 0; j < map.roughness_order(); ++j) k[j] = map.reflection()[j][v];
        const bool has = std::isfinite(map.log_sigma()[v]) && std::all_of(k.begin(), k.end(), [](double x) {
                           return std::isfinite(x);
                         });
        const std::vector<double> a = has ? ReflectionToAr(k) : std::vector<double>{};
        out->add_sigma(has ? std::exp(map.log_sigma()[v]) : 0.0);
        out->add_a1(a.size() > 0 ? a[0] : 0.0);
        out->add_a2(a.size() > 1 ? a[1] : 0.0);
      }
    }
    FillRegions(map, out);
    FillRegionPieces(map, snapshot.first_import_drag, samples, out);
  }
  return AppendSamples(samples, out->mutable_samples());
}

void FillMesh(const SurfaceLevel& level, int level_index, int64_t object_id, pb::GetMeshResponse* out) {
  out->set_object_id(object_id);
  out->set_level(level_index);
  out->mutable_positions()->Reserve(static_cast<int>(level.limit_positions.size()));
  for (const Eigen::Vector3d& p : level.limit_positions) *out->add_positions() = ToProto(p);
  for (const Eigen::Vector3d& n : level.limit_normals) *out->add_normals() = ToProto(n);
  out->mutable_triangle_indices()->Reserve(static_cast<int>(level.triangles.size() * 3));
  for (const auto& t : level.triangles) {
    out->add_triangle_indices(t[0]);
    out->add_triangle_indices(t[1]);
    out->add_triangle_indices(t[2]);
  }
}

}  // namespace surfmap
