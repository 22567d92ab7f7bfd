// Particle state as structure-of-arrays. One particle per k x k patches: particle (a, b) is the
// control point at patch (k*a, k*b) of the field, anchored at that patch's root; the particle
// lattice covers the field with one extra column/row where needed so that every patch
// interpolates between particles (no border special cases).
#pragma once

#include <cstdint>
#include <vector>

#include "sim/lod/lattice_window.h"

namespace sg {

/// The simulated particles: a window of the particle lattice (the whole of it with the level of
/// detail off). Storage is toroidal (sim/lod/lattice_window.h); countX == window.sizeI and
/// countZ == window.sizeJ always, so the pointwise stages simply run over countX * countZ.
struct ParticleGrid {
  int k = 1;             ///< patches per particle along each axis
  int64_t countX = 0;    ///< particles per stored row (along x)
  int64_t countZ = 0;    ///< stored particle rows (along z)
  LatticeWindow window;  ///< which particles of the field are held, and where
  int64_t size() const { return countX * countZ; }
  /// Particles per axis covering n patches: ceil((n - 1) / k) + 1.
  static int64_t coverCount(int64_t patches, int k) { return (patches - 1 + k - 1) / k + 1; }
};

template <class S>
struct ParticleArrays {
  std::vector<S> px, py, pz;                 ///< position (m)
  std::vector<S> vx, vy, vz;                 ///< velocity (m/s)
  std::vector<S> anchorX, anchorY, anchorZ;  ///< rod anchor = tuft root on the ground (m)
  /// Model blade with trampling only (else empty): 1 when a body pressed the tip, decaying to 0
  /// over the scenario's trampleSeconds (sim/particles/blade.h). State: saved and hashed.
  std::vector<S> trample;
  void resize(size_t n, bool tramples = false) {
    for (auto* v : {&px, &py, &pz, &vx, &vy, &vz, &anchorX, &anchorY, &anchorZ}) v->assign(n, S(0));
    trample.assign(tramples ? n : 0, S(0));
  }
};

/// Per-scenario particle constants, rounded once into the scalar.
template <class S>
struct ParticleConstants {
  S dt{};              ///< s
  S invDt{};           ///< 1/s
  S dampingPerTick{};  ///< damping^dt, from deterministicPow
  S rodLength{};       ///< L (m)
  // model blade (sim/particles/blade.h); zero for the other models
  S bladeStiffnessDt{};     ///< 1/s: stiffness * dt
  S bladeDampingPerTick{};  ///< damping^dt exp(-blade damping rate * dt)
  S trampleDecayPerTick{};  ///< dt / trampleSeconds
  S invRodLength{};         ///< 1/L (1/m)
};

}  // namespace sg
