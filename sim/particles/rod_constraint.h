// Stage 4 of the step: the rod constraint that holds each tuft particle at distance L from its
// root anchor (thesis: "hard" particle constraint, linear projection):
//     d = p - anchor;   p = anchor + d * (L / |d|)
// |d| is computed from the exact sum of squares in the fixed types (one rounding), so a tuft on
// its vertical axis stays exactly on it. A particle exactly at its anchor (d = 0) has no
// direction; it is put back upright at anchor + (0, L, 0) instead of dividing by zero.
//
// Mode "thesis" leaves the velocity untouched (it keeps growing upward under the constant
// acceleration; docs/physics-notes.md measures it). Mode "pbd" adds the correction divided by
// dt to the velocity, i.e. v = (p_corrected - p_start) / dt as position-based dynamics does.
#pragma once

#include <cstdint>

#include "sim/math/scalar.h"
#include "sim/particles/particles.h"

namespace sg {

template <class S, bool UpdateVelocity>
inline int64_t projectRodRow(ParticleArrays<S>& p, int64_t begin, int64_t end, const ParticleConstants<S>& c) {
  using T = ScalarTraits<S>;
  S* __restrict px = p.px.data();
  S* __restrict py = p.py.data();
  S* __restrict pz = p.pz.data();
  S* __restrict vx = p.vx.data();
  S* __restrict vy = p.vy.data();
  S* __restrict vz = p.vz.data();
  const S* __restrict ax = p.anchorX.data();
  const S* __restrict ay = p.anchorY.data();
  const S* __restrict az = p.anchorZ.data();
  const S rod = c.rodLength, invDt = c.invDt;
  for (int64_t i = begin; i < end; ++i) {
    const S dx = px[i] - ax[i], dy = py[i] - ay[i], dz = pz[i] - az[i];
    const S len = length3(dx, dy, dz);
    S nx, ny, nz;
    if (len == S(0)) {
      nx = ax[i];
      ny = ay[i] + rod;
      nz = az[i];
    } else {
      const S scale = rod / len;
      nx = ax[i] + dx * scale;
      ny = ay[i] + dy * scale;
      nz = az[i] + dz * scale;
    }
    if constexpr (UpdateVelocity) {
      vx[i] += (nx - px[i]) * invDt;
      vy[i] += (ny - py[i]) * invDt;
      vz[i] += (nz - pz[i]) * invDt;
    }
    px[i] = nx;
    py[i] = ny;
    pz[i] = nz;
    if (T::faultPending() || !(T::inStateRange(nx) && T::inStateRange(ny) && T::inStateRange(nz) &&
                               T::inStateRange(vx[i]) && T::inStateRange(vy[i]) && T::inStateRange(vz[i])))
      return i;
  }
  return -1;
}

}  // namespace sg
