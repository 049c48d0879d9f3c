#include "tests/support/rig_fleet.h"

#include <algorithm>
#include <chrono>

#include "server/codec/trace_samples_proto.h"
#include "absl/strings/str_cat.h"
#include "tests/support/server_process.h"

namespace surfmap::itest {

RigFleet::RigFleet(std::string address, const SimulatedRig& rig, RigFleetOptions options)
    : address_(std::move(address)), rig_(rig), options_(std::move(options)) {}

RigFleet::~RigFleet() {
  RequestStop();
  Join();
}

void RigFleet::Start() {
  for (int i = 0; i < options_.rigs; ++i) threads_.emplace_back([this, i] { RigLoop(i); });
}

void RigFleet::Join() {
  for (std::thread& t : threads_) {
    if (t.joinable()) t.join();
  }
  threads_.clear();
}

RigFleetRecord RigFleet::Run() {
  Start();
  Join();
  return record();
}

RigFleetRecord RigFleet::record() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return record_;
}

void RigFleet::RigLoop(int index) {
  const std::string rig_id = absl::StrCat(options_.rig_prefix, "-", index);
  Stubs stubs(ConnectedChannel(address_, /*own_subchannel=*/true));
  auto rpc_error = [&](const std::string& what, const grpc::Status& status) {
    std::lock_guard<std::mutex> lock(mutex_);
    record_.rpc_errors.push_back(absl::StrCat(rig_id, " ", what, ": ", Describe(status)));
  };

  while (!stop_.load()) {
    pb::LeaseCommandRequest lease_request;
    lease_request.set_rig_id(rig_id);
    lease_request.set_job_id(options_.job_id);
    pb::LeaseCommandResponse lease;
    grpc::Status status = stubs.probe->LeaseCommand(Context(options_.call_deadline_s).get(), lease_request, &lease);
    if (!status.ok()) {
      rpc_error("LeaseCommand", status);
      if (options_.stop_on_rpc_error) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      continue;
    }
    if (lease.job_finished()) {
      std::lock_guard<std::mutex> lock(mutex_);
      ++record_.rigs_saw_job_finished;
      return;
    }
    if (!lease.has_command() || lease.command().command_id() == 0) {
      double wait = lease.retry_after().seconds() + lease.retry_after().nanos() * 1e-9;
      wait = std::clamp(wait, 0.002, options_.max_retry_sleep_s);
      std::this_thread::sleep_for(std::chrono::microseconds(static_cast<int64_t>(wait * 1e6)));
      continue;
    }
    const pb::ProbeCommand& command = lease.command();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      record_.leases.push_back({rig_id, command.command_id(), command.site(), command.attempt()});
    }

    const int64_t seed_id = options_.seed_by_site ? SiteSeedId(command.site()) : command.command_id();
    absl::StatusOr<ProbeRequest> request = SeededProbeRequest(command, seed_id);
    absl::StatusOr<ProbeExecution> execution =
        request.ok() ? rig_.ExecuteDetailed(*request) : absl::StatusOr<ProbeExecution>(request.status());
    if (!execution.ok()) {
      pb::ReportFailureRequest failure;
      failure.set_command_id(command.command_id());
      failure.set_rig_id(rig_id);
      failure.set_reason(std::string(execution.status().message()));
      pb::ReportFailureResponse failure_response;
      status = stubs.probe->ReportFailure(Context(options_.call_deadline_s).get(), failure, &failure_response);
      if (!status.ok()) {
        rpc_error(absl::StrCat("ReportFailure(command ", command.command_id(), ")"), status);
        if (options_.stop_on_rpc_error) return;
      } else {
        std::lock_guard<std::mutex> lock(mutex_);
        record_.reported_failures.push_back(command.command_id());
        record_.failure_reasons.push_back(absl::StrCat("command ", command.command_id(), " site (",
                                                       command.site().level(), ", ", command.site().vertex(),
                                                       ") at (", command.position().x(), ", ",
                                                       command.position().y(), ", ", command.position().z(),
                                                       "): ", failure.reason()));
      }
      continue;
    }

    pb::SubmitTraceRequest submit;
    submit.set_command_id(command.command_id());
    submit.set_rig_id(rig_id);
    *submit.mutable_samples() = DragTraceToProto(execution->trace);
    pb::SubmitTraceResponse response;
    status = stubs.probe->SubmitTrace(Context(options_.call_deadline_s).get(), submit, &response);
    if (!status.ok()) {
      rpc_error(absl::StrCat("SubmitTrace(command ", command.command_id(), ")"), status);
      if (options_.stop_on_rpc_error) return;
      continue;
    }
    RigAck ack{rig_id, command.command_id(), command.site(), response.sample().trace_id(),
               response.already_accepted(), std::move(*submit.mutable_samples()), response.sample()};
    if (!ack.already_accepted) acked_.fetch_add(1);
    std::lock_guard<std::mutex> lock(mutex_);
    record_.acks.push_back(std::move(ack));
  }
}

}  // namespace surfmap::itest
