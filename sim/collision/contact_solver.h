// Collision response for rigid bodies (thesis §7, Cyclone; the restitution pass after Box2D v3):
//   0. prepare: each contact's arms, directions and effective masses, and its normal relative
//      velocity *before* this tick's gravity (`approachVelocity`). Restitution is measured
//      against it: the velocity after gravity was taken by a ball already inside the ground, so
//      reflecting it returned g dt more speed than arrived, every bounce (a ball with e = 1
//      dropped from 2 m rose to 6.8 m in a minute at 60 Hz).
//   1. velocities: sequential impulses over all contacts, `velocityIterations` sweeps, with
//      accumulated normal impulses kept >= 0 and a separating-velocity target of 0; Coulomb
//      friction on two tangents, accumulated and clamped to mu * normal impulse (the thesis
//      leaves friction out; a testbed needs it).
//   2. restitution, one pass after the solve (Box2D v3's b2ApplyRestitution): a contact that
//      approached faster than `restitutionThreshold` and pushed (normal impulse > 0) takes the
//      impulse that makes its separating velocity e times the approach velocity.
//   3. positions: Cyclone's non-linear projection, down to `linearSlop` of overlap (so resting
//      contacts persist from tick to tick). Repeatedly take the deepest contact, move both
//      bodies linearly and angularly in proportion to their inverse mass and inverse angular
//      inertia about the contact, limit the angular part to 0.2 |r| per step, and update the
//      penetration of every other contact of the moved bodies. It moves positions only: it
//      never feeds velocity.
// Contacts are sorted canonically (bodies, then features) before solving, so the result never
// depends on how the narrow phase found them.
#pragma once

#include <vector>

#include "sim/bodies/rigid_body.h"
#include "sim/collision/contact.h"

namespace sg {

template <class S>
struct SolverSettings {
  int velocityIterations = 8;
  int positionIterationsPerContact = 8;  // the scenario's bodies.positionIterations default
  S restitutionThreshold{};              ///< m/s
  S linearSlop{};                        ///< m: penetration the position pass leaves alone
};

/// Sorts contacts into their canonical order (bodyA, bodyB, featureA, featureB).
template <class S>
void sortContacts(std::vector<Contact<S>>& contacts);

/// The accumulated impulses of one contact at the end of a tick, keyed by its canonical identity
/// (bodies and features). The next tick starts from them (warm starting, as Box2D and Jolt do):
/// without it, sequential impulses need many more iterations and a stack leans and falls.
/// Part of the world state (saved, restored, hashed).
template <class S>
struct CachedImpulse {
  int32_t bodyA = 0, bodyB = kTerrainBody;
  uint32_t featureA = 0, featureB = 0;
  S normal{}, tangent1{}, tangent2{};
  Vec3<S> point = Vec3<S>::Zero();  ///< world contact point, for matching when features change
  friend bool operator==(const CachedImpulse&, const CachedImpulse&) = default;
};

/// One contact as the velocity solver sees it (one row of the normal and two friction
/// constraints).
template <class S>
struct ContactRow {
  Vec3<S> rA, rB;  ///< m: contact point relative to the centres of mass
  Vec3<S> normal, t1, t2;
  S massN{}, massT1{}, massT2{};  ///< kg: 1 / effective inverse mass along each direction
  S approachVelocity{};           ///< m/s: normal relative velocity before this tick's gravity (< 0: closing)
  S restitution{}, friction{};
  S impulseN{}, impulseT1{}, impulseT2{};  ///< N s, accumulated
  int32_t a = 0, b = kTerrainBody;
};

/// Builds the rows of `contacts` from the bodies as they are before this tick's gravity (stage 0).
template <class S>
void prepareContactRows(const std::vector<RigidBody<S>>& bodies, const std::vector<Contact<S>>& contacts,
                        std::vector<ContactRow<S>>& rows);

/// Solves velocities (stages 1 and 2); `cache` holds last tick's impulses (sorted by key) and is
/// replaced by this tick's. A contact takes the cached impulses of the same key, or else of the
/// nearest cached contact point of the same body pair within 1 cm: two coplanar box faces swap
/// clipping features from tick to tick (a corner exactly on a side plane), and losing their
/// impulses makes a stack walk.
template <class S>
void solveContactVelocities(std::vector<RigidBody<S>>& bodies, const std::vector<Contact<S>>& contacts,
                            std::vector<ContactRow<S>>& rows, const SolverSettings<S>& settings,
                            std::vector<CachedImpulse<S>>& cache);

/// Stage 3. A contact separating at vn > 0 after the velocity solve loses vn dt of its overlap in
/// this tick's integration by itself: the projection removes only the rest. Projecting the whole
/// overlap of a bouncing contact counted that separation twice and lifted the body by up to
/// u dt per bounce, potential energy from nowhere (a ball with e = 0.9 settled into endless
/// 5 cm hops at the 1 m/s restitution threshold instead of coming to rest).
template <class S>
void solveContactPositions(std::vector<RigidBody<S>>& bodies, const std::vector<Contact<S>>& contacts,
                           const std::vector<ContactRow<S>>& rows, S dt, const SolverSettings<S>& settings);

}  // namespace sg
