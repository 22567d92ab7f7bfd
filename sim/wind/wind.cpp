#include "sim/wind/wind.h"

namespace sg {

WindSchedule WindSchedule::build(const Scenario& s, int64_t rows, const Rational& rowSpacing) {
  WindSchedule w;
  int64_t offset = 0;
  for (const WindGust& g : s.wind.schedule) {
    const int64_t duration = *div(g.duration, s.timeStep)->roundToInt64();  // validated >= 1
    const bool backward = s.wind.travel == WindTravel::Direction && g.force[2].num < 0;
    w.gusts.push_back({offset, duration, backward});
    offset += duration;
  }
  w.periodTicks = offset > 0 ? offset : 1;
  // Ticks per row step = rowSpacing / (speed * dt), kept exact; round once per row.
  const Rational ticksPerRow = *div(rowSpacing, *mul(s.wind.travelSpeed, s.timeStep));
  w.delayFromFirstRow.resize(size_t(rows));
  w.delayFromLastRow.resize(size_t(rows));
  for (int64_t r = 0; r < rows; ++r) {
    w.delayFromFirstRow[size_t(r)] = *mul(ticksPerRow, Rational::integer(r))->roundToInt64();
    w.delayFromLastRow[size_t(r)] = *mul(ticksPerRow, Rational::integer(rows - 1 - r))->roundToInt64();
  }
  return w;
}

template <class S>
void computeRowAcceleration(const WindSchedule& schedule, const WindConstants<S>& c, int64_t tick,
                            RowAccelerationDt<S>* out) {
  const int64_t rows = int64_t(schedule.delayFromFirstRow.size());
  out->x.resize(size_t(rows));
  out->y.resize(size_t(rows));
  out->z.resize(size_t(rows));
  for (int64_t r = 0; r < rows; ++r) {
    S ax = c.accX, ay = c.accY, az = c.accZ;
    for (size_t g = 0; g < schedule.gusts.size(); ++g) {
      if (!schedule.active(g, r, tick)) continue;
      ax += c.forceX[g];
      ay += c.forceY[g];
      az += c.forceZ[g];
    }
    out->x[size_t(r)] = ax * c.dt;
    out->y[size_t(r)] = ay * c.dt;
    out->z[size_t(r)] = az * c.dt;
  }
}

template void computeRowAcceleration(const WindSchedule&, const WindConstants<Fx32>&, int64_t, RowAccelerationDt<Fx32>*);
template void computeRowAcceleration(const WindSchedule&, const WindConstants<Fx16>&, int64_t, RowAccelerationDt<Fx16>*);
template void computeRowAcceleration(const WindSchedule&, const WindConstants<float>&, int64_t, RowAccelerationDt<float>*);
template void computeRowAcceleration(const WindSchedule&, const WindConstants<double>&, int64_t, RowAccelerationDt<double>*);
}  // namespace sg
