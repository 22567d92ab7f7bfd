// Fixed-chunk parallelism. Work is cut into chunks whose boundaries depend only on the problem
// size, never on the thread count; any thread may run any chunk, and chunks write disjoint
// data, so results are bit-identical for 1..N threads. The caller thread works too.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace sg {

/// Thrown by ChunkPool when the machine refuses to start one of the requested threads
/// (RLIMIT_NPROC, address space for the stacks): the workers already started are joined first.
class ThreadStartError : public std::runtime_error {
 public:
  ThreadStartError(int created, int requested)
      : std::runtime_error("--threads: expected a thread count this machine can start (created " +
                           std::to_string(created) + " of " + std::to_string(requested) + ")"),
        created_(created),
        requested_(requested) {}
  int created() const { return created_; }
  int requested() const { return requested_; }

 private:
  int created_, requested_;
};

class ChunkPool {
 public:
  /// fn(chunk index, worker index in [0, threads)).
  using ChunkFn = std::function<void(int64_t, int)>;

  explicit ChunkPool(int threads = 1);
  ~ChunkPool();
  ChunkPool(const ChunkPool&) = delete;
  ChunkPool& operator=(const ChunkPool&) = delete;

  int threads() const { return int(workers_.size()) + 1; }
  /// Runs fn for chunks [0, chunks) and returns when all are done.
  void run(int64_t chunks, const ChunkFn& fn);

 private:
  void workerLoop(int worker);
  void drain(int worker);
  void stopAndJoin();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, finished_;
  const ChunkFn* job_ = nullptr;
  int64_t jobChunks_ = 0;
  std::atomic<int64_t> next_{0};
  int busy_ = 0;
  uint64_t generation_ = 0;
  bool stop_ = false;
};

}  // namespace sg
