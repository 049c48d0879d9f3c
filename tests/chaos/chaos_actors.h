// The actors of the chaos soak: rigs that lease and submit (and misbehave on
// purpose: identical retries, conflicting retries, traces after their lease
// expired, failure reports), an operator who pauses and resumes, dashboards
// that watch with and without the map, and readers that call everything else
// (GetJob, GetPlan, GetMap, QueryMap, ListSamples, GetSample with series,
// ListJobEvents, RefitJob). Each runs on its own thread with its own seeded
// random stream until told to stop, and reports to the Ledger.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <random>
#include <string>

#include <mutex>
#include "clients/sim/rig/simulated_rig.h"
#include "tests/chaos/chaos_ledger.h"
#include "tests/support/surfmap_client.h"

namespace surfmap::chaos {

// The server's current address (it changes at every restart).
class ServerAddress {
 public:
  void Set(std::string address) {
    std::lock_guard<std::mutex> lock(mu_);
    address_ = std::move(address);
  }
  std::string Get() const {
    std::lock_guard<std::mutex> lock(mu_);
    return address_;
  }

 private:
  mutable std::mutex mu_;
  std::string address_;
};

struct ActorEnv {
  ServerAddress* server = nullptr;
  Ledger* ledger = nullptr;
  const SimulatedRig* rig = nullptr;
  std::atomic<bool>* stop = nullptr;
  std::atomic<bool>* job_cancelled = nullptr;  // set by the operator when it cancels
  int64_t job_id = 0;
  double deadline_s = 10.0;  // every call's deadline
};

void RunRig(const ActorEnv& env, const std::string& rig_id, uint64_t seed);
void RunOperator(const ActorEnv& env, uint64_t seed);
void RunWatcher(const ActorEnv& env, uint64_t seed);
void RunReader(const ActorEnv& env, uint64_t seed);

}  // namespace surfmap::chaos
