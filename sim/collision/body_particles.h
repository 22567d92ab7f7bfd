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
// largest bounding radius of all bodies (pushAllowance): a particle is within L of its anchor
// after the constraint stage and one push moves it by less than one part's radius. A chain of
// pushes (bodies piled in a line, each pushing the tip out of its far side into the next) can
// carry it further; a particle that has moved pushAllowance or more on x or z this tick is taken
// out of the ranges and meets every later part in order, as brute force does. So no particle that
// "brute" would push is ever skipped, and both give bit-identical states (tests: Bodies.
// BroadPhasesAreBitIdentical, GrassCandidates.ChainedPushesReachTheSameBodiesInEveryBroadPhase).
// Candidates are filtered by the height band of each row's parts first (grass_candidates.h).
#pragma once

#include <cstdint>
#include <vector>

#include "sim/bodies/rigid_body.h"
#include "sim/particles/particle_kernel.h"
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
  S pushAllowance{};                   ///< m: the largest bounding radius, the part of margin a push may use
  S anchorOriginX{}, anchorOriginZ{};  ///< m, un-jittered position of particle (0, 0)
  S invParticleSpacing{};              ///< 1 / (k spacing)
  /// The rows' height marks (grass_candidates.h), fixed-point only. They change no bits; off only
  /// in the tests that check exactly that.
  bool heightMarks = true;
  /// A pushed tip is held as a contact would (model blade always; thesis and pbd with
  /// `"tipContact": "hold"`): it goes back to its rod's length at once, a vertical push bends it,
  /// it loses the velocity that carried it into the body (a spring or the rod's projection would
  /// otherwise turn the push into velocity, tick after tick), and it is trampled when the particles
  /// carry a trample level (sim/particles/blade.h). Otherwise (`"push"`, the thesis): the position
  /// moves, nothing else.
  bool holdTips = false;
  S rodLength{};  ///< L (m), for holdTips
};

/// Candidate ranges for every body part, in (body, part) order.
template <class S>
std::vector<ParticleRange> particleRanges(const std::vector<RigidBody<S>>& bodies, const ParticleGrid& grid,
                                          const BodyParticleSettings<S>& settings);

/// One body part as the grass sees it this tick: its pose, shape, how much of the overlap the
/// particle takes (share), and the lattice range of its candidates.
template <class S>
struct GrassPusher {
  Pose<S> pose;
  const BodyPart<S>* shape = nullptr;
  S share{};
  ParticleRange range;
  int64_t firstColumn = 0;  ///< storage column of range.a0 (the same for every row: computed once)
  S candidateReach{};       ///< m: particles farther from the centre on any axis are not pushed
  int32_t body = 0;
};

/// The pushers of one tick, bucketed by lattice row (compressed rows): the pushers that may touch
/// lattice row b are byRow[rowStart[b - originJ] .. rowStart[b - originJ + 1]), in (body, part)
/// order. A row then visits only the parts over it: the stage costs O(rows + parts x rows they
/// span + candidate particles), not O(rows x bodies) (with 300 bodies the per-row scan of every
/// body was 76 % of a thesis-meadow tick).
template <class S>
struct GrassPushers {
  std::vector<GrassPusher<S>> parts;
  std::vector<int64_t> rowStart;  ///< window rows + 1 offsets into byRow
  std::vector<int32_t> byRow;
  int64_t originJ = 0;
};

/// Builds this tick's pushers from the bodies (poses and shares computed once, not per row).
template <class S>
GrassPushers<S> prepareGrassPushers(const std::vector<RigidBody<S>>& bodies, const ParticleGrid& grid,
                                    const BodyParticleSettings<S>& settings);

/// Applies every pusher to particle rows [rowBegin, rowEnd) (storage rows). Adds the number of
/// particles each body pushed to pushedPerBody[body] (may be null). Returns the first faulting
/// particle or -1. `kernel` picks the pre-test (grass_candidates.h): the same bits either way.
template <class S>
int64_t pushParticlesOutOfBodies(ParticleArrays<S>& particles, const ParticleGrid& grid, const GrassPushers<S>& pushers,
                                 const BodyParticleSettings<S>& settings, int64_t rowBegin, int64_t rowEnd,
                                 int64_t* pushedPerBody, ParticleKernel kernel);

}  // namespace sg
