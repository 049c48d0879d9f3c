// surfmap-bench: how fast a real surfmapd acknowledges drag traces, and how
// fast it answers map queries.
//
//   surfmap-bench [--server HOST:PORT] [--seconds 5] [--rigs 1,4,16]
//                 [--level 4] [--queries 2000] [--points 100] [--token T]
//                 [--lease combined|separate|both]
//
// Without --server it starts surfmapd itself (tests/support/ServerProcess, a
// temp database). Throughput: for each rig count a fresh uniform job on the
// plate scene's mesh at a fine level (level 4: ~20,800 sites, enough not to
// run out), rigs = threads with their own connection doing LeaseCommand ->
// SubmitTrace ("separate") or SubmitTrace with lease_next, which returns the
// rig's next command ("combined"), with pre-generated ~1,000-sample traces
// moved to the command's site; every ack is durable (the server commits before it answers). Map
// latency: QueryMap with `points` random points per call, one caller, on a
// finished job. Not a test: it prints numbers and exits 0 unless the server
// fails.
#include <atomic>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include "absl/strings/str_format.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "clients/sim/rig/scene.h"
#include "server/mesh/control_mesh.h"
#include "tests/bench/bench_stats.h"
#include "tests/bench/steering_load.h"
#include "tests/bench/trace_templates.h"
#include "tests/support/job_helpers.h"
#include "tests/support/server_process.h"
#include "tests/support/surfmap_client.h"

namespace surfmap::bench {
namespace {

using itest::Context;
using itest::Describe;
using itest::pb::ProbeCommand;
using Clock = std::chrono::steady_clock;
namespace pb = ::surfmap::v1;

struct Flags {
  std::string server;
  double seconds = 5.0;
  std::string rigs = "1,4,16";
  int level = 4;
  int queries = 2000;
  int points = 100;
  std::string token;
  std::string lease = "both";
  std::string only;  // "", "throughput", "watchers", "reads"
  int watchers = 4;
  int watcher_rigs = 2;
  int watcher_rounds = 3;
  int64_t big_trace_samples = 990'000;
  int heavy_calls = 4;
};

struct PhaseResult {
  int rigs = 0;
  bool combined = false;  // lease_next on SubmitTrace instead of a LeaseCommand per trace
  int acked = 0;
  int errors = 0;
  double seconds = 0.0;
  bool ran_out = false;
  LatencySummary submit;
  std::string first_error;
};

PhaseResult RunThroughput(const std::string& address, int64_t job_id, int rigs, bool combined, double seconds,
                          const std::vector<DragTrace>& templates, const std::string& token) {
  PhaseResult result;
  result.rigs = rigs;
  result.combined = combined;
  std::atomic<int> acked{0}, errors{0};
  std::atomic<bool> ran_out{false};
  std::mutex mutex;
  std::vector<double> submit_ms;
  std::string first_error;
  const Clock::time_point start = Clock::now();
  const Clock::time_point end = start + std::chrono::microseconds(static_cast<int64_t>(seconds * 1e6));
  std::vector<std::thread> threads;
  for (int r = 0; r < rigs; ++r) {
    threads.emplace_back([&, r] {
      itest::Stubs stubs(itest::ConnectedChannel(address, /*own_subchannel=*/true));
      const std::string rig_id = absl::StrFormat("bench-%d-%d", rigs, r);
      std::vector<double> local_ms;
      size_t next_template = r;
      pb::LeaseCommandResponse lease;
      bool have_lease = false;  // combined: the previous submission's `next`
      while (Clock::now() < end) {
        grpc::Status status;
        if (!have_lease) {
          pb::LeaseCommandRequest lease_request;
          lease_request.set_rig_id(rig_id);
          lease_request.set_job_id(job_id);
          status = stubs.probe->LeaseCommand(Context(30, token).get(), lease_request, &lease);
        }
        have_lease = false;
        if (!status.ok()) {
          ++errors;
          std::lock_guard<std::mutex> lock(mutex);
          if (first_error.empty()) first_error = "LeaseCommand: " + Describe(status);
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
          continue;
        }
        if (lease.job_finished()) {
          ran_out = true;
          break;
        }
        if (!lease.has_command() || lease.command().command_id() == 0) {
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
          continue;
        }
        pb::SubmitTraceRequest submit;
        submit.set_command_id(lease.command().command_id());
        submit.set_rig_id(rig_id);
        submit.set_lease_next(combined);
        *submit.mutable_samples() = PlaceTrace(templates[next_template++ % templates.size()], lease.command());
        pb::SubmitTraceResponse response;
        const Clock::time_point sent = Clock::now();
        status = stubs.probe->SubmitTrace(Context(30, token).get(), submit, &response);
        local_ms.push_back(Ms(Clock::now() - sent));
        if (status.ok()) {
          ++acked;
          if (combined) {
            lease = response.next();
            have_lease = true;
          }
        } else {
          ++errors;
          std::lock_guard<std::mutex> lock(mutex);
          if (first_error.empty()) first_error = "SubmitTrace: " + Describe(status);
        }
      }
      std::lock_guard<std::mutex> lock(mutex);
      submit_ms.insert(submit_ms.end(), local_ms.begin(), local_ms.end());
    });
  }
  for (std::thread& t : threads) t.join();
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  result.acked = acked;
  result.errors = errors;
  result.ran_out = ran_out;
  result.submit = Summarize(std::move(submit_ms));
  result.first_error = first_error;
  return result;
}

int Main(int argc, char** argv) {
  Flags flags;
  CLI::App app{"surfmap-bench: acknowledged traces per second and QueryMap latency of a real surfmapd"};
  app.add_option("--server", flags.server, "HOST:PORT of a running surfmapd (default: start one)");
  app.add_option("--seconds", flags.seconds, "duration of each throughput phase")->check(CLI::PositiveNumber);
  app.add_option("--rigs", flags.rigs, "comma-separated rig counts");
  app.add_option("--level", flags.level, "subdivision level of the uniform throughput jobs")->check(CLI::Range(0, 6));
  app.add_option("--queries", flags.queries, "QueryMap calls")->check(CLI::NonNegativeNumber);
  app.add_option("--points", flags.points, "points per QueryMap call")->check(CLI::Range(1, 10000));
  app.add_option("--token", flags.token, "bearer token (steer role) when the server has tokens");
  app.add_option("--lease", flags.lease,
                 "combined: SubmitTrace leases the rig's next command (lease_next); separate: a LeaseCommand "
                 "per trace; both: each rig count both ways, in this order")
      ->check(CLI::IsMember({"combined", "separate", "both"}));
  app.add_option("--only", flags.only,
                 "run one part: throughput (rigs, QueryMap), watchers (rigs with and without WatchJob streams), "
                 "reads (GetJob under heavy GetSample calls)")
      ->check(CLI::IsMember({"throughput", "watchers", "reads"}));
  app.add_option("--watchers", flags.watchers, "WatchJob(include_map) streams in the watcher phases");
  app.add_option("--watcher-rigs", flags.watcher_rigs, "rigs in the watcher phases");
  app.add_option("--watcher-rounds", flags.watcher_rounds, "alternating phase pairs (without, with watchers)");
  app.add_option("--big-trace-samples", flags.big_trace_samples, "samples of the trace GetSample reads");
  app.add_option("--heavy-calls", flags.heavy_calls, "concurrent GetSample(include_series) calls");
  CLI11_PARSE(app, argc, argv);

  std::vector<int> rig_counts;
  for (absl::string_view part : absl::StrSplit(flags.rigs, ',', absl::SkipEmpty())) {
    int n = 0;
    if (!absl::SimpleAtoi(part, &n) || n < 1 || n > 256) {
      std::cerr << "--rigs: '" << part << "' is not a rig count in 1..256\n";
      return 2;
    }
    rig_counts.push_back(n);
  }

  std::unique_ptr<itest::ServerProcess> own_server;
  std::string address = flags.server;
  if (address.empty()) {
    auto server = itest::ServerProcess::Start();
    if (!server.ok()) {
      std::cerr << "cannot start surfmapd: " << server.status() << "\n";
      return 1;
    }
    own_server = std::move(*server);
    address = own_server->address();
    std::cout << "started " << itest::DefaultSurfmapdPath() << " on " << address << " (db " << own_server->db_path()
              << ")\n";
  }
  itest::Stubs stubs(itest::MakeChannel(address));

  absl::StatusOr<Scene> plate = LoadSceneByName("plate");
  if (!plate.ok()) {
    std::cerr << plate.status() << "\n";
    return 1;
  }
  pb::UploadObjectRequest upload;
  upload.set_name("bench-plate");
  upload.set_format(pb::MESH_FORMAT_OBJ);
  upload.set_mesh(WriteObj(plate->mesh));
  pb::UploadObjectResponse uploaded;
  if (grpc::Status s = stubs.objects->UploadObject(Context(120, flags.token).get(), upload, &uploaded); !s.ok()) {
    std::cerr << "UploadObject: " << Describe(s) << "\n";
    return 1;
  }
  const int64_t object_id = uploaded.object().object_id();

  const Clock::time_point generating = Clock::now();
  absl::StatusOr<std::vector<DragTrace>> templates = MakeTraceTemplates(16, 4242, 20.0, 200.0);
  if (!templates.ok()) {
    std::cerr << "trace templates: " << templates.status() << "\n";
    return 1;
  }
  std::cout << absl::StrFormat("%zu template traces of %zu samples simulated in %.0f ms\n", templates->size(),
                               templates->front().samples.size(), Ms(Clock::now() - generating));

  if (flags.only.empty() || flags.only == "watchers") {
    WatcherLoadResult w = RunWatcherLoad(address, object_id, *templates, flags.watcher_rigs, flags.watchers,
                                         flags.watcher_rounds, flags.seconds, /*level=*/4);
    double without = 0, with = 0;
    std::cout << absl::StrFormat("\nWatchers: %d rigs, with and without %d WatchJob(include_map) streams (job on the "
                                 "level-4 plate: 20,769 sites), alternating %.1f s phases\n",
                                 flags.watcher_rigs, flags.watchers, flags.seconds);
    for (size_t i = 0; i < w.rate_without.size() && i < w.rate_with.size(); ++i) {
      std::cout << absl::StrFormat("  round %zu: %.0f traces/s without, %.0f with (%.2fx)\n", i + 1, w.rate_without[i],
                                   w.rate_with[i], w.rate_without[i] > 0 ? w.rate_with[i] / w.rate_without[i] : 0.0);
      without += w.rate_without[i];
      with += w.rate_with[i];
    }
    std::cout << absl::StrFormat("  all rounds: %.2fx (goal >= 0.80); %lld map updates delivered\n",
                                 without > 0 ? with / without : 0.0, static_cast<long long>(w.updates));
  }
  if (flags.only.empty() || flags.only == "reads") {
    ReadLatencyResult r = RunReadLatency(address, object_id, flags.big_trace_samples, flags.heavy_calls, flags.seconds);
    if (!r.error.empty()) {
      std::cout << "\nReads under load: " << r.error << "\n";
    } else {
      std::cout << absl::StrFormat(
          "\nGetJob while %d GetSample(include_series) calls on a %lld-sample trace run (%d done, mean %.0f ms)\n"
          "  alone:      p50 %.2f ms  p99 %.2f ms  max %.2f ms (%d calls)\n"
          "  under load: p50 %.2f ms  p99 %.2f ms  max %.2f ms (%d calls); goal p99 < 20 ms: %s\n",
          flags.heavy_calls, static_cast<long long>(r.trace_samples), r.heavy_calls, r.heavy_mean_ms,
          r.get_job_alone.p50_ms, r.get_job_alone.p99_ms, r.get_job_alone.max_ms, r.get_job_alone.count,
          r.get_job_under_load.p50_ms, r.get_job_under_load.p99_ms, r.get_job_under_load.max_ms,
          r.get_job_under_load.count, r.get_job_under_load.p99_ms < 20 ? "met" : "NOT met");
    }
  }
  if (!flags.only.empty() && flags.only != "throughput") {
    if (own_server) {
      auto stopped = own_server->Stop(std::chrono::seconds(30));
      if (!stopped.ok()) std::cerr << "stopping surfmapd: " << stopped.status() << "\n";
    }
    return 0;
  }

  std::vector<std::pair<int, bool>> runs;  // rigs, combined
  for (int rigs : rig_counts) {
    if (flags.lease != "combined") runs.emplace_back(rigs, false);
    if (flags.lease != "separate") runs.emplace_back(rigs, true);
  }
  std::vector<PhaseResult> phases;
  for (const auto& [rigs, combined] : runs) {
    itest::JobSpecOptions spec;
    spec.mode = pb::SAMPLING_MODE_UNIFORM;
    spec.coarsest_level = flags.level;
    spec.finest_level = flags.level;
    const Clock::time_point creating = Clock::now();
    absl::StatusOr<pb::JobInfo> job = itest::CreateJob(stubs, itest::MakeJobSpec(object_id, spec), flags.token);
    if (!job.ok()) {
      std::cerr << job.status() << "\n";
      return 1;
    }
    std::cout << absl::StrFormat("job %d (uniform, level %d, %d sites pending) created in %.0f ms; %d rig(s) for %.1f s\n",
                                 job->job_id(), flags.level, job->progress().pending() + job->progress().issued(),
                                 Ms(Clock::now() - creating), rigs, flags.seconds);
    phases.push_back(RunThroughput(address, job->job_id(), rigs, combined, flags.seconds, *templates, flags.token));
    if (!phases.back().first_error.empty()) std::cout << "  first error: " << phases.back().first_error << "\n";
    pb::SetJobStateRequest cancel;
    cancel.set_job_id(job->job_id());
    pb::SetJobStateResponse cancelled;
    stubs.jobs->CancelJob(Context(60, flags.token).get(), cancel, &cancelled);  // frees the server's job state
  }

  std::cout << "\nAcknowledged traces (~" << templates->front().samples.size()
            << " samples each, durable before ack)\n";
  std::cout << "rigs  lease      acked   errors  seconds   traces/s   vs first   submit p50 ms   submit p99 ms\n";
  const double base = phases.empty() || phases[0].seconds == 0 ? 0 : phases[0].acked / phases[0].seconds;
  for (const PhaseResult& p : phases) {
    const double rate = p.seconds > 0 ? p.acked / p.seconds : 0.0;
    std::cout << absl::StrFormat("%4d  %-8s  %6d  %7d  %7.2f  %9.0f  %8.2fx  %14.2f  %14.2f%s\n", p.rigs,
                                 p.combined ? "combined" : "separate", p.acked, p.errors, p.seconds, rate,
                                 base > 0 ? rate / base : 0.0, p.submit.p50_ms, p.submit.p99_ms,
                                 p.ran_out ? "  (job ran out of sites)" : "");
  }

  // Map query latency on a finished job: uniform level 1 (~1,400 samples).
  itest::JobSpecOptions small;
  small.mode = pb::SAMPLING_MODE_UNIFORM;
  small.coarsest_level = 1;
  small.finest_level = 1;
  absl::StatusOr<pb::JobInfo> job = itest::CreateJob(stubs, itest::MakeJobSpec(object_id, small), flags.token);
  if (!job.ok()) {
    std::cerr << job.status() << "\n";
    return 1;
  }
  PhaseResult fill = RunThroughput(address, job->job_id(), 4, /*combined=*/true, 600.0, *templates, flags.token);
  absl::StatusOr<pb::JobInfo> done = itest::WaitForJobState(stubs, job->job_id(), pb::JOB_STATE_COMPLETED,
                                                            std::chrono::seconds(60));
  if (!done.ok()) {
    std::cerr << "map job did not complete: " << done.status() << " (" << fill.first_error << ")\n";
    return 1;
  }
  double min_x = 1e300, max_x = -1e300, min_y = 1e300, max_y = -1e300;
  for (const Eigen::Vector3d& p : plate->mesh.positions) {
    min_x = std::min(min_x, p.x());
    max_x = std::max(max_x, p.x());
    min_y = std::min(min_y, p.y());
    max_y = std::max(max_y, p.y());
  }
  std::mt19937_64 random(77);
  std::uniform_real_distribution<double> ux(min_x, max_x), uy(min_y, max_y), uz(-2.0, 2.0);
  std::vector<double> query_ms;
  int query_errors = 0;
  std::string query_error;
  for (int q = 0; q < flags.queries; ++q) {
    pb::QueryMapRequest request;
    request.set_job_id(job->job_id());
    for (int i = 0; i < flags.points; ++i) {
      pb::Vec3* p = request.add_points();
      p->set_x(ux(random));
      p->set_y(uy(random));
      p->set_z(uz(random));
    }
    pb::QueryMapResponse response;
    const Clock::time_point sent = Clock::now();
    grpc::Status status = stubs.maps->QueryMap(Context(30, flags.token).get(), request, &response);
    query_ms.push_back(Ms(Clock::now() - sent));
    if (!status.ok() || response.values_size() != flags.points) {
      if (++query_errors == 1) query_error = status.ok() ? "wrong number of values" : Describe(status);
    }
  }
  LatencySummary query = Summarize(query_ms);
  std::cout << absl::StrFormat(
      "\nQueryMap, %d points per call, job of %d samples, one caller: %d calls, %d errors\n"
      "  mean %.3f ms   p50 %.3f ms   p99 %.3f ms   max %.3f ms\n",
      flags.points, done->progress().measured(), query.count, query_errors, query.mean_ms, query.p50_ms,
      query.p99_ms, query.max_ms);
  if (!query_error.empty()) std::cout << "  first error: " << query_error << "\n";

  const double best = [&] {
    double b = 0;
    for (const PhaseResult& p : phases) b = std::max(b, p.seconds > 0 ? p.acked / p.seconds : 0.0);
    return b;
  }();
  std::cout << absl::StrFormat("\nGoals: >= 2000 traces/s: %s (best %.0f); QueryMap p99 < 2 ms: %s (%.3f ms)\n",
                               best >= 2000 ? "met" : "NOT met", best, query.p99_ms < 2.0 ? "met" : "NOT met",
                               query.p99_ms);
  if (own_server) {
    auto stopped = own_server->Stop(std::chrono::seconds(30));
    if (!stopped.ok()) std::cerr << "stopping surfmapd: " << stopped.status() << "\n";
  }
  return 0;
}

}  // namespace
}  // namespace surfmap::bench

int main(int argc, char** argv) { return surfmap::bench::Main(argc, argv); }
