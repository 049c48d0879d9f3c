// Test helpers shared by the storage tests and the benchmark: deterministic
// traces and a populated job.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "storage/records.h"
#include "storage/store.h"

namespace surfmap {

// A drag trace shaped like the paper's (forward, pause, reverse), n samples,
// deterministic for a seed.
inline std::vector<StoredSample> MakeTestSamples(int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<StoredSample> samples(n);
  for (int i = 0; i < n; ++i) {
    StoredSample& s = samples[i];
    const double u = static_cast<double>(i) / n;
    s.phase = static_cast<uint8_t>(u < 0.45 ? 0 : (u < 0.55 ? 1 : 2));
    s.t = 0.01 * i;
    s.x = 10.0 + 20.0 * (s.phase == 2 ? 1.0 - u : u);
    s.y = -5.0 + noise(rng);
    s.z = 3.0 + noise(rng);
    s.fx = (s.phase == 0 ? -0.65 : 0.65) + noise(rng);
    s.fy = noise(rng);
    s.fz = 6.0 + noise(rng);
  }
  return samples;
}

inline NewFit MakeTestFit(double mu) {
  NewFit fit;
  fit.estimator_name = "differential+ar2";
  fit.estimator_version = "1.0.0";
  fit.options_json = R"({"window":0.8})";
  fit.result_json = absl::StrCat(R"({"mu":)", mu, "}");
  fit.mu = mu;
  fit.a1 = 0.6;
  fit.a2 = 0.25;
  fit.sigma = 0.11;
  return fit;
}

inline NewCommand MakeTestCommand(int level, int vertex) {
  return NewCommand{level, vertex, absl::StrCat(R"({"site":[)", level, ",", vertex, "]}")};
}

// An object and a running job with n_commands pending commands.
// A job on a one-triangle object with exactly these commands.
inline absl::StatusOr<CreatedJob> MakeTestJob(Store& store, std::vector<NewCommand> commands) {
  NewObject object{"bottle", "obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 3, 1};
  absl::StatusOr<int64_t> object_id = store.CreateObject(object);
  if (!object_id.ok()) return object_id.status();
  NewJob job;
  job.object_id = *object_id;
  job.params_json = R"({"threshold":0.1})";
  job.plan_json = R"({"measured":[]})";
  job.commands = std::move(commands);
  job.events.push_back(NewEvent{"job_created", "{}"});
  return store.CreateJob(job);
}

// ... with n_commands commands for the level-0 sites 0..n-1.
inline absl::StatusOr<CreatedJob> MakeTestJob(Store& store, int n_commands) {
  std::vector<NewCommand> commands;
  for (int i = 0; i < n_commands; ++i) commands.push_back(MakeTestCommand(0, i));
  return MakeTestJob(store, std::move(commands));
}

inline AcceptTraceRequest MakeTestAccept(const CommandRecord& command, int n_samples) {
  AcceptTraceRequest r;
  r.command_id = command.id;
  r.job_id = command.job_id;
  r.lease_owner = command.lease_owner;
  r.samples = MakeTestSamples(n_samples, static_cast<uint64_t>(command.id));
  r.fit = MakeTestFit(0.1 + 0.001 * static_cast<double>(command.id));
  r.new_plan_json = absl::StrCat(R"({"last":)", command.id, "}");
  r.events.push_back(NewEvent{"trace_accepted", absl::StrCat(R"({"command":)", command.id, "}")});
  return r;
}

}  // namespace surfmap
