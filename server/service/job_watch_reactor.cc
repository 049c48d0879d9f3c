#include "server/service/job_watch_reactor.h"

#include "server/service/proto_builders.h"
#include "server/service/proto_conversion.h"

namespace surfmap {

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
  if (stream->building.exchange(true)) return;  // the running build will see `dirty`
  // A continuation of an admitted stream: never refused.
  stream->services.pool->Post([stream] { BuildLoop(stream); });
}

void JobWatchReactor::BuildLoop(const std::shared_ptr<Stream>& stream) {
  for (;;) {
    {
      MutexLock lock(&stream->mu);
      if (stream->reactor == nullptr || stream->finished || stream->final_sent ||
          (stream->writing && stream->next.has_value())) {
        // Gone, done, or a slow client with an update already waiting: keep
        // `dirty`; OnWriteDone wakes the stream again.
        stream->building.store(false);
        return;
      }
    }
    stream->dirty.store(false);
    bool final = false;
    absl::StatusOr<pb::JobUpdate> update = BuildUpdate(*stream, &final);  // no lock held
    {
      MutexLock lock(&stream->mu);
      if (stream->reactor != nullptr) {
        if (update.ok()) {
          stream->OfferLocked(std::move(*update), final);
        } else {
          stream->FinishLocked(ToGrpcStatus(update.status()));
        }
      }
    }
    stream->building.store(false);
    if (!stream->dirty.load() || stream->building.exchange(true)) return;
  }
}

absl::StatusOr<pb::JobUpdate> JobWatchReactor::BuildUpdate(const Stream& stream, bool* final) {
  JobCoordinator& coordinator = *stream.services.coordinator;
  absl::StatusOr<JobSnapshot> job = coordinator.GetJob(stream.job_id);
  if (!job.ok()) return job.status();
  pb::JobUpdate update;
  // The state is the durable one: the final update is built after the job's
  // last write committed, so the samples read below include all of it.
  *update.mutable_job() = JobInfoToProto(*job);
  *final = IsFinalJobState(job->record.state);
  if (job->latest_sample) {
    absl::StatusOr<pb::Sample> latest = BuildSample(*job->latest_sample);
    if (!latest.ok()) return latest.status();
    *update.mutable_latest_sample() = std::move(*latest);
  }
  if (stream.include_map) {
    // An update without the map that was asked for would look like a job
    // with no samples: end the stream with the reason instead.
    absl::StatusOr<MapSnapshot> map = coordinator.Map(stream.job_id);
    if (!map.ok()) return map.status();
    absl::StatusOr<std::vector<SampleRecord>> samples = coordinator.reads().ListSamples(stream.job_id, 0);
    if (!samples.ok()) return samples.status();
    absl::Status filled = FillMapLevel(*map, map->surface->max_level(), *samples, stream.job_id, update.mutable_map());
    if (!filled.ok()) return filled;
  }
  return update;
}

void JobWatchReactor::Stream::OfferLocked(pb::JobUpdate update, bool final) {
  if (finished || final_sent) return;
  if (writing) {
    next = std::move(update);  // replaces an older waiting update
    next_final = final;
    return;
  }
  SendLocked(std::move(update), final);
}

void JobWatchReactor::Stream::SendLocked(pb::JobUpdate update, bool final) {
  in_flight = std::move(update);
  writing = true;
  final_sent = final;
  reactor->StartWrite(&in_flight);
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
    if (stream_->next.has_value()) {
      pb::JobUpdate next = std::move(*stream_->next);
      stream_->next.reset();
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
