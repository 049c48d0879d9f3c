#include "tests/bench/steering_load.h"

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

#include "absl/strings/str_cat.h"
#include "tests/bench/bench_stats.h"
#include "tests/bench/trace_templates.h"
#include "tests/support/job_helpers.h"
#include "tests/support/server_process.h"

namespace surfmap::bench {
namespace {

namespace pb = ::surfmap::v1;
using Clock = std::chrono::steady_clock;

// `rigs` rigs submitting (lease_next) for `seconds`; returns traces/s.
double RigPhase(const std::string& address, int64_t job_id, int rigs, double seconds,
                const std::vector<DragTrace>& templates) {
  std::atomic<int> acked{0};
  const Clock::time_point end = Clock::now() + std::chrono::microseconds(static_cast<int64_t>(seconds * 1e6));
  const Clock::time_point start = Clock::now();
  std::vector<std::thread> threads;
  for (int r = 0; r < rigs; ++r) {
    threads.emplace_back([&, r] {
      itest::Stubs stubs(itest::ConnectedChannel(address, /*own_subchannel=*/true));
      const std::string rig_id = absl::StrCat("watch-bench-", r);
      pb::LeaseCommandResponse lease;
      bool have = false;
      size_t next = r;
      while (Clock::now() < end) {
        if (!have) {
          pb::LeaseCommandRequest request;
          request.set_rig_id(rig_id);
          request.set_job_id(job_id);
          if (!stubs.probe->LeaseCommand(itest::Context(30).get(), request, &lease).ok()) continue;
        }
        have = false;
        if (lease.job_finished()) return;
        if (lease.command().command_id() == 0) {
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
          continue;
        }
        pb::SubmitTraceRequest submit;
        submit.set_command_id(lease.command().command_id());
        submit.set_rig_id(rig_id);
        submit.set_lease_next(true);
        *submit.mutable_samples() = PlaceTrace(templates[next++ % templates.size()], lease.command());
        pb::SubmitTraceResponse response;
        if (stubs.probe->SubmitTrace(itest::Context(30).get(), submit, &response).ok()) {
          acked.fetch_add(1);
          lease = response.next();
          have = true;
        }
      }
    });
  }
  for (std::thread& t : threads) t.join();
  return acked.load() / std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

WatcherLoadResult RunWatcherLoad(const std::string& address, int64_t object_id, const std::vector<DragTrace>& templates,
                                 int rigs, int watchers, int rounds, double seconds, int level) {
  WatcherLoadResult result;
  itest::Stubs stubs(itest::ConnectedChannel(address));
  itest::JobSpecOptions spec;
  spec.mode = pb::SAMPLING_MODE_UNIFORM;
  spec.coarsest_level = level;
  spec.finest_level = level;
  absl::StatusOr<pb::JobInfo> job = itest::CreateJob(stubs, itest::MakeJobSpec(object_id, spec));
  if (!job.ok()) return result;
  std::atomic<int64_t> updates{0};
  for (int round = 0; round < rounds; ++round) {
    result.rate_without.push_back(RigPhase(address, job->job_id(), rigs, seconds, templates));
    std::atomic<bool> stop{false};
    std::vector<std::unique_ptr<grpc::ClientContext>> contexts(watchers);
    std::vector<std::thread> threads;
    std::mutex contexts_mu;
    for (int w = 0; w < watchers; ++w) {
      threads.emplace_back([&, w] {
        itest::Stubs watch_stubs(itest::ConnectedChannel(address, /*own_subchannel=*/true));
        pb::WatchJobRequest request;
        request.set_job_id(job->job_id());
        request.set_include_map(true);
        auto context = std::make_unique<grpc::ClientContext>();
        grpc::ClientContext* raw = context.get();
        {
          std::lock_guard<std::mutex> lock(contexts_mu);
          contexts[w] = std::move(context);
        }
        auto reader = watch_stubs.jobs->WatchJob(raw, request);
        pb::JobUpdate update;
        while (!stop.load() && reader->Read(&update)) updates.fetch_add(1);
        raw->TryCancel();
        while (reader->Read(&update)) {
        }
        reader->Finish();
      });
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the streams are open and building
    result.rate_with.push_back(RigPhase(address, job->job_id(), rigs, seconds, templates));
    stop = true;
    {
      std::lock_guard<std::mutex> lock(contexts_mu);
      for (auto& c : contexts) if (c) c->TryCancel();
    }
    for (std::thread& t : threads) t.join();
  }
  result.updates = updates.load();
  pb::SetJobStateRequest cancel;
  cancel.set_job_id(job->job_id());
  pb::SetJobStateResponse cancelled;
  stubs.jobs->CancelJob(itest::Context(30).get(), cancel, &cancelled);
  return result;
}

ReadLatencyResult RunReadLatency(const std::string& address, int64_t object_id, int64_t samples, int heavy,
                                 double seconds) {
  ReadLatencyResult result;
  itest::Stubs stubs(itest::ConnectedChannel(address));
  itest::JobSpecOptions spec;
  spec.mode = pb::SAMPLING_MODE_UNIFORM;
  spec.coarsest_level = 0;
  spec.finest_level = 0;
  absl::StatusOr<pb::JobInfo> job = itest::CreateJob(stubs, itest::MakeJobSpec(object_id, spec));
  if (!job.ok()) {
    result.error = job.status().ToString();
    return result;
  }
  // One long drag, sampled densely enough for ~`samples` samples in 20 mm.
  // The simulated drag lasts ~5.1 s (2 x 20 mm at 10 mm/s, the pause, ramps, settling).
  const double duration_s = 5.1;
  absl::StatusOr<std::vector<DragTrace>> big = MakeTraceTemplates(1, 99, 20.0, samples / duration_s);
  if (!big.ok()) {
    result.error = big.status().ToString();
    return result;
  }
  absl::StatusOr<pb::ProbeCommand> command = itest::LeaseOne(stubs, job->job_id(), "big-rig");
  if (!command.ok()) {
    result.error = command.status().ToString();
    return result;
  }
  pb::TraceSamples all = PlaceTrace(big->front(), *command);
  result.trace_samples = all.t_size();
  {
    // Streamed in chunks of 100,000 samples (each well under the message limit).
    auto context = itest::Context(300);
    pb::SubmitTraceResponse response;
    auto writer = stubs.probe->SubmitTraceStream(context.get(), &response);
    for (int start = 0; start < all.t_size(); start += 100'000) {
      const int end = std::min(all.t_size(), start + 100'000);
      pb::SubmitTraceChunk chunk;
      if (start == 0) {
        chunk.set_command_id(command->command_id());
        chunk.set_rig_id("big-rig");
      }
      pb::TraceSamples* s = chunk.mutable_samples();
      for (int i = start; i < end; ++i) {
        s->add_t(all.t(i));
        s->add_x(all.x(i));
        s->add_y(all.y(i));
        s->add_z(all.z(i));
        s->add_fx(all.fx(i));
        s->add_fy(all.fy(i));
        s->add_fz(all.fz(i));
        s->add_phases(all.phases(i));
      }
      if (!writer->Write(chunk)) break;
    }
    writer->WritesDone();
    grpc::Status status = writer->Finish();
    if (!status.ok()) {
      result.error = "SubmitTraceStream: " + itest::Describe(status);
      return result;
    }
    result.heavy_calls = 0;
    // Keep the trace id for the heavy calls.
    result.trace_samples = all.t_size();
    const int64_t trace_id = response.sample().trace_id();

    auto measure_get_job = [&](double for_seconds) {
      std::vector<double> ms;
      const Clock::time_point end = Clock::now() + std::chrono::microseconds(static_cast<int64_t>(for_seconds * 1e6));
      itest::Stubs reader(itest::ConnectedChannel(address, /*own_subchannel=*/true));
      while (Clock::now() < end) {
        pb::GetJobRequest request;
        request.set_job_id(job->job_id());
        pb::GetJobResponse out;
        const Clock::time_point sent = Clock::now();
        if (reader.jobs->GetJob(itest::Context(30).get(), request, &out).ok()) ms.push_back(Ms(Clock::now() - sent));
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      return Summarize(ms);
    };
    result.get_job_alone = measure_get_job(std::min(seconds, 3.0));

    std::atomic<bool> stop{false};
    std::atomic<int> calls{0};
    std::mutex heavy_mu;
    std::vector<double> heavy_ms;
    std::vector<std::thread> threads;
    for (int h = 0; h < heavy; ++h) {
      threads.emplace_back([&] {
        itest::Stubs heavy_stubs(itest::ConnectedChannel(address, /*own_subchannel=*/true));
        while (!stop.load()) {
          pb::GetSampleRequest request;
          request.set_trace_id(trace_id);
          request.set_include_series(true);
          pb::GetSampleResponse out;
          const Clock::time_point sent = Clock::now();
          if (heavy_stubs.maps->GetSample(itest::Context(300).get(), request, &out).ok()) {
            calls.fetch_add(1);
            std::lock_guard<std::mutex> lock(heavy_mu);
            heavy_ms.push_back(Ms(Clock::now() - sent));
          }
        }
      });
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the heavy calls are under way
    result.get_job_under_load = measure_get_job(seconds);
    stop = true;
    for (std::thread& t : threads) t.join();
    result.heavy_calls = calls.load();
    result.heavy_mean_ms = Summarize(heavy_ms).mean_ms;
  }
  return result;
}

}  // namespace surfmap::bench
