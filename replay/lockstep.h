// Replaying recordings side by side on common simulated times, also when the time steps differ
// by a whole ratio (the lock-step rule of docs/diff-and-compare.md).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "replay/format/sgr_reader.h"
#include "replay/player.h"
#include "replay/variant.h"
#include "sim/math/rational.h"

namespace sg {

/// How two time steps line up: `aSteps` ticks of run A last as long as `bSteps` ticks of run B,
/// one of the two being 1.
struct TimeRatio {
  int64_t aSteps = 1, bSteps = 1;
};

/// Lines up time steps dtA and dtB when one is a whole multiple of the other; else nullopt.
std::optional<TimeRatio> lineUp(const Rational& dtA, const Rational& dtB);

/// lineUp(recordedDt, runDt) for a run replaying a recording; throws std::invalid_argument
/// ("dt=1/90: expected a time step that is a whole multiple or a whole fraction of ...").
TimeRatio lockStepRatio(const Rational& recordedDt, const Rational& runDt);

/// The time step a recording was made with.
Rational recordedTimeStep(const sgr::Recording& recording);

/// The hashes a recording holds (CHCK, SNAP, END unless it faulted), by tick.
class RecordedHashes {
 public:
  explicit RecordedHashes(const sgr::Recording& recording);
  std::optional<uint64_t> at(int64_t tick) const;
  size_t size() const { return byTick_.size(); }

 private:
  std::vector<sgr::Check> byTick_;  ///< sorted by tick
};

/// A recording's inputs driving a world built with the recorded settings plus `variant`. When
/// the variant's time step is r times finer than the recorded one, each recorded tick takes r
/// steps: the recorded input of tick t at the first (camera and body commands), the camera alone
/// at the others. When it is m times coarser, each step covers m recorded ticks, with their
/// inputs merged (body commands in order, the last tick's camera).
class LockStepReplay {
 public:
  /// Throws sgr::RecordingError (the recording does not build under the variant) or
  /// std::invalid_argument ("dt=1/90: expected ...": no whole ratio to the recorded step).
  LockStepReplay(const sgr::Recording& recording, int threads, const VariantSettings& variant = {});

  Player& player() { return player_; }
  SimWorld& world() { return player_.world(); }
  int64_t substeps() const { return ratio_.bSteps; }     ///< r: steps per recorded tick
  int64_t mergedTicks() const { return ratio_.aSteps; }  ///< m: recorded ticks per step
  /// Where the world is, in recorded ticks.
  int64_t recordedTick() const { return player_.tick() / ratio_.bSteps * ratio_.aSteps; }
  /// Steps until recordedTick() == target (target >= recordedTick(), a multiple of
  /// mergedTicks()); stops at the first fault and returns it.
  StepResult advanceTo(int64_t target);

  /// The input of one step that covers `count` recorded ticks from `first` (merge rule).
  static TickInput mergedInput(const sgr::Recording& recording, int64_t first, int64_t count);

 private:
  const sgr::Recording& recording_;
  TimeRatio ratio_;  ///< recorded ticks (aSteps) per own steps (bSteps); checked before the world is built
  Player player_;
};

}  // namespace sg
