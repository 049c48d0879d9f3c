// What the chaos soak's clients saw, and the invariants checked against the
// server after every round:
//   - every call returned within its deadline (a call that ran across a
//     kill -9 is excused: the server it talked to is gone);
//   - every acknowledged trace is stored, with exactly the samples the rig
//     that was told OK sent (so no acknowledgement was for data not stored);
//   - a command was never held by two rigs at once (a lease is only granted
//     again after the previous one's deadline);
//   - after a restart the plan and the stored traces agree (one trace per
//     measured site, and as many traces as measured sites).
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "tests/support/surfmap_client.h"

namespace surfmap::chaos {

namespace pb = ::surfmap::v1;

struct LeaseSeen {
  std::string rig;
  int64_t command_id = 0;
  int64_t received_unix_ms = 0;   // client clock when the answer arrived
  int64_t deadline_unix_ms = 0;   // the lease deadline the server gave
};

struct AckSeen {
  std::string rig;
  int64_t job_id = 0;
  int64_t command_id = 0;
  int64_t trace_id = 0;
  pb::TraceSamples samples;  // exactly what this rig sent
};

class Ledger {
 public:
  // Kills so far; a call notes it before and after to know whether a kill
  // happened while it ran.
  int64_t kill_epoch() const { return kills_.load(); }
  void NoteKill() { kills_.fetch_add(1); }

  void AddCall() { calls_.fetch_add(1); }
  // `what` failed in a way the service must never answer.
  void Violation(const std::string& what);
  void AddLease(LeaseSeen lease);
  void AddAck(AckSeen ack);

  // Checks the invariants against the server behind `stubs`; appends the
  // violations found. Returns the number of checks made.
  int CheckAgainstServer(itest::Stubs& stubs, const std::vector<int64_t>& job_ids);

  int64_t calls() const { return calls_.load(); }
  int64_t kills() const { return kills_.load(); }
  size_t acks() const;
  size_t leases() const;
  std::vector<std::string> violations() const;

 private:
  std::atomic<int64_t> calls_{0};
  std::atomic<int64_t> kills_{0};
  mutable std::mutex mu_;
  std::vector<LeaseSeen> leases_;
  std::vector<AckSeen> acks_;
  std::vector<std::string> violations_;
  size_t acks_checked_ = 0;  // acks before this index were checked already
};

}  // namespace surfmap::chaos
