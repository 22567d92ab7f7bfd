// Wall-clock stage timing for tools: a StageObserver that accumulates nanoseconds per stage.
// Lives outside sim/: the core never reads a clock.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>

#include "sim/world/stage.h"

namespace sg {

/// Milliseconds of wall time since t0 (the tools' timings: compare, sweep).
inline double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

class StageClock final : public StageObserver {
 public:
  void stageBegin(Stage s) override { begin_[size_t(s)] = std::chrono::steady_clock::now(); }
  void stageEnd(Stage s) override {
    nanos[size_t(s)] += uint64_t(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - begin_[size_t(s)])
            .count());
  }
  std::array<uint64_t, size_t(Stage::Count)> nanos{};

 private:
  std::array<std::chrono::steady_clock::time_point, size_t(Stage::Count)> begin_{};
};

}  // namespace sg
