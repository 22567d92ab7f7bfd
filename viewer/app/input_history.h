// A live session's input of every tick since tick 0, stored as runs of equal inputs. A scripted
// `step 100000000` gives one input 10^8 times; as a vector of TickInput the history grew by about
// 100 bytes a tick (an independent pass watched 550 MB at 5,000,000 ticks of a 6 x 6 meadow).
// Runs grow only with the inputs that change: a camera moved by hand, a body command.
#pragma once

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <vector>

#include "sim/world/tick_input.h"

namespace sg::viewer {

class InputHistory {
 public:
  /// The ticks the history holds inputs for (0 .. size() - 1).
  int64_t size() const { return size_; }
  /// The input of the next tick, size().
  void push_back(const TickInput& input) {
    if (runs_.empty() || !(runs_.back().input == input)) runs_.push_back(Run{size_, input});
    ++size_;
  }
  /// Keeps the inputs of ticks 0 .. n - 1 (n <= size()): a new branch from tick n.
  void resize(int64_t n) {
    while (!runs_.empty() && runs_.back().start >= n) runs_.pop_back();
    size_ = std::min(size_, n);
  }
  /// The input of tick t (0 <= t < size()).
  const TickInput& operator[](int64_t t) const {
    const auto after =
        std::upper_bound(runs_.begin(), runs_.end(), t, [](int64_t tick, const Run& run) { return tick < run.start; });
    return std::prev(after)->input;
  }
  /// Runs held (for tests: the memory is O(runs), not O(ticks)).
  size_t runCount() const { return runs_.size(); }

 private:
  struct Run {
    int64_t start;  ///< the first tick of the run; it lasts to the next run's start
    TickInput input;
  };
  std::vector<Run> runs_;  ///< increasing starts, the first at 0
  int64_t size_ = 0;
};

}  // namespace sg::viewer
