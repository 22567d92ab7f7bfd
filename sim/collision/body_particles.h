// Bodies push grass particles (thesis §4 "Particles: position only, velocity unchanged"):
//   sphere: out along the normal from the centre, by penetration * share;
//   box:    "up" (thesis) pushes the particle DOWN by the smallest face gap * share (the thesis'
//           constant normal (0, 1, 0) with newPos = oldPos - n pen / totalInertia: grass pressed
//           into the ground), "nearest-face" pushes it out through the nearest face;
// with share = particleInvMass / (particleInvMass + bodyInvMass) (the body, heavier, "moves
// less"; it is not moved by grass). Bodies are applied in id order to each particle, particles in
// index order: the same result for every broad phase and thread count.
//
// Broad phase "grid" (the thesis' lattice ranges) tests only particles whose anchor lies within
// boundingRadius + margin of a part's centre, on both axes. margin = rod length + jitter + the
// largest bounding radius of all bodies: a particle is within L of its anchor after the
// constraint stage and a push this tick moves it by at most one part's radius, so no particle that
// "brute" would push is ever skipped. Tests check both give bit-identical states.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/bodies/rigid_body.h"
#include "sim/particles/particles.h"

namespace sg {

/// Inclusive particle-lattice index ranges of one body part's candidates.
struct ParticleRange {
  int64_t a0 = 0, a1 = -1, b0 = 0, b1 = -1;
};

template <class S>
struct BodyParticleSettings {
  BoxParticleNormal boxNormal = BoxParticleNormal::Up;
  ParticleBroadphase broadphase = ParticleBroadphase::Grid;
  S particleInvMass{1};
  S margin{};                          ///< m, see above
  S anchorOriginX{}, anchorOriginZ{};  ///< m, un-jittered position of particle (0, 0)
  S invParticleSpacing{};              ///< 1 / (k spacing)
};

/// Candidate ranges for every body part, in (body, part) order.
template <class S>
std::vector<ParticleRange> particleRanges(const std::vector<RigidBody<S>>& bodies, const ParticleGrid& grid,
                                          const BodyParticleSettings<S>& settings);

/// Applies every body to particle rows [rowBegin, rowEnd). Adds the number of particles each body
/// pushed to pushedPerBody[body] (may be null). Returns the first faulting particle or -1.
template <class S>
int64_t pushParticlesOutOfBodies(ParticleArrays<S>& particles, const ParticleGrid& grid,
                                 const std::vector<RigidBody<S>>& bodies, const std::vector<ParticleRange>& ranges,
                                 const BodyParticleSettings<S>& settings, int64_t rowBegin, int64_t rowEnd,
                                 int64_t* pushedPerBody);

}  // namespace sg
