#include "clients/cli/job_commands.h"

#include <cmath>
#include <cstdio>
#include <optional>

#include <google/protobuf/util/time_util.h>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "clients/cli/import_command.h"
#include "clients/cli/provenance_options.h"
#include "clients/remote/progress_line.h"
#include "clients/cli/number_text.h"
#include "proto/surfmap/v1/surfmap.grpc.pb.h"

namespace surfmap::cli {
namespace {

namespace pb = ::surfmap::v1;
using google::protobuf::util::TimeUtil;

std::string_view PropertyName(pb::Property p) {
  switch (p) {
    case pb::PROPERTY_FRICTION: return "friction";
    case pb::PROPERTY_ROUGHNESS: return "roughness";
    case pb::PROPERTY_BOTH: return "both";
    default: return "unspecified";
  }
}

std::string_view ModeName(pb::SamplingMode m) {
  switch (m) {
    case pb::SAMPLING_MODE_ADAPTIVE: return "adaptive";
    case pb::SAMPLING_MODE_UNIFORM: return "uniform";
    case pb::SAMPLING_MODE_UNCERTAINTY: return "uncertainty";
    case pb::SAMPLING_MODE_BOUNDARY: return "boundary";
    default: return "unspecified";
  }
}

std::string_view SiteStateName(pb::SiteState s) {
  switch (s) {
    case pb::SITE_STATE_PENDING: return "pending";
    case pb::SITE_STATE_ISSUED: return "issued";
    case pb::SITE_STATE_MEASURED: return "measured";
    case pb::SITE_STATE_FAILED: return "failed";
    case pb::SITE_STATE_SKIPPED: return "skipped";
    default: return "unspecified";
  }
}

struct CreateArgs {
  int64_t object_id = 0;
  std::string property = "friction";
  std::string mode = "boundary";
  std::optional<int> coarsest;
  std::optional<int> finest;
  std::optional<int> map_level;
  std::optional<double> threshold;
  std::optional<int> budget;
  std::optional<double> segment_mm;
  std::optional<double> speed;
  std::optional<double> force;
  std::optional<uint64_t> seed;
  std::optional<double> lease_s;
  std::optional<int> max_retries;
  std::optional<double> spacing_mm;
  ProvenanceArgs provenance;
  bool json = false;
};

// The plan's size and robot time, and the server's warnings, on stderr (stdout
// keeps only the id for scripts).
void PrintPlanEstimate(const pb::CreateJobResponse& response) {
  const pb::PlanEstimate& e = response.estimate();
  auto hours = [](const google::protobuf::Duration& d) {
    const double s = static_cast<double>(d.seconds()) + d.nanos() * 1e-9;
    char text[64];
    if (s >= 3600) {
      std::snprintf(text, sizeof(text), "%.1f h", s / 3600);
    } else {
      std::snprintf(text, sizeof(text), "%.0f min", s / 60);
    }
    return std::string(text);
  };
  std::fprintf(stderr,
               "plan: %d level-0 sites (%s control mesh of %d vertices, %.3g mm apart), about %d in all (at most %d)\n"
               "robot time: %.1f s per drag (%.1f s approach + the passes) -> level 0 %s, expected %s\n",
               e.level0_sites(), e.simplified() ? "simplified" : "the object's", e.control_vertices(),
               e.control_spacing_mm(), e.expected_sites(), e.max_sites(), e.seconds_per_drag(), e.approach_s(),
               hours(e.level0_time()).c_str(), hours(e.expected_time()).c_str());
  for (const std::string& w : response.warnings()) std::fprintf(stderr, "warning: %s\n", w.c_str());
}

// Unset options stay zero: the server applies its defaults to zero fields.
pb::JobSpec SpecFromArgs(const CreateArgs& a) {
  pb::JobSpec spec;
  spec.set_object_id(a.object_id);
  spec.set_property(a.property == "roughness" ? pb::PROPERTY_ROUGHNESS
                    : a.property == "both"    ? pb::PROPERTY_BOTH
                                              : pb::PROPERTY_FRICTION);
  spec.set_mode(a.mode == "uniform"       ? pb::SAMPLING_MODE_UNIFORM
                : a.mode == "uncertainty" ? pb::SAMPLING_MODE_UNCERTAINTY
                : a.mode == "adaptive"    ? pb::SAMPLING_MODE_ADAPTIVE
                                          : pb::SAMPLING_MODE_BOUNDARY);
  if (a.coarsest) spec.set_coarsest_level(*a.coarsest);
  if (a.finest) spec.set_finest_level(*a.finest);
  if (a.map_level) spec.set_map_level(*a.map_level);
  if (a.threshold) spec.set_threshold(*a.threshold);
  if (a.budget) spec.set_budget(*a.budget);
  if (a.segment_mm) spec.mutable_probe()->set_segment_length_mm(*a.segment_mm);
  if (a.speed) spec.mutable_probe()->set_speed_mm_s(*a.speed);
  if (a.force) spec.mutable_probe()->set_normal_force_n(*a.force);
  if (a.seed) spec.set_seed(*a.seed);
  if (a.max_retries) spec.set_max_retries(*a.max_retries);
  if (a.spacing_mm) spec.set_site_spacing_mm(*a.spacing_mm);
  if (a.lease_s) {
    *spec.mutable_lease() = TimeUtil::MillisecondsToDuration(static_cast<int64_t>(std::llround(*a.lease_s * 1000.0)));
  }
  return spec;
}

void PrintJobTable(const google::protobuf::RepeatedPtrField<pb::JobInfo>& jobs) {
  // issued = sites handed to rigs and not answered yet: with measured and
  // pending it accounts for every open site, so a stalled rig shows here.
  std::printf("%6s %7s  %-9s %-9s %-11s %6s %8s %6s %8s  %-24s %s\n", "job", "object", "state", "property", "mode",
              "levels", "measured", "issued", "pending", "updated", "operator / specimen");
  for (const pb::JobInfo& j : jobs) {
    std::printf("%6lld %7lld  %-9s %-9s %-11s %3d..%-2d %8d %6d %8d  %-24s %s\n", static_cast<long long>(j.job_id()),
                static_cast<long long>(j.spec().object_id()), std::string(JobStateName(j.state())).c_str(),
                std::string(PropertyName(j.spec().property())).c_str(),
                std::string(ModeName(j.spec().mode())).c_str(), j.spec().coarsest_level(), j.spec().finest_level(),
                j.progress().measured(), j.progress().issued(), j.progress().pending(),
                TimeUtil::ToString(j.updated()).c_str(),
                (j.provenance().operator_name() + " / " + j.provenance().specimen()).c_str());
  }
}

using SetStateMethod = grpc::Status (pb::JobService::Stub::*)(grpc::ClientContext*, const pb::SetJobStateRequest&,
                                                              pb::SetJobStateResponse*);

void AddSetStateCommand(CLI::App* job, std::shared_ptr<RemoteCli> cli, const std::string& name,
                        const std::string& help, const std::string& rpc, SetStateMethod method) {
  auto id = std::make_shared<int64_t>(0);
  CLI::App* cmd = job->add_subcommand(name, help);
  cmd->add_option("id", *id, "Job id")->required();
  cmd->callback([cli, id, rpc, method] {
    auto stub = pb::JobService::NewStub(cli->Channel());
    pb::SetJobStateRequest request;
    request.set_job_id(*id);
    pb::SetJobStateResponse response;
    if (!CallRpc(*cli, rpc, *stub, method, request, &response)) return;
    std::printf("job %lld: %s\n", static_cast<long long>(response.job().job_id()),
                std::string(JobStateName(response.job().state())).c_str());
  });
}

}  // namespace

std::string FormatJobInfo(const pb::JobInfo& job) {
  const pb::JobSpec& s = job.spec();
  const pb::JobProgress& p = job.progress();
  std::string out = absl::StrFormat("job %d  object %d  %s\n", job.job_id(), s.object_id(), JobStateName(job.state()));
  absl::StrAppendFormat(&out, "  property %s, mode %s, levels %d..%d, map level %d, %sbudget %s, seed %d\n",
                        PropertyName(s.property()), ModeName(s.mode()), s.coarsest_level(), s.finest_level(),
                        s.has_map_level() ? s.map_level() : s.finest_level(),
                        s.mode() == pb::SAMPLING_MODE_ADAPTIVE ? absl::StrFormat("threshold %g, ", s.threshold()) : "",
                        s.budget() > 0 ? std::to_string(s.budget()) : "default", s.seed());
  absl::StrAppendFormat(&out, "  probe: %g mm at %g mm/s, %g N; lease %s, max retries %d\n",
                        s.probe().segment_length_mm(), s.probe().speed_mm_s(), s.probe().normal_force_n(),
                        TimeUtil::ToString(s.lease()), s.max_retries());
  absl::StrAppendFormat(&out, "  created %s, updated %s\n", TimeUtil::ToString(job.created()),
                        TimeUtil::ToString(job.updated()));
  absl::StrAppendFormat(&out, "  progress: %s%s\n", FormatProgressLine(p, 0), p.complete() ? " (complete)" : "");
  if (const std::string provenance = FormatProvenance(job.provenance(), "    "); !provenance.empty()) {
    absl::StrAppend(&out, "  provenance:\n", provenance);
  }
  absl::StrAppendFormat(&out, "  %5s %8s %8s %8s %8s\n", "level", "measured", "issued", "pending", "failed");
  for (const pb::LevelProgress& l : p.levels()) {
    absl::StrAppendFormat(&out, "  %5d %8d %8d %8d %8d\n", l.level(), l.measured(), l.issued(), l.pending(),
                          l.failed());
  }
  return out;
}

void AddJobCommands(CLI::App& app, std::shared_ptr<RemoteCli> cli) {
  CLI::App* job = app.add_subcommand("job", "Mapping jobs: create, list, show, import, pause, resume, cancel, plan");
  job->require_subcommand(1);

  auto a = std::make_shared<CreateArgs>();
  CLI::App* create = job->add_subcommand("create", "Create a mapping job on an object; prints the job id");
  create->add_option("--object", a->object_id, "Object id")->required();
  create->add_option("--property", a->property, "What to map")
      ->check(CLI::IsMember({"friction", "roughness", "both"}))
      ->capture_default_str();
  create->add_option("--mode", a->mode,
                     "Sampling strategy: boundary (goes looking for boundaries), adaptive (the paper's threshold "
                     "rule), uniform (every vertex of --coarsest), uncertainty (needs --budget)")
      ->check(CLI::IsMember({"boundary", "adaptive", "uniform", "uncertainty"}))
      ->capture_default_str();
  create->add_option("--coarsest", a->coarsest, "Coarsest subdivision level (default 0)")->check(CLI::Range(0, 6));
  create->add_option("--finest", a->finest, "The plan's finest level (default: two coarser than the map level)")
      ->check(CLI::Range(0, 6));
  create->add_option("--map-level", a->map_level, "The level the map is evaluated on (default: ~1 mm edges)")
      ->check(CLI::Range(0, 6));
  create->add_option("--threshold", a->threshold, "Texture distance that triggers refinement (adaptive only)")
      ->check(CLI::PositiveNumber);
  create->add_option("--budget", a->budget, "Maximum number of samples (0 = the mode's default)")
      ->check(CLI::NonNegativeNumber);
  create->add_option("--segment-mm", a->segment_mm, "Drag length, mm (default 20)")->check(CLI::PositiveNumber);
  create->add_option("--speed", a->speed, "Drag speed, mm/s (default 10)")->check(CLI::PositiveNumber);
  create->add_option("--force", a->force, "Normal force, N (default 5)")->check(CLI::PositiveNumber);
  create->add_option("--seed", a->seed, "Seed of the plan's deterministic choices");
  create->add_option("--lease-s", a->lease_s, "Lease of a probe command, s (default 60)")
      ->check(CLI::PositiveNumber);
  create->add_option("--max-retries", a->max_retries, "Attempts per site after a failure (default 2)")
      ->check(CLI::NonNegativeNumber);
  create->add_option("--spacing-mm", a->spacing_mm,
                     "Target distance between level-0 sites, mm (default: boundary 0.65 x the drag length, other "
                     "modes the drag length); a denser mesh is simplified to it")
      ->check(CLI::PositiveNumber);
  AddProvenanceOptions(create, &a->provenance);
  create->add_flag("--json", a->json, "Print the JobInfo as JSON instead of the id");
  create->callback([cli, a] {
    auto stub = pb::JobService::NewStub(cli->Channel());
    pb::CreateJobRequest request;
    *request.mutable_spec() = SpecFromArgs(*a);
    std::string error;
    if (!ProvenanceFromArgs(a->provenance, request.mutable_provenance(), &error)) return FailUsage(*cli, error);
    pb::CreateJobResponse response;
    if (!CallRpc(*cli, "CreateJob", *stub, &pb::JobService::Stub::CreateJob, request, &response)) return;
    if (a->json) {
      std::printf("%s\n", MessageToJson(response.job()).c_str());
    } else {
      std::printf("%lld\n", static_cast<long long>(response.job().job_id()));
    }
    PrintPlanEstimate(response);
  });

  auto list_object = std::make_shared<int64_t>(0);
  auto list_json = std::make_shared<bool>(false);
  CLI::App* list = job->add_subcommand("list", "List jobs");
  list->add_option("--object", *list_object, "Only the jobs of this object");
  list->add_flag("--json", *list_json, "Print the response as JSON");
  list->callback([cli, list_object, list_json] {
    auto stub = pb::JobService::NewStub(cli->Channel());
    pb::ListJobsRequest request;
    request.set_object_id(*list_object);
    pb::ListJobsResponse response;
    if (!CallRpc(*cli, "ListJobs", *stub, &pb::JobService::Stub::ListJobs, request, &response)) return;
    if (*list_json) {
      std::printf("%s\n", MessageToJson(response).c_str());
    } else {
      PrintJobTable(response.jobs());
    }
  });

  auto show_id = std::make_shared<int64_t>(0);
  auto show_json = std::make_shared<bool>(false);
  CLI::App* show = job->add_subcommand("show", "A job's state and progress per level");
  show->add_option("id", *show_id, "Job id")->required();
  show->add_flag("--json", *show_json, "Print the JobInfo as JSON");
  show->callback([cli, show_id, show_json] {
    auto stub = pb::JobService::NewStub(cli->Channel());
    pb::GetJobRequest request;
    request.set_job_id(*show_id);
    pb::GetJobResponse response;
    if (!CallRpc(*cli, "GetJob", *stub, &pb::JobService::Stub::GetJob, request, &response)) return;
    if (*show_json) {
      std::printf("%s\n", MessageToJson(response.job()).c_str());
    } else {
      std::fputs(FormatJobInfo(response.job()).c_str(), stdout);
    }
  });

  AddImportCommand(job, cli);
  AddSetStateCommand(job, cli, "pause", "Stop issuing probe commands (leased ones may still be submitted)",
                     "PauseJob", &pb::JobService::Stub::PauseJob);
  AddSetStateCommand(job, cli, "resume", "Resume a paused job", "ResumeJob", &pb::JobService::Stub::ResumeJob);
  AddSetStateCommand(job, cli, "cancel", "Cancel a job for good", "CancelJob", &pb::JobService::Stub::CancelJob);

  auto plan_id = std::make_shared<int64_t>(0);
  auto plan_json = std::make_shared<bool>(false);
  CLI::App* plan = job->add_subcommand("plan", "The job's sampling sites and their states");
  plan->add_option("id", *plan_id, "Job id")->required();
  plan->add_flag("--json", *plan_json, "Print the response as JSON");
  plan->callback([cli, plan_id, plan_json] {
    auto stub = pb::JobService::NewStub(cli->Channel());
    pb::GetPlanRequest request;
    request.set_job_id(*plan_id);
    pb::GetPlanResponse response;
    if (!CallRpc(*cli, "GetPlan", *stub, &pb::JobService::Stub::GetPlan, request, &response)) return;
    if (*plan_json) {
      std::printf("%s\n", MessageToJson(response).c_str());
      return;
    }
    std::printf("job %lld: %s\n", static_cast<long long>(response.job_id()),
                FormatProgressLine(response.progress(), 0).c_str());
    std::printf("%5s %7s  %-9s %8s  %28s  %s\n", "level", "vertex", "state", "attempts", "position (mm)", "failure");
    for (const pb::PlanSite& s : response.sites()) {
      std::printf("%5d %7d  %-9s %8d  %8.2f %8.2f %8.2f    %s\n", s.site().level(), s.site().vertex(),
                  std::string(SiteStateName(s.state())).c_str(), s.attempts(), Shown(s.position().x(), 2),
                  Shown(s.position().y(), 2), Shown(s.position().z(), 2), s.failure_reason().c_str());
    }
  });
}

}  // namespace surfmap::cli
