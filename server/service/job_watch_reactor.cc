#include "server/service/job_watch_reactor.h"

#include "server/service/proto_builders.h"
#include "server/service/proto_conversion.h"

namespace surfmap {
namespace {

// A dashboard redraws a few times a second at most; a plain progress stream
// may tick faster. See the header.
constexpr std::chrono::milliseconds kMapUpdateInterval{250};
constexpr std::chrono::milliseconds kUpdateInterval{50};

int64_t SteadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

JobWatchReactor* JobWatchReactor::Start(const ServiceContext& services, int64_t job_id, bool include_map) {
  auto stream = std::make_shared<Stream>(services, job_id, include_map);
  auto* reactor = new JobWatchReactor(stream);
  MutexLock lock(&stream->mu);
  stream->reactor = reactor;
  // Subscribing may load the job (long): on the pool.
  if (!services.pool->Submit([stream] { Subscribe(stream); })) {
    stream->FinishLocked(ToGrpcStatus(absl::UnavailableError("server busy: work queue full, retry later")));
  }
  return reactor;
}

void JobWatchReactor::Subscribe(const std::shared_ptr<Stream>& stream) {
  std::weak_ptr<Stream> weak = stream;
  absl::StatusOr<JobCoordinator::WatchHandle> handle =
      stream->services.coordinator->Watch(stream->job_id, [weak] {
        if (std::shared_ptr<Stream> alive = weak.lock()) OnChange(alive);
      });
  {
    MutexLock lock(&stream->mu);
    if (!handle.ok()) {
      if (stream->reactor != nullptr) stream->FinishLocked(ToGrpcStatus(handle.status()));
      return;
    }
    if (stream->reactor == nullptr) {  // the stream ended while subscribing
      JobCoordinator::Unwatch(*handle);
      return;
    }
    stream->handle = std::move(*handle);
  }
  OnChange(stream);  // the first update
}

void JobWatchReactor::OnChange(const std::shared_ptr<Stream>& stream) {
  stream->dirty.store(true);
  if (stream->building.exchange(true)) return;  // the scheduled build will see `dirty`
  ScheduleBuild(stream);
}

void JobWatchReactor::ScheduleBuild(const std::shared_ptr<Stream>& stream) {
  // A continuation of an admitted stream: never refused by the pool.
  auto post = [stream] { stream->services.pool->Post([stream] { Build(stream); }); };
  const int64_t due_ns = stream->next_build_ns.load();
  if (due_ns <= SteadyNowNs()) {
    post();
  } else {
    stream->services.timers->RunAt(TimerQueue::Clock::time_point(std::chrono::nanoseconds(due_ns)), post);
  }
}

void JobWatchReactor::Build(const std::shared_ptr<Stream>& stream) {
  {
    MutexLock lock(&stream->mu);
    if (stream->reactor == nullptr || stream->finished || stream->final_sent ||
        (stream->writing && stream->next != nullptr)) {
      // Gone, done, or a slow client with an update already waiting: keep
      // `dirty`; OnWriteDone wakes the stream again.
      stream->building.store(false);
      return;
    }
  }
  const auto interval = stream->include_map ? kMapUpdateInterval : kUpdateInterval;
  stream->next_build_ns.store(SteadyNowNs() + std::chrono::duration_cast<std::chrono::nanoseconds>(interval).count());
  stream->dirty.store(false);
  absl::StatusOr<SharedUpdate> update =
      stream->services.watch_updates->Get(stream->job_id, stream->include_map);  // no lock held
  {
    MutexLock lock(&stream->mu);
    if (stream->reactor != nullptr) {
      if (update.ok()) {
        stream->OfferLocked(std::move(update->update), update->final);
      } else {
        stream->FinishLocked(ToGrpcStatus(update.status()));
      }
    }
  }
  stream->building.store(false);
  if (stream->dirty.load() && !stream->building.exchange(true)) ScheduleBuild(stream);
}

void JobWatchReactor::Stream::OfferLocked(std::shared_ptr<const pb::JobUpdate> update, bool final) {
  if (finished || final_sent) return;
  if (writing) {
    next = std::move(update);  // replaces an older waiting update
    next_final = final;
    return;
  }
  SendLocked(std::move(update), final);
}

void JobWatchReactor::Stream::SendLocked(std::shared_ptr<const pb::JobUpdate> update, bool final) {
  in_flight = std::move(update);  // kept alive until OnWriteDone
  writing = true;
  final_sent = final;
  reactor->StartWrite(in_flight.get());
}

void JobWatchReactor::Stream::FinishLocked(const grpc::Status& status) {
  if (finished) return;
  finished = true;
  if (writing) {
    pending_finish = status;
  } else {
    reactor->Finish(status);
  }
}

void JobWatchReactor::OnWriteDone(bool ok) {
  bool wake = false;
  {
    MutexLock lock(&stream_->mu);
    stream_->writing = false;
    if (stream_->pending_finish) {
      Finish(*stream_->pending_finish);
      return;
    }
    if (!ok || stream_->final_sent) {
      stream_->FinishLocked(grpc::Status::OK);  // the client went away, or the job ended
      return;
    }
    if (stream_->next != nullptr) {
      std::shared_ptr<const pb::JobUpdate> next = std::move(stream_->next);
      stream_->next = nullptr;
      stream_->SendLocked(std::move(next), stream_->next_final);
    }
    wake = stream_->dirty.load();
  }
  if (wake) OnChange(stream_);
}

void JobWatchReactor::OnCancel() {
  MutexLock lock(&stream_->mu);
  stream_->FinishLocked(grpc::Status::CANCELLED);
}

void JobWatchReactor::OnDone() {
  JobCoordinator::WatchHandle handle;
  {
    MutexLock lock(&stream_->mu);
    handle = std::move(stream_->handle);
    stream_->reactor = nullptr;  // late listeners and pool tasks see it gone
  }
  JobCoordinator::Unwatch(handle);
  delete this;
}

}  // namespace surfmap
