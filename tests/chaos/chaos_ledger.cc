#include "tests/chaos/chaos_ledger.h"

#include <algorithm>
#include <set>

#include "absl/strings/str_cat.h"

namespace surfmap::chaos {

void Ledger::Violation(const std::string& what) {
  std::lock_guard<std::mutex> lock(mu_);
  violations_.push_back(what);
}

void Ledger::AddLease(LeaseSeen lease) {
  std::lock_guard<std::mutex> lock(mu_);
  leases_.push_back(std::move(lease));
}

void Ledger::AddAck(AckSeen ack) {
  std::lock_guard<std::mutex> lock(mu_);
  acks_.push_back(std::move(ack));
}

size_t Ledger::acks() const {
  std::lock_guard<std::mutex> lock(mu_);
  return acks_.size();
}

size_t Ledger::leases() const {
  std::lock_guard<std::mutex> lock(mu_);
  return leases_.size();
}

std::vector<std::string> Ledger::violations() const {
  std::lock_guard<std::mutex> lock(mu_);
  return violations_;
}

int Ledger::CheckAgainstServer(itest::Stubs& stubs, const std::vector<int64_t>& job_ids) {
  std::vector<AckSeen> acks;
  std::vector<LeaseSeen> leases;
  {
    std::lock_guard<std::mutex> lock(mu_);
    acks.assign(acks_.begin() + static_cast<std::ptrdiff_t>(acks_checked_), acks_.end());
    acks_checked_ = acks_.size();
    leases = leases_;
  }
  int checks = 0;
  std::vector<std::string> found;

  // Acknowledged traces are stored exactly as their rig sent them.
  for (const AckSeen& ack : acks) {
    pb::GetTraceRequest request;
    request.set_trace_id(ack.trace_id);
    pb::GetTraceResponse trace;
    grpc::Status status = stubs.traces->GetTrace(itest::Context(60).get(), request, &trace);
    ++checks;
    if (!status.ok()) {
      found.push_back(absl::StrCat("acknowledged trace ", ack.trace_id, " (command ", ack.command_id, ", ", ack.rig,
                                   ") cannot be read: ", itest::Describe(status)));
      continue;
    }
    std::string difference;
    if (trace.command_id() != ack.command_id || !itest::SameSamples(trace.samples(), ack.samples, &difference)) {
      found.push_back(absl::StrCat("trace ", ack.trace_id, " acknowledged to ", ack.rig,
                                   " does not hold what it sent: ", difference));
    }
  }

  // Never two holders: a command is leased again only after the previous
  // lease's deadline (the new answer arrives after the server granted it).
  std::map<int64_t, std::vector<const LeaseSeen*>> by_command;
  for (const LeaseSeen& l : leases) by_command[l.command_id].push_back(&l);
  for (auto& [command, list] : by_command) {
    std::sort(list.begin(), list.end(),
              [](const LeaseSeen* a, const LeaseSeen* b) { return a->received_unix_ms < b->received_unix_ms; });
    for (size_t i = 1; i < list.size(); ++i) {
      ++checks;
      if (list[i]->received_unix_ms < list[i - 1]->deadline_unix_ms && list[i]->rig != list[i - 1]->rig) {
        found.push_back(absl::StrCat("command ", command, " leased to ", list[i]->rig, " at ",
                                     list[i]->received_unix_ms, " while ", list[i - 1]->rig,
                                     "'s lease ran until ", list[i - 1]->deadline_unix_ms));
      }
    }
  }

  // The plan and the stored traces agree.
  for (int64_t job_id : job_ids) {
    pb::GetPlanRequest plan_request;
    plan_request.set_job_id(job_id);
    pb::GetPlanResponse plan;
    grpc::Status status = stubs.jobs->GetPlan(itest::Context(60).get(), plan_request, &plan);
    pb::ListSamplesRequest samples_request;
    samples_request.set_job_id(job_id);
    pb::ListSamplesResponse samples;
    if (status.ok()) status = stubs.maps->ListSamples(itest::Context(60).get(), samples_request, &samples);
    ++checks;
    if (!status.ok()) {
      found.push_back(absl::StrCat("job ", job_id, ": plan or samples unreadable: ", itest::Describe(status)));
      continue;
    }
    std::set<int> measured;
    for (const pb::PlanSite& site : plan.sites()) {
      if (site.state() == pb::SITE_STATE_MEASURED) measured.insert(site.site().vertex());
    }
    std::map<int, int> traces_per_vertex;
    for (const pb::Sample& s : samples.samples()) traces_per_vertex[s.site().vertex()]++;
    if (static_cast<int>(measured.size()) != samples.samples_size()) {
      found.push_back(absl::StrCat("job ", job_id, ": the plan has ", measured.size(), " measured sites but ",
                                   samples.samples_size(), " traces are stored"));
    }
    for (const auto& [vertex, n] : traces_per_vertex) {
      if (n != 1) found.push_back(absl::StrCat("job ", job_id, ": vertex ", vertex, " has ", n, " traces"));
      if (!measured.count(vertex)) {
        found.push_back(absl::StrCat("job ", job_id, ": vertex ", vertex, " has a trace but is not measured in the plan"));
      }
    }
  }
  std::lock_guard<std::mutex> lock(mu_);
  violations_.insert(violations_.end(), found.begin(), found.end());
  return checks;
}

}  // namespace surfmap::chaos
