// Stage 1 of the step: wind. The thesis' travelling gust schedule, in integer ticks.
//
// The schedule repeats with period P (sum of the gust durations). Gust g starts at offset S_g in
// the period and reaches particle row r after a travel delay d_g(r) = round(distance / speed / dt)
// ticks, where the distance is measured from the first row the gust meets (row 0 for a +z gust,
// the last row for a -z gust; with travel "forward" always row 0, as the thesis code behaved).
// Row r is under gust g at tick t when t >= S_g + d_g(r) and (t - S_g - d_g(r)) mod P < D_g;
// it gets no force before the gust first arrives. Overlapping gusts add. The whole wind state is
// a pure function of the tick: nothing to save, nothing to restore.
//
// A gust with a `front` direction u = (ux, uz) (any horizontal direction) sweeps the field as a
// straight front moving along u at the travel speed, entering at the corner it meets first: the
// particle at lattice column i, row j is reached after
//     d_g(i, j) = floor((i a + j b + c + 2^31) / 2^32)  ticks,
// a = round(2^32 K ux), b = round(2^32 K uz) (K = ticks per particle spacing), c the offset that
// makes the smallest delay over the field 0. a and b are computed once at load in IEEE double
// (correctly rounded divisions and square root only: the same bits on every machine); from then
// on every delay is exact integer arithmetic, so a row's wind is runs of columns under the same
// gusts (computeRowWind), and the runs' boundaries are found by division, not by a scan (by a
// column scan only where the row spans more gust periods than it has columns). A front along
// +-z is not swept: it is the thesis' rows with their exact delays.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/math/int128.h"
#include "sim/scenario/derived.h"

namespace sg {

struct WindSchedule {
  struct Gust {
    int64_t startTick = 0;      ///< S_g: offset within the period
    int64_t durationTicks = 0;  ///< D_g
    bool backward = false;      ///< reaches the last row first
    bool swept = false;         ///< has a front direction: its delay depends on the column too
    int64_t perColumn = 0;      ///< a: Q32.32 ticks per particle column (swept)
    int64_t perRow = 0;         ///< b: Q32.32 ticks per particle row (swept)
    Int128 offset = 0;          ///< c (Q32.32 ticks), plus 2^31 for the rounding (swept)
    /// d_g(i, j) of a swept gust (lattice particle column i, row j of the field).
    int64_t delay(int64_t column, int64_t row) const {
      return int64_t((Int128(column) * perColumn + Int128(row) * perRow + offset) >> 32);
    }
  };
  std::vector<Gust> gusts;
  int64_t periodTicks = 0;
  std::vector<int64_t> delayFromFirstRow;  ///< d(r) for rows counted from row 0
  std::vector<int64_t> delayFromLastRow;   ///< d(r) for rows counted from the last row

  /// Builds the tick schedule from the scenario's derived constants (gust ticks, row delays).
  static WindSchedule build(const Scenario& s, const ScenarioConstants& c);

  /// True when no gust is swept: the wind is the same along every particle row.
  bool rowUniform() const {
    for (const Gust& g : gusts)
      if (g.swept) return false;
    return true;
  }
  /// Is swept gust g blowing on the particle at (column, row) during tick `tick`?
  bool activeAt(size_t g, int64_t column, int64_t row, int64_t tick) const {
    const int64_t since = tick - gusts[g].startTick - gusts[g].delay(column, row);
    return since >= 0 && since % periodTicks < gusts[g].durationTicks;
  }
  /// Is (row-uniform) gust g blowing on particle row `row` during tick `tick`?
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

/// Per-row velocity increments of the row-uniform gusts (all of the wind when rowUniform()), for
/// the field's particle rows [rowBegin, rowEnd) (rowEnd < 0: to the last); *out holds every row of
/// the field, the others untouched. A level-of-detail window computes only its own rows (walking
/// every row of a 1,048,576-row field was 7-9 ms of a 10 ms tick).
template <class S>
void computeRowAcceleration(const WindSchedule& schedule, const WindConstants<S>& c, int64_t tick,
                            RowAccelerationDt<S>* out, int64_t rowBegin = 0, int64_t rowEnd = -1);

/// Columns [begin, end) of one particle row under the same wind: (a + F/m) dt.
template <class S>
struct WindRun {
  int64_t begin = 0, end = 0;  ///< lattice columns
  S dvx{}, dvy{}, dvz{};
};

/// The wind of lattice row `row`, lattice columns [columnBegin, columnEnd), at tick `tick`: runs
/// in column order covering the range, each under one set of gusts, its increment summed in gust
/// order exactly as computeRowAcceleration sums a row's. Replaces *out.
template <class S>
void computeRowWind(const WindSchedule& schedule, const WindConstants<S>& c, int64_t tick, int64_t row,
                    int64_t columnBegin, int64_t columnEnd, std::vector<WindRun<S>>* out);

}  // namespace sg
