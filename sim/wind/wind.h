// Stage 1 of the step: wind. The thesis' travelling gust schedule, in integer ticks.
//
// The schedule repeats with period P (sum of the gust durations). Gust g starts at offset S_g in
// the period and reaches particle row r after a travel delay d_g(r) = round(distance / speed / dt)
// ticks, where the distance is measured from the first row the gust meets (row 0 for a +z gust,
// the last row for a -z gust; with travel "forward" always row 0, as the thesis code behaved).
// Row r is under gust g at tick t when t >= S_g + d_g(r) and (t - S_g - d_g(r)) mod P < D_g;
// it gets no force before the gust first arrives. Overlapping gusts add. The whole wind state is
// a pure function of the tick: nothing to save, nothing to restore.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/scenario/derived.h"

namespace sg {

struct WindSchedule {
  struct Gust {
    int64_t startTick = 0;      ///< S_g: offset within the period
    int64_t durationTicks = 0;  ///< D_g
    bool backward = false;      ///< reaches the last row first
  };
  std::vector<Gust> gusts;
  int64_t periodTicks = 0;
  std::vector<int64_t> delayFromFirstRow;  ///< d(r) for rows counted from row 0
  std::vector<int64_t> delayFromLastRow;   ///< d(r) for rows counted from the last row

  /// Builds the tick schedule from the scenario's derived constants (gust ticks, row delays).
  static WindSchedule build(const Scenario& s, const ScenarioConstants& c);

  /// Is gust g blowing on particle row `row` during tick `tick`?
  bool active(size_t g, int64_t row, int64_t tick) const {
    const Gust& gust = gusts[g];
    const int64_t delay = gust.backward ? delayFromLastRow[size_t(row)] : delayFromFirstRow[size_t(row)];
    const int64_t since = tick - gust.startTick - delay;
    return since >= 0 && since % periodTicks < gust.durationTicks;
  }
  /// First tick at which gust g blows on row `row` (for tests and tools).
  int64_t firstTick(size_t g, int64_t row) const {
    const Gust& gust = gusts[g];
    return gust.startTick + (gust.backward ? delayFromLastRow[size_t(row)] : delayFromFirstRow[size_t(row)]);
  }
};

/// Per-row velocity increment of this tick: (acceleration + wind force / mass) * dt.
template <class S>
struct RowAccelerationDt {
  std::vector<S> x, y, z;
};

template <class S>
struct WindConstants {
  std::vector<S> forceX, forceY, forceZ;  ///< per gust, already multiplied by 1/mass
  S accX{}, accY{}, accZ{};               ///< constant particle acceleration
  S dt{};
};

template <class S>
void computeRowAcceleration(const WindSchedule& schedule, const WindConstants<S>& c, int64_t tick,
                            RowAccelerationDt<S>* out);

}  // namespace sg
