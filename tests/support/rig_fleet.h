// RigFleet: N simulated rigs, each a thread with its own gRPC connection,
// working one job on a real server the way a lab rig does: LeaseCommand ->
// execute the drag (SimulatedRig) -> SubmitTrace, or ReportFailure when the
// rig cannot measure; sleep `retry_after` when nothing is ready; stop on
// job_finished. Everything the rigs saw is recorded so tests can check that
// no command ran twice and no acknowledged trace was lost.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <grpcpp/channel.h>
#include "clients/sim/rig/simulated_rig.h"
#include "tests/support/surfmap_client.h"

namespace surfmap::itest {

struct RigFleetOptions {
  int rigs = 4;
  std::int64_t job_id = 0;            // 0 = any running job
  std::string rig_prefix = "rig";     // rig ids are <prefix>-<i>
  // Seed each trace by its site (SiteSeedId) instead of the command id, so a
  // run's traces do not depend on the order commands were issued in.
  bool seed_by_site = true;
  double call_deadline_s = 60.0;
  double max_retry_sleep_s = 0.2;     // cap on the server's retry_after
  // Stop after a failed RPC (e.g. the server was killed) instead of retrying.
  bool stop_on_rpc_error = true;
};

struct RigAck {
  std::string rig;
  std::int64_t command_id = 0;
  pb::Site site;
  std::int64_t trace_id = 0;
  bool already_accepted = false;
  pb::TraceSamples samples;      // exactly what was sent
  pb::Sample sample;             // what the server fitted
};

struct RigLease {
  std::string rig;
  std::int64_t command_id = 0;
  pb::Site site;
  int attempt = 0;
};

struct RigFleetRecord {
  std::vector<RigLease> leases;             // every command handed out
  std::vector<RigAck> acks;                 // every OK SubmitTrace
  std::vector<std::int64_t> reported_failures;  // command ids given to ReportFailure
  std::vector<std::string> failure_reasons;     // the rig's reason for each, same order
  std::vector<std::string> rpc_errors;      // "rig-2 SubmitTrace(command 17): UNAVAILABLE: ..."
  int rigs_saw_job_finished = 0;
};

class RigFleet {
 public:
  // `rig` must outlive the fleet (SimulatedRig::Execute is thread-safe).
  RigFleet(std::string address, const SimulatedRig& rig, RigFleetOptions options);
  ~RigFleet();  // RequestStop() + Join()

  void Start();
  void RequestStop() { stop_.store(true); }
  void Join();
  // Runs to the end (every rig saw job_finished, or an RPC error stopped it).
  RigFleetRecord Run();

  // Acknowledged fresh traces so far (not counting already_accepted).
  int acked() const { return acked_.load(); }
  RigFleetRecord record() const;

 private:
  void RigLoop(int index);

  std::string address_;
  const SimulatedRig& rig_;
  RigFleetOptions options_;
  std::atomic<bool> stop_{false};
  std::atomic<int> acked_{0};
  std::vector<std::thread> threads_;
  mutable std::mutex mutex_;
  RigFleetRecord record_;
};

}  // namespace surfmap::itest
