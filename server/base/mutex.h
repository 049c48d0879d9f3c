// Mutex, MutexLock, Notification: the locks of every threaded layer.
//
// Why not Mutex: Debian's abseil is built without ThreadSanitizer
// support, so TSan cannot see an Mutex being taken and would report
// every guarded access as a race. These are built on the standard library
// (pthreads, which TSan intercepts), keep absl's calling style, and carry
// clang's thread-safety attributes, so `ABSL_GUARDED_BY(mu_)` and friends are
// checked at compile time (scripts/check-thread-safety.sh).
//
// Await: absl-style conditional waits. The predicate runs with the lock held
// and is re-checked whenever the lock is released by another thread (every
// Unlock, and every wait, wakes the waiters, which costs nothing without
// waiters).
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>

#include "absl/base/thread_annotations.h"

namespace surfmap {

class ABSL_LOCKABLE Mutex {
 public:
  Mutex() = default;
  Mutex(const Mutex&) = delete;
  Mutex& operator=(const Mutex&) = delete;

  void Lock() ABSL_EXCLUSIVE_LOCK_FUNCTION() { mu_.lock(); }
  void Unlock() ABSL_UNLOCK_FUNCTION() {
    changed_.notify_all();
    mu_.unlock();
  }

  // Waits, with the lock released meanwhile, until pred() is true.
  // The wait releases the lock without Unlock(), so it first wakes the
  // other waiters itself: the caller may have changed what they wait for in
  // this same critical section (the fault-injecting store marks a write
  // held, then waits for its release; without this, a test waiting to see
  // it held slept until its 10 s timeout).
  template <typename Predicate>
  void Await(Predicate pred) ABSL_EXCLUSIVE_LOCKS_REQUIRED(this) {
    changed_.notify_all();
    std::unique_lock<std::mutex> lock(mu_, std::adopt_lock);
    changed_.wait(lock, pred);
    lock.release();  // still held: the caller unlocks
  }
  // Same, for at most `timeout`; returns pred().
  template <typename Predicate, typename Rep, typename Period>
  bool AwaitWithTimeout(Predicate pred, std::chrono::duration<Rep, Period> timeout) ABSL_EXCLUSIVE_LOCKS_REQUIRED(this) {
    changed_.notify_all();
    std::unique_lock<std::mutex> lock(mu_, std::adopt_lock);
    const bool met = changed_.wait_for(lock, timeout, pred);
    lock.release();
    return met;
  }

 private:
  std::mutex mu_;
  std::condition_variable changed_;
};

class ABSL_SCOPED_LOCKABLE MutexLock {
 public:
  explicit MutexLock(Mutex* mu) ABSL_EXCLUSIVE_LOCK_FUNCTION(mu) : mu_(mu) { mu_->Lock(); }
  ~MutexLock() ABSL_UNLOCK_FUNCTION() { mu_->Unlock(); }
  MutexLock(const MutexLock&) = delete;
  MutexLock& operator=(const MutexLock&) = delete;

 private:
  Mutex* const mu_;
};

// A one-shot event: Notify once, any number of waiters.
class Notification {
 public:
  void Notify() ABSL_LOCKS_EXCLUDED(mu_) {
    MutexLock lock(&mu_);
    notified_ = true;
  }
  bool HasBeenNotified() ABSL_LOCKS_EXCLUDED(mu_) {
    MutexLock lock(&mu_);
    return notified_;
  }
  void WaitForNotification() ABSL_LOCKS_EXCLUDED(mu_) {
    MutexLock lock(&mu_);
    mu_.Await([this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return notified_; });
  }
  template <typename Rep, typename Period>
  bool WaitForNotificationWithTimeout(std::chrono::duration<Rep, Period> timeout) ABSL_LOCKS_EXCLUDED(mu_) {
    MutexLock lock(&mu_);
    return mu_.AwaitWithTimeout([this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return notified_; }, timeout);
  }

 private:
  Mutex mu_;
  bool notified_ ABSL_GUARDED_BY(mu_) = false;
};

}  // namespace surfmap
