#include "sim/world/chunk_pool.h"

#include <exception>
#include <string>

namespace sg {

ChunkPool::ChunkPool(int threads) {
  try {
    workers_.reserve(size_t(threads > 1 ? threads - 1 : 0));
    for (int w = 1; w < threads; ++w) workers_.emplace_back([this, w] { workerLoop(w); });
  } catch (const std::exception&) {
    // The workers already started wait on wake_: they must be stopped and joined before the
    // members die (destroying a condition variable with waiters hangs), then the caller learns
    // how many the machine would start.
    const int created = int(workers_.size()) + 1;
    stopAndJoin();
    throw ThreadStartError(created, threads);
  }
}

ChunkPool::~ChunkPool() { stopAndJoin(); }

void ChunkPool::stopAndJoin() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (auto& t : workers_) t.join();
}

void ChunkPool::drain(int worker) {
  for (int64_t c = next_.fetch_add(1); c < jobChunks_; c = next_.fetch_add(1)) (*job_)(c, worker);
}

void ChunkPool::run(int64_t chunks, const ChunkFn& fn) {
  if (chunks <= 0) return;
  if (workers_.empty() || chunks == 1) {
    for (int64_t c = 0; c < chunks; ++c) fn(c, 0);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = &fn;
    jobChunks_ = chunks;
    next_.store(0);
    busy_ = int(workers_.size());
    ++generation_;
  }
  wake_.notify_all();
  drain(0);
  std::unique_lock<std::mutex> lock(mutex_);
  finished_.wait(lock, [this] { return busy_ == 0; });
  job_ = nullptr;
}

void ChunkPool::workerLoop(int worker) {
  uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
    }
    drain(worker);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (--busy_ == 0) finished_.notify_one();
    }
  }
}

}  // namespace sg
