#include "sim/wind/wind.h"

#include <algorithm>
#include <cmath>

namespace sg {

namespace {
/// floor(n / d) and ceil(n / d) for d > 0.
Int128 floorDiv(Int128 n, Int128 d) {
  const Int128 q = n / d;
  return (n % d != 0 && n < 0) ? q - 1 : q;
}
Int128 ceilDiv(Int128 n, Int128 d) {
  const Int128 q = n / d;
  return (n % d != 0 && n > 0) ? q + 1 : q;
}
int64_t clampColumn(Int128 column, int64_t lo, int64_t hi) {
  return column < lo ? lo : column > hi ? hi : int64_t(column);
}

/// The first column of [lo, hi] whose delay is >= v (perColumn > 0) or <= v (perColumn < 0);
/// hi when none is.
int64_t firstColumnReaching(const WindSchedule::Gust& g, int64_t row, int64_t v, int64_t lo, int64_t hi) {
  const Int128 rest = Int128(row) * g.perRow + g.offset;
  if (g.perColumn > 0)  // i a + rest >= v 2^32
    return clampColumn(ceilDiv((Int128(v) << 32) - rest, g.perColumn), lo, hi);
  // i a + rest < (v + 1) 2^32, a = -m: i m > rest - (v + 1) 2^32
  return clampColumn(floorDiv(rest - (Int128(v + 1) << 32), -Int128(g.perColumn)) + 1, lo, hi);
}
}  // namespace

WindSchedule WindSchedule::build(const Scenario& s, const ScenarioConstants& c) {
  WindSchedule w;
  int64_t offset = 0;
  for (size_t g = 0; g < s.wind.schedule.size(); ++g) {
    const WindGust& spec = s.wind.schedule[g];
    Gust gust{offset, c.gustTicks[g], s.wind.travel == WindTravel::Direction && spec.force[2].num < 0};
    if (spec.front && (*spec.front)[0].isZero()) {
      // Along z: the thesis' rows, with their exact delays (rounding K to Q32.32 could move a
      // row whose delay is exactly half a tick to the other side).
      gust.backward = (*spec.front)[1].isNegative();
    } else if (spec.front) {
      // The front's ticks per particle column and row, K u, as Q32.32 (see the top of wind.h).
      const double ticksPerSpacing = c.ticksPerParticleSpacing.toDouble();
      const double x = (*spec.front)[0].toDouble(), z = (*spec.front)[1].toDouble();
      const double length = std::sqrt(x * x + z * z);
      gust.swept = true;
      gust.backward = false;
      gust.perColumn = std::llround(std::ldexp(ticksPerSpacing * x / length, 32));
      gust.perRow = std::llround(std::ldexp(ticksPerSpacing * z / length, 32));
      Int128 first = 0;  // the smallest i a + j b over the field, at the corner the front meets first
      if (gust.perColumn < 0) first += Int128(c.particlesX - 1) * gust.perColumn;
      if (gust.perRow < 0) first += Int128(c.particlesZ - 1) * gust.perRow;
      gust.offset = (Int128(1) << 31) - first;
    }
    w.gusts.push_back(gust);
    offset += c.gustTicks[g];
  }
  w.periodTicks = offset > 0 ? offset : 1;
  const size_t rows = c.rowDelayTicks.size();
  w.delayFromFirstRow = c.rowDelayTicks;
  w.delayFromLastRow.resize(rows);
  for (size_t r = 0; r < rows; ++r) w.delayFromLastRow[r] = c.rowDelayTicks[rows - 1 - r];
  return w;
}

template <class S>
void computeRowAcceleration(const WindSchedule& schedule, const WindConstants<S>& c, int64_t tick,
                            RowAccelerationDt<S>* out, int64_t rowBegin, int64_t rowEnd) {
  const int64_t rows = int64_t(schedule.delayFromFirstRow.size());
  out->x.resize(size_t(rows));
  out->y.resize(size_t(rows));
  out->z.resize(size_t(rows));
  rowBegin = std::clamp<int64_t>(rowBegin, 0, rows);
  rowEnd = rowEnd < 0 ? rows : std::clamp<int64_t>(rowEnd, rowBegin, rows);
  for (int64_t r = rowBegin; r < rowEnd; ++r) {
    S ax = c.accX, ay = c.accY, az = c.accZ;
    for (size_t g = 0; g < schedule.gusts.size(); ++g) {
      if (schedule.gusts[g].swept || !schedule.active(g, r, tick)) continue;
      ax += c.forceX[g];
      ay += c.forceY[g];
      az += c.forceZ[g];
    }
    out->x[size_t(r)] = ax * c.dt;
    out->y[size_t(r)] = ay * c.dt;
    out->z[size_t(r)] = az * c.dt;
  }
}

template <class S>
void computeRowWind(const WindSchedule& w, const WindConstants<S>& c, int64_t tick, int64_t row, int64_t columnBegin,
                    int64_t columnEnd, std::vector<WindRun<S>>* out) {
  out->clear();
  if (columnBegin >= columnEnd) return;
  // Where a swept gust starts or stops blowing along the row: its delay d is monotone in the
  // column, and it blows where tick - start - d lies in [n P, n P + D) for some n >= 0.
  thread_local std::vector<int64_t> cuts;
  cuts.assign({columnBegin, columnEnd});
  for (const WindSchedule::Gust& g : w.gusts) {
    if (!g.swept || g.perColumn == 0) continue;  // along the row: one value for all of it
    const int64_t first = g.delay(columnBegin, row), last = g.delay(columnEnd - 1, row);
    const int64_t dMin = std::min(first, last), dMax = std::max(first, last);
    const int64_t top = tick - g.startTick;  // a particle with delay d has blown for top - d ticks
    if (top < dMin) continue;
    const int64_t period = w.periodTicks;
    const int64_t nLo = std::max<int64_t>(0, int64_t(ceilDiv(top - dMax - g.durationTicks + 1, period)));
    const int64_t nHi = int64_t(floorDiv(top - dMin, period));
    if (nHi - nLo >= columnEnd - columnBegin) {
      // More gust periods across the row than columns (a slow front, short gusts): a cut at every
      // column costs less than one per period, and the runs are the same.
      for (int64_t column = columnBegin + 1; column < columnEnd; ++column) cuts.push_back(column);
      continue;
    }
    for (int64_t n = nLo; n <= nHi; ++n) {
      const int64_t lo = std::max(top - n * period - g.durationTicks + 1, dMin), hi = std::min(top - n * period, dMax);
      if (lo > hi) continue;
      const bool rising = g.perColumn > 0;  // delays [lo, hi] are columns [enter, leave)
      cuts.push_back(firstColumnReaching(g, row, rising ? lo : hi, columnBegin, columnEnd));
      cuts.push_back(firstColumnReaching(g, row, rising ? hi + 1 : lo - 1, columnBegin, columnEnd));
    }
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    const int64_t column = cuts[k];
    S ax = c.accX, ay = c.accY, az = c.accZ;
    for (size_t g = 0; g < w.gusts.size(); ++g) {
      if (!(w.gusts[g].swept ? w.activeAt(g, column, row, tick) : w.active(g, row, tick))) continue;
      ax += c.forceX[g];
      ay += c.forceY[g];
      az += c.forceZ[g];
    }
    out->push_back({column, cuts[k + 1], ax * c.dt, ay * c.dt, az * c.dt});
  }
}

template void computeRowAcceleration(const WindSchedule&, const WindConstants<Fx32>&, int64_t, RowAccelerationDt<Fx32>*,
                                     int64_t, int64_t);
template void computeRowAcceleration(const WindSchedule&, const WindConstants<Fx16>&, int64_t, RowAccelerationDt<Fx16>*,
                                     int64_t, int64_t);
template void computeRowAcceleration(const WindSchedule&, const WindConstants<float>&, int64_t,
                                     RowAccelerationDt<float>*, int64_t, int64_t);
template void computeRowAcceleration(const WindSchedule&, const WindConstants<double>&, int64_t,
                                     RowAccelerationDt<double>*, int64_t, int64_t);
#define SG_INSTANTIATE_ROW_WIND(S)                                                                               \
  template void computeRowWind(const WindSchedule&, const WindConstants<S>&, int64_t, int64_t, int64_t, int64_t, \
                               std::vector<WindRun<S>>*);
SG_FOR_EACH_SCALAR(SG_INSTANTIATE_ROW_WIND)
}  // namespace sg
