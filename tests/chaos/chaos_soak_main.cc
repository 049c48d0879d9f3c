// surfmap-chaos: a bounded, seeded chaos soak of the real surfmapd.
//
// Each round creates a job and lets rigs (some misbehaving on purpose), an
// operator pausing and resuming, dashboards watching with and without the
// map, and readers of everything else loose on it at once for a few seconds;
// in some rounds the server is killed (SIGKILL) at a random moment and
// restarted on the same database, and some rounds end with a cancel. After
// each round the invariants of chaos_ledger.h are checked against the server.
//
//   surfmap-chaos [--rounds N] [--round-seconds S] [--seed S] [--kill-chance P]
//
// CTest runs a short soak (label chaos); run it longer by hand, e.g.
// `surfmap-chaos --rounds 200`. Exit code 1 when any invariant broke.
#include <chrono>
#include <iostream>
#include <random>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include "absl/strings/str_cat.h"
#include "tests/chaos/chaos_actors.h"
#include "tests/support/job_helpers.h"
#include "tests/support/server_process.h"

namespace surfmap::chaos {
namespace {

using std::chrono::milliseconds;

struct SoakOptions {
  int rounds = 6;
  double round_seconds = 3.0;
  uint64_t seed = 1;
  double kill_chance = 0.5;
  double cancel_chance = 0.3;
  int rigs = 3;
};

int Soak(const SoakOptions& options) {
  std::mt19937_64 random(options.seed);
  itest::ServerOptions server_options;
  server_options.config_json = R"({"worker_threads": 2})";
  absl::StatusOr<std::unique_ptr<itest::ServerProcess>> server = itest::ServerProcess::Start(server_options);
  if (!server.ok()) {
    std::cerr << "surfmap-chaos: " << server.status() << "\n";
    return 2;
  }
  absl::StatusOr<std::unique_ptr<SimulatedRig>> rig = itest::MakeSceneRig("plate");
  if (!rig.ok()) {
    std::cerr << "surfmap-chaos: " << rig.status() << "\n";
    return 2;
  }
  ServerAddress address;
  address.Set((*server)->address());
  Ledger ledger;
  std::vector<int64_t> jobs;
  int checks = 0;
  const auto started = std::chrono::steady_clock::now();

  absl::StatusOr<pb::ObjectInfo> object;
  {
    itest::Stubs stubs((*server)->channel());
    object = itest::UploadSceneMesh(stubs, **rig);
  }
  if (!object.ok()) {
    std::cerr << "surfmap-chaos: " << object.status() << "\n";
    return 2;
  }

  for (int round = 1; round <= options.rounds; ++round) {
    itest::Stubs stubs(itest::ConnectedChannel(address.Get()));
    itest::JobSpecOptions spec;
    // BOUNDARY (the default job's mode) issues commands as rigs ask
    // (command_lookahead.h); the others issue every site at once.
    constexpr pb::SamplingMode kModes[] = {pb::SAMPLING_MODE_UNIFORM, pb::SAMPLING_MODE_ADAPTIVE,
                                           pb::SAMPLING_MODE_BOUNDARY};
    spec.mode = kModes[std::uniform_int_distribution<int>(0, 2)(random)];
    spec.coarsest_level = 0;
    spec.finest_level = 2;
    spec.threshold = 2.0;
    spec.lease_s = 1.0;  // short: slow rigs outlive their leases
    spec.max_retries = 3;
    spec.seed = options.seed * 1000 + static_cast<uint64_t>(round);
    absl::StatusOr<pb::JobInfo> job = itest::CreateJob(stubs, itest::MakeJobSpec(object->object_id(), spec));
    if (!job.ok()) {
      ledger.Violation(absl::StrCat("round ", round, ": CreateJob: ", job.status().ToString()));
      break;
    }
    jobs.push_back(job->job_id());

    std::atomic<bool> stop{false}, cancelled{false};
    ActorEnv env{&address, &ledger, rig->get(), &stop, &cancelled, job->job_id(), 10.0};
    std::vector<std::thread> actors;
    const uint64_t base = options.seed * 7919 + static_cast<uint64_t>(round) * 104729;
    for (int i = 0; i < options.rigs; ++i) {
      actors.emplace_back(RunRig, env, absl::StrCat("rig-", round, "-", i), base + i);
    }
    actors.emplace_back(RunOperator, env, base + 101);
    actors.emplace_back(RunWatcher, env, base + 102);
    actors.emplace_back(RunWatcher, env, base + 103);
    actors.emplace_back(RunReader, env, base + 104);
    actors.emplace_back(RunReader, env, base + 105);

    const int round_ms = static_cast<int>(options.round_seconds * 1000);
    bool killed = false;
    if (std::uniform_real_distribution<double>(0, 1)(random) < options.kill_chance) {
      std::this_thread::sleep_for(milliseconds(std::uniform_int_distribution<int>(round_ms / 5, round_ms * 3 / 5)(random)));
      if (absl::Status s = (*server)->Kill(); !s.ok()) ledger.Violation(absl::StrCat("kill: ", s.ToString()));
      ledger.NoteKill();
      killed = true;
      std::this_thread::sleep_for(milliseconds(std::uniform_int_distribution<int>(100, 600)(random)));
      if (absl::Status s = (*server)->Restart(); !s.ok()) {
        std::cerr << "surfmap-chaos: restart failed: " << s << "\n" << (*server)->LogTail() << "\n";
        stop = true;
        for (std::thread& t : actors) t.join();
        return 1;
      }
      address.Set((*server)->address());
      std::this_thread::sleep_for(milliseconds(round_ms * 2 / 5));
    } else {
      std::this_thread::sleep_for(milliseconds(round_ms));
    }
    if (std::uniform_real_distribution<double>(0, 1)(random) < options.cancel_chance) {
      itest::Stubs steer(itest::ConnectedChannel(address.Get()));
      pb::SetJobStateRequest request;
      request.set_job_id(job->job_id());
      pb::SetJobStateResponse response;
      cancelled = true;
      grpc::Status status = steer.jobs->CancelJob(itest::Context(10).get(), request, &response);
      if (!status.ok() && status.error_code() != grpc::StatusCode::FAILED_PRECONDITION) {
        ledger.Violation(absl::StrCat("round ", round, ": CancelJob: ", itest::Describe(status)));
      }
    }
    stop = true;
    for (std::thread& t : actors) t.join();

    itest::Stubs check(itest::ConnectedChannel(address.Get()));
    checks += ledger.CheckAgainstServer(check, jobs);
    std::cout << "round " << round << ": " << (killed ? "killed and restarted, " : "") << ledger.calls() << " calls, "
              << ledger.acks() << " acknowledged traces, " << ledger.leases() << " leases, "
              << ledger.violations().size() << " violations\n"
              << std::flush;
  }
  // A graceful stop must still work after all that.
  absl::StatusOr<itest::ServerExit> exit = (*server)->Stop(std::chrono::seconds(30));
  if (!exit.ok() || !exit->exited || exit->code != 0) {
    ledger.Violation(absl::StrCat("graceful stop: ", exit.ok() ? absl::StrCat("exit code ", exit->code, " signal ",
                                                                             exit->signal)
                                                               : exit.status().ToString()));
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const std::vector<std::string> violations = ledger.violations();
  std::cout << "surfmap-chaos: " << options.rounds << " rounds in " << seconds << " s, " << ledger.calls()
            << " calls, " << ledger.kills() << " kill -9 restarts, " << ledger.acks() << " acknowledged traces, "
            << ledger.leases() << " leases, " << checks << " invariant checks, " << violations.size()
            << " violations\n";
  for (const std::string& v : violations) std::cout << "  VIOLATION " << v << "\n";
  if (!violations.empty()) std::cout << (*server)->LogTail() << "\n";
  return violations.empty() ? 0 : 1;
}

}  // namespace
}  // namespace surfmap::chaos

int main(int argc, char** argv) {
  CLI::App app{"surfmap-chaos: seeded chaos soak of surfmapd (rigs, steering, watchers, readers, kill -9)"};
  surfmap::chaos::SoakOptions options;
  app.add_option("--rounds", options.rounds, "Rounds (each: a new job, all actors at once)")->check(CLI::Range(1, 100000));
  app.add_option("--round-seconds", options.round_seconds, "Length of a round")->check(CLI::Range(0.5, 600.0));
  app.add_option("--seed", options.seed, "Seed of every random choice");
  app.add_option("--kill-chance", options.kill_chance, "Chance a round kills (SIGKILL) and restarts the server")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--rigs", options.rigs, "Rigs per round")->check(CLI::Range(1, 32));
  CLI11_PARSE(app, argc, argv);
  return surfmap::chaos::Soak(options);
}
