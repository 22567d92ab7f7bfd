// Stage 3 of the step: particle integration (thesis order, from Cyclone's Particle::integrate):
//     p += v dt;   v += (a + F/m) dt;   v *= damping^dt
// For the "pbd" constraint mode the order is symplectic instead (velocity first, then position
// with the new velocity), because the velocity is later recomputed from the corrected position
// and the explicit order would drop this tick's acceleration.
//
// (a + F/m) dt is the same for a whole particle row (wind is per row), so it comes in per row.
#pragma once

#include <cstdint>

#include "sim/math/scalar.h"
#include "sim/particles/particles.h"

namespace sg {

/// Integrates particles [begin, end) of one row. Returns the first index whose arithmetic
/// faulted (overflow or non-finite), or -1.
template <class S, bool Symplectic>
inline int64_t integrateParticleRow(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy, S dvz,
                                    const ParticleConstants<S>& c) {
  using T = ScalarTraits<S>;
  S* __restrict px = p.px.data();
  S* __restrict py = p.py.data();
  S* __restrict pz = p.pz.data();
  S* __restrict vx = p.vx.data();
  S* __restrict vy = p.vy.data();
  S* __restrict vz = p.vz.data();
  const S dt = c.dt, damp = c.dampingPerTick;
  for (int64_t i = begin; i < end; ++i) {
    if constexpr (!Symplectic) {
      px[i] += vx[i] * dt;
      py[i] += vy[i] * dt;
      pz[i] += vz[i] * dt;
    }
    vx[i] = (vx[i] + dvx) * damp;
    vy[i] = (vy[i] + dvy) * damp;
    vz[i] = (vz[i] + dvz) * damp;
    if constexpr (Symplectic) {
      px[i] += vx[i] * dt;
      py[i] += vy[i] * dt;
      pz[i] += vz[i] * dt;
    }
    if (T::faultPending() || !(T::isFinite(px[i]) && T::isFinite(py[i]) && T::isFinite(pz[i]) && T::isFinite(vx[i]) &&
                               T::isFinite(vy[i]) && T::isFinite(vz[i])))
      return i;
  }
  return -1;
}

}  // namespace sg
