// Stages 3 and 4 of the step for the grass model "blade" (docs/grass-models.md): a tuft is a stiff
// blade whose tip is pulled back toward its upright rest pose r = anchor + (0, L, 0) - the
// recovery force of Jahrmann & Wimmer 2017 ("Responsive Real-Time Grass Rendering for General 3D
// Scenes"), kept second order so that a blade sways and rings down instead of creeping back:
//
//     g  = (a + F/m) dt - stiffness (1 - trample) dt (p - r),  less its part along the rod
//     v  = (v + g) * dampingPerTick
//     p' = p + v dt                        (symplectic Euler)
//     p'.y = max(p'.y, anchor.y)           (the tip never goes below its root: J&W's validation)
//     p'' = anchor + (p' - anchor) L / |p' - anchor|           (the blade keeps its length)
//     v += (p'' - (p + v dt)) / dt         (the corrections feed the velocity, as in PBD, so a
//                                           constraint never stores energy in a hidden velocity)
//     trample = max(trample - dt / trampleSeconds, 0)
//
// dampingPerTick = damping^dt exp(-c dt): the scenario's per-second factor and the blade's
// damping rate c = 4 pi dampingRatio frequency, each the exact decay of one tick (so always in
// (0, 1]: stable at any rate). The stiffness is (2 pi frequency)^2 - a.y / L, so that with the
// acceleration a = (0, -g, 0) the tangential motion is exactly a damped pendulum,
// theta'' = -(2 pi frequency)^2 sin(theta) - c theta' (tests/grass_model_test.cpp compares it with
// the analytic damped oscillator and checks that the error falls with dt).
//
// Trampling: a body that pushes a tip sets its trample level to 1 (collision/body_particles.cpp).
// The stiffness then grows back linearly over trampleSeconds; under gravity the blade stays down
// until (1 - trample) stiffness exceeds g/L, then rises.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/math/scalar.h"
#include "sim/particles/particle_kernel.h"
#include "sim/particles/particles.h"
#include "sim/patches/patch_state.h"

namespace sg {

/// The reference: advances particles [begin, end) of one row under the blade model and writes
/// the tip displacement p - anchor - (0, L, 0) into (dx, dy, dz). (dvx, dvy, dvz) is the row's
/// (a + F/m) dt. Returns the first particle whose arithmetic faulted, or -1 (the row then stops
/// there: the particles after it are untouched and no displacement is written).
template <class S, bool Tramples>
inline int64_t advanceBladeRowScalar(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy, S dvz,
                                     const ParticleConstants<S>& c, std::vector<S>& dx, std::vector<S>& dy,
                                     std::vector<S>& dz) {
  using T = ScalarTraits<S>;
  S* __restrict px = p.px.data();
  S* __restrict py = p.py.data();
  S* __restrict pz = p.pz.data();
  S* __restrict vx = p.vx.data();
  S* __restrict vy = p.vy.data();
  S* __restrict vz = p.vz.data();
  S* __restrict trample = Tramples ? p.trample.data() : nullptr;
  const S* __restrict ax = p.anchorX.data();
  const S* __restrict ay = p.anchorY.data();
  const S* __restrict az = p.anchorZ.data();
  const S dt = c.dt, invDt = c.invDt, rod = c.rodLength, damp = c.bladeDampingPerTick;
  const S stiffnessDt = c.bladeStiffnessDt, decay = c.trampleDecayPerTick, invRod = c.invRodLength;
  for (int64_t i = begin; i < end; ++i) {
    S stiffness = stiffnessDt;
    if constexpr (Tramples) {
      stiffness = stiffnessDt * (S(1) - trample[i]);
      trample[i] = trample[i] > decay ? trample[i] - decay : S(0);
    }
    // Recovery toward the upright rest pose plus wind and gravity, only across the rod: the rod
    // carries the part along it. Integrated and then projected away, a push along the rod
    // toward the root (gravity on a standing blade, the spring's chord) would feed the sway
    // energy, g dt / (2 L) per second: a 5 cm blade at 60 Hz swung up to 58 deg. The rod
    // direction is the tip's offset over L (the tip starts the tick at length L).
    const S rx = px[i] - ax[i], ry = py[i] - ay[i], rz = pz[i] - az[i];
    S gx = dvx - stiffness * rx, gy = dvy - stiffness * (ry - rod), gz = dvz - stiffness * rz;
    const S along = ((gx * rx + gy * ry + gz * rz) * invRod) * invRod;
    gx -= rx * along;
    gy -= ry * along;
    gz -= rz * along;
    vx[i] = (vx[i] + gx) * damp;
    vy[i] = (vy[i] + gy) * damp;
    vz[i] = (vz[i] + gz) * damp;
    const S predictedX = px[i] + vx[i] * dt, predictedY = py[i] + vy[i] * dt, predictedZ = pz[i] + vz[i] * dt;
    // Above the root, then back to length L (the height above the root keeps its sign).
    const S ex = predictedX - ax[i], ey = predictedY > ay[i] ? predictedY - ay[i] : S(0), ez = predictedZ - az[i];
    const S len = length3(ex, ey, ez);
    S nx = ax[i], ny = ay[i] + rod, nz = az[i];  // at the root: no direction, put back upright
    if (len != S(0)) {
      const S scale = rod / len;
      nx = ax[i] + ex * scale;
      ny = ay[i] + ey * scale;
      nz = az[i] + ez * scale;
    }
    vx[i] += (nx - predictedX) * invDt;
    vy[i] += (ny - predictedY) * invDt;
    vz[i] += (nz - predictedZ) * invDt;
    px[i] = nx;
    py[i] = ny;
    pz[i] = nz;
    if (T::faultPending() || !(T::inStateRange(nx) && T::inStateRange(ny) && T::inStateRange(nz) &&
                               T::inStateRange(vx[i]) && T::inStateRange(vy[i]) && T::inStateRange(vz[i])))
      return i;
  }
  particleDisplacement(p, begin, end, rod, dx, dy, dz);
  return -1;
}

/// The AVX2 kernel (Fx32 and Fx16 only; blade_row_avx2.cpp). Same contract and bits as
/// advanceBladeRowScalar. Call only when avx2KernelAvailable().
template <class S, bool Tramples>
int64_t advanceBladeRowAvx2(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy, S dvz,
                            const ParticleConstants<S>& c, std::vector<S>& dx, std::vector<S>& dy, std::vector<S>& dz);

/// The blade row with the chosen kernel (float and double run the reference: no IEEE lanes yet).
template <class S, bool Tramples>
inline int64_t advanceBladeRow(ParticleKernel kernel, ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy,
                               S dvz, const ParticleConstants<S>& c, std::vector<S>& dx, std::vector<S>& dy,
                               std::vector<S>& dz) {
  if constexpr (ScalarTraits<S>::isFixed)
    if (kernel == ParticleKernel::Avx2)
      return advanceBladeRowAvx2<S, Tramples>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
  return advanceBladeRowScalar<S, Tramples>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
}

}  // namespace sg
