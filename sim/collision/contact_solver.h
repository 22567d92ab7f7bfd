// Contact solver for rigid bodies: a soft step after Box2D v3 (b2SolverStage in solver.c,
// contact_solver.c), written for 3D, fixed point and one deterministic sequence. One tick of dt
// is `substeps` sub-steps of h = dt / substeps; the world runs, in order (world_contacts.cpp):
//   prepare   (once)  each contact's arms, effective masses, body-frame anchors and separation;
//                     last tick's impulses by contact key (warm starting);
//   per sub-step:     gravity and the gyroscopic term (h); warm start (apply the accumulated
//                     impulses); solve with soft bias; integrate positions (h); relax without
//                     bias;
//   store (once)      the impulses, keyed, for the next tick (before restitution: the next tick
//                     warm-starts with the resting impulse, not the one-off bounce); which
//                     bodies slid;
//   restitution (once) a contact that pushed against an approach faster than
//                     `restitutionThreshold` takes the impulse that makes its separating velocity
//                     e times that approach (b2ApplyRestitution). The approach is the normal
//                     velocity the pushing solves met, before their impulse: after the gravity
//                     of that sub-step only (measured after the whole tick's gravity, with the
//                     body already in the ground, each bounce gained g dt: 2 m became 6.8 m in
//                     a minute).
//
// Why this design (it replaced sequential impulses plus Cyclone's position projection):
//   * Soft contacts (a spring-damper of `contactHertz`, damping ratio `contactDampingRatio`, as
//     an implicit soft constraint) push overlap out at a bounded speed (`contactPushMaxVelocity`)
//     and the relax pass then removes that push velocity: position correction never feeds
//     velocity, so it cannot add energy (the projection moved positions only, but its
//     overshoots and re-contacts did).
//   * Sub-steps: the stack and mass-ratio error of Gauss-Seidel falls with the step size
//     squared, so 4 sub-steps of 1 iteration beat 16 iterations of one step (Box2D's result:
//     a 20-box stack stands at defaults, where the old solver needed 128 iterations).
//   * The current separation is recomputed from the bodies' moved anchors after every position
//     update (before the solve and before the relax sweeps), so a sub-step solves the positions it
//     has, not those of the tick's start.
//   * Speculative contacts: a contact of positive separation s (the narrow phase reports shapes
//     up to the speculative distance plus the tick's motion apart) lets the bodies close by at
//     most s within a sub-step (bias s / h). A body fast enough to pass through a wall in one
//     tick stops at its surface: continuous collision without a time-of-impact search.
// Contacts are solved in their canonical order (bodies, then features): the same bits for any
// broad phase and thread count. Box2D colours the constraint graph to solve it in parallel; a
// sequential solve in canonical order needs no colouring and converges as well.
#pragma once

#include <span>
#include <vector>

#include "sim/bodies/rigid_body.h"
#include "sim/collision/contact.h"

namespace sg {

/// An implicit soft constraint's coefficients for one sub-step h (Box2D's b2Softness): with
/// omega = 2 pi hertz, a1 = 2 zeta + h omega, a2 = h omega a1, a3 = 1 / (1 + a2):
/// biasRate = omega / a1 (1/s), massScale = a2 a3, impulseScale = a3.
template <class S>
struct Softness {
  S biasRate{};
  S massScale{1};
  S impulseScale{};
};

/// The soft coefficients for a spring of `hertz` and damping ratio `zeta` over a sub-step h (s);
/// `pi` is pi in S. hertz 0 gives a rigid constraint without bias.
template <class S>
Softness<S> makeSoftness(S hertz, S zeta, S h, S pi);

template <class S>
struct SolverSettings {
  int substeps = 4;               ///< sub-steps per tick (the scenario's bodies.substeps)
  int solveIterations = 3;        ///< solve sweeps per sub-step of a body alone (bodies.velocityIterations)
  int islandSolveIterations = 6;  ///< of an island of 2+ bodies (bodies.islandVelocityIterations, >= the above)
  int relaxIterations = 1;        ///< relax sweeps per sub-step (bodies.positionIterations)
  S restitutionThreshold{};       ///< m/s
  S maxPushVelocity{};            ///< m/s: the fastest a soft contact pushes overlap out
  S linearSlop{};                 ///< m: deeper overlap keeps a body awake (settings::kLinearSlop)
  /// s: 1 / (h omega^2) of body-body and terrain contacts. A soft contact carrying the normal
  /// impulse P per sub-step gives way by P / (m h omega^2), m its effective mass, at rest: that
  /// much overlap is its load, not a push-out (storeImpulses' sleep rule).
  S bodyGiveTime{}, staticGiveTime{};
  S invSubstep{};                     ///< 1/s: 1 / h
  Vec3<S> gravity = Vec3<S>::Zero();  ///< m/s^2 (restitution's speculative-gap gain)
  Softness<S> bodySoftness;           ///< body against body
  Softness<S> staticSoftness;         ///< body against the terrain: twice as stiff (Box2D)
};

/// Sorts contacts into their canonical order (bodyA, bodyB, featureA, featureB).
template <class S>
void sortContacts(std::vector<Contact<S>>& contacts);

/// The accumulated impulses of one contact at the end of a tick (per sub-step), keyed by its
/// canonical identity (bodies and features). The next tick starts from them (warm starting, as
/// Box2D and Jolt do). Part of the world state (saved, restored, hashed).
template <class S>
struct CachedImpulse {
  int32_t bodyA = 0, bodyB = kTerrainBody;
  uint32_t featureA = 0, featureB = 0;
  S normal{}, tangent1{}, tangent2{};
  Vec3<S> point = Vec3<S>::Zero();  ///< world contact point, for matching when features change
  friend bool operator==(const CachedImpulse&, const CachedImpulse&) = default;
};

/// One direction of a contact row (the normal or a friction tangent) with its Jacobian
/// precomputed at prepare, so a sweep is dot products and axpys, no cross product or matrix
/// (Box2D keeps rn = r x n the same way): the relative velocity along `dir` is
/// vA.dir + wA.armA - vB.dir - wB.armB, and an impulse p along it changes wA by turnA p.
template <class S>
struct ContactAxis {
  Vec3<S> dir = Vec3<S>::Zero();                             ///< unit
  Vec3<S> armA = Vec3<S>::Zero(), armB = Vec3<S>::Zero();    ///< m: rA x dir, rB x dir
  Vec3<S> turnA = Vec3<S>::Zero(), turnB = Vec3<S>::Zero();  ///< 1/(kg m): I^-1 (r x dir) of each body
  S invMass{};                                               ///< 1/kg: 1/mA + 1/mB + armA.turnA + armB.turnB
  S mass{};                                                  ///< kg: 1 / invMass; 0 when immovable
  S impulse{};                                               ///< N s per sub-step, accumulated
};

/// One contact as the solver sees it: the normal and two friction axes.
template <class S>
struct ContactRow {
  ContactAxis<S> normal, t1, t2;
  Vec3<S> localA = Vec3<S>::Zero(),
          localB = Vec3<S>::Zero();     ///< m: contact point from each centre of mass, body frame
  Vec3<S> anchorGap = Vec3<S>::Zero();  ///< m: A's anchor - B's anchor (terrain: A's alone) at prepare; s starts exact
  S separation{};                       ///< m at prepare: minus the penetration (> 0: speculative)
  S separationNow{};                    ///< m: the separation at the bodies' present poses (updateSeparations)
  S invMassA{}, invMassB{};
  S impactVelocity{};  ///< m/s: the most negative normal velocity a pushing solve met this tick
  S impactGap{};       ///< m: the separation (>= 0) when it did (a speculative stop short of the surface)
  S restitution{}, friction{};
  S maxImpulseN{};  ///< the largest normal impulse of any sub-step (did it push?)
  int32_t a = 0, b = kTerrainBody;
  bool slidingAxes = false;  ///< t1 along the sliding velocity at prepare (else tangentOf(normal))
};

/// Builds rows [begin, end) of `contacts` (sized to them by the caller) from the bodies as they
/// are before this tick's gravity, and takes each contact's impulses from `cache` (last tick's,
/// sorted by key): the entry of the same key, or else the nearest cached point of the same body
/// pair within 1 cm (two coplanar box faces swap clipping features from tick to tick, and losing
/// their impulses makes a stack walk). [begin, end) must hold whole body pairs (nextPairStart):
/// a pair's rows share their cache entries and their sliding rule, and ranges so cut build the
/// same rows apart, or on different threads, as the whole list at once.
template <class S>
void prepareContacts(const std::vector<RigidBody<S>>& bodies, const std::vector<Contact<S>>& contacts,
                     const std::vector<CachedImpulse<S>>& cache, int substeps, std::vector<ContactRow<S>>& rows,
                     size_t begin, size_t end);

/// The first row at or after i that starts a body pair (contacts sorted; contacts.size() past the end).
template <class S>
size_t nextPairStart(const std::vector<Contact<S>>& contacts, size_t i);

/// What one island's sub-steps need besides its bodies, rows and SolverSettings.
template <class S>
struct IslandStep {
  Vec3<S> gravityH = Vec3<S>::Zero();  ///< m/s: g h, a sub-step's gravity
  S maxAngularSpeed{};                 ///< rad/s (clampAngularSpeed)
  S h{};                               ///< s: one sub-step
};

/// The sub-steps of one island: `islandBodies` (ascending) and the rows that join them
/// (`islandRows`, ascending: their canonical order). Each sub-step: gravity, the angular-speed cap
/// and the gyroscopic term per awake body; warm start; the separations at the present poses;
/// `solveIterations` sweeps with bias (`islandSolveIterations` for an island of two or more
/// bodies); positions integrated over h; the separations again; `relaxIterations` sweeps without
/// bias. Then each awake body's world inverse inertia (read by the next prepare).
/// Islands share no body (rows against the terrain join none: it does not move), so solving them
/// one after another, or at the same time on different threads, gives the same bits: every
/// operation of an island reads and writes that island's bodies and rows only, in canonical
/// order. (With one sweep count for all, that is the bits of one sweep over all rows; the code
/// before islands did that, and tests/data/solver_pile*.json keep its hashes at
/// "islandVelocityIterations": 3.)
template <class S>
void solveIsland(std::vector<RigidBody<S>>& bodies, std::vector<ContactRow<S>>& rows,
                 std::span<const int32_t> islandBodies, std::span<const int32_t> islandRows,
                 const SolverSettings<S>& settings, const IslandStep<S>& step);

/// After the sub-steps: restitution against the impact velocity, where the contact pushed.
template <class S>
void applyRestitution(std::vector<RigidBody<S>>& bodies, std::vector<ContactRow<S>>& rows,
                      const SolverSettings<S>& settings);

/// Replaces `cache` by this tick's impulses and marks the bodies whose contacts slid or overlap
/// by more than the slop, or that one turning point holds (RigidBody::heldThisTick false).
template <class S>
void storeImpulses(std::vector<RigidBody<S>>& bodies, const std::vector<Contact<S>>& contacts,
                   const std::vector<ContactRow<S>>& rows, const SolverSettings<S>& settings,
                   std::vector<CachedImpulse<S>>& cache);

}  // namespace sg
