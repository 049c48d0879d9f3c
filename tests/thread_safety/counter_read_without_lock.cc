// Deliberately wrong, and never built: reads a guarded member without its
// lock. The thread_safety_check_fires test runs scripts/check-thread-safety.sh
// on this file alone and expects the read to be refused, so the suite shows
// that the check can fail, not only that today's code passes it.
#include "server/base/mutex.h"

namespace surfmap {

class Counter {
 public:
  void Add() {
    MutexLock lock(&mu_);
    ++count_;
  }
  int Read() const { return count_; }  // wrong: mu_ is not held

 private:
  mutable Mutex mu_;
  int count_ ABSL_GUARDED_BY(mu_) = 0;
};

int ReadCounter(const Counter& counter) { return counter.Read(); }

}  // namespace surfmap
