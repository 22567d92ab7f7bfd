#include "sim/wind/wind.h"

namespace sg {

WindSchedule WindSchedule::build(const Scenario& s, const ScenarioConstants& c) {
  WindSchedule w;
  int64_t offset = 0;
  for (size_t g = 0; g < s.wind.schedule.size(); ++g) {
    const bool backward = s.wind.travel == WindTravel::Direction && s.wind.schedule[g].force[2].num < 0;
    w.gusts.push_back({offset, c.gustTicks[g], backward});
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

template void computeRowAcceleration(const WindSchedule&, const WindConstants<Fx32>&, int64_t,
                                     RowAccelerationDt<Fx32>*);
template void computeRowAcceleration(const WindSchedule&, const WindConstants<Fx16>&, int64_t,
                                     RowAccelerationDt<Fx16>*);
template void computeRowAcceleration(const WindSchedule&, const WindConstants<float>&, int64_t,
                                     RowAccelerationDt<float>*);
template void computeRowAcceleration(const WindSchedule&, const WindConstants<double>&, int64_t,
                                     RowAccelerationDt<double>*);
}  // namespace sg
