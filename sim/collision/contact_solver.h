// Collision response for rigid bodies (thesis §7, Cyclone):
//   1. velocities: sequential impulses over all contacts, `velocityIterations` sweeps. Normal
//      impulses are accumulated and kept >= 0, the separating-velocity target is -e v_n
//      (restitution) for approaches faster than `restitutionThreshold`, else 0 (resting contact);
//      Coulomb friction on two tangents, accumulated and clamped to mu * normal impulse (the
//      thesis leaves friction out; a testbed needs it).
//   2. positions: Cyclone's non-linear projection, down to `linearSlop` of overlap (so resting
//      contacts persist from tick to tick). Repeatedly take the deepest contact, move both
//      bodies linearly and angularly in proportion to their inverse mass and inverse angular
//      inertia about the contact, limit the angular part to 0.2 |r| per step, and update the
//      penetration of every other contact of the moved bodies.
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
  int positionIterationsPerContact = 2;
  S restitutionThreshold{};  ///< m/s
  S linearSlop{};            ///< m: penetration the position pass leaves alone
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

/// Solves velocities; `cache` holds last tick's impulses (sorted by key) and is replaced by this
/// tick's. A contact takes the cached impulses of the same key, or else of the nearest cached
/// contact point of the same body pair within 1 cm: two coplanar box faces swap clipping
/// features from tick to tick (a corner exactly on a side plane), and losing their impulses makes
/// a stack walk.
template <class S>
void solveContactVelocities(std::vector<RigidBody<S>>& bodies, const std::vector<Contact<S>>& contacts,
                            const SolverSettings<S>& settings, std::vector<CachedImpulse<S>>& cache);

template <class S>
void solveContactPositions(std::vector<RigidBody<S>>& bodies, const std::vector<Contact<S>>& contacts,
                           const SolverSettings<S>& settings);

}  // namespace sg
