// The core's built-in constants that no scenario sets: solver thresholds, the sleep rule and the
// parallel chunk size. One place, with the reason for each value; exact fractions so every scalar
// rounds the same value once.
#pragma once

#include <cstdint>

namespace sg::settings {

/// An exact constant num/den in SI units.
struct Exact {
  int64_t num, den;
};

// ---- contact solver (sim/collision/contact_solver.cpp) -------------------------------------
/// Approaches slower than this (m/s) do not bounce (Box2D's b2_velocityThreshold): a resting
/// body's contacts approach at g h every sub-step and must not hop.
inline constexpr Exact kRestitutionThreshold{1, 1};
/// Soft contacts (Box2D v3's contactHertz 30, contactDampingRatio 10, contactSpeed 3 m/s): the
/// spring that pushes overlap out, capped below a quarter of the sub-step rate (stiffer is not
/// resolved by the sub-step), heavily overdamped so it does not bounce, and never faster than
/// kContactPushMaxVelocity. Terrain contacts use twice the frequency (nothing there gives way).
/// The hertz is the scenario's `bodies.contactHertz` (default 60).
inline constexpr Exact kContactDampingRatio{10, 1};
inline constexpr Exact kContactPushMaxVelocity{3, 1};
/// Shapes this close (m) get speculative contacts even when nothing moves (Box2D's
/// b2_speculativeDistance, 4 x its 5 mm slop): a resting contact that opens by rounding or a
/// small hop keeps its row and its warm-start impulses. The world adds each body's motion in
/// the tick, (|v| + |w| r + |g| dt) dt, for continuous collision.
inline constexpr Exact kSpeculativeDistance{1, 50};
/// The most contacts one tick may hold, bodies against bodies and against the terrain together
/// (2^18: about 100 MB of contacts and solver rows at fx32). A pile of 1,024 bodies resting on
/// each other holds tens of thousands; past this, bodies are heaped inside one another (128
/// compounds of 16 boxes placed at one spot made 8 million, and ran the machine out of memory),
/// and the tick stops with an error naming the count instead.
inline constexpr int64_t kMaxContacts = int64_t(1) << 18;
/// Overlap above which a body counts as being pushed out (m, Box2D's b2_linearSlop). The solver
/// itself has no slop (soft contacts settle to their load's give); only the sleep rule reads it:
/// a body with a contact deeper than this is moving at up to kContactPushMaxVelocity, a motion
/// the relax pass hides from its velocity, so it may not fall asleep (a sphere started 1.5 m under
/// the ground fell asleep 8 cm inside it). A contact that gives more than this under a heavy
/// load (1000 kg on a 1 kg box) keeps its island awake.
inline constexpr Exact kLinearSlop{1, 200};
/// pi for the soft constraints' 2 pi hertz (355/113: 3e-7 relative, far below what a stiffness
/// needs; an exact fraction, so every scalar rounds it once).
inline constexpr Exact kPi{355, 113};

// ---- the viewer's mouse drag (BodyCommandKind::DragTo, sim/bodies/body_commands.cpp) --------
/// Box2D's mouse joint: a soft spring of 5 Hz, damping ratio 0.7, on the centre of mass, solved
/// implicitly over the tick (stable at any dt). It sags g / omega^2 = 1 cm under gravity.
inline constexpr Exact kDragHertz{5, 1};
inline constexpr Exact kDragDampingRatio{7, 10};
/// The pull is bounded, so a target far away (a hostile input) neither overflows nor flings:
/// the offset counts at most 10 m per axis, the velocity change at most 50 m/s per axis a tick.
inline constexpr Exact kDragMaxOffset{10, 1};
inline constexpr Exact kDragMaxSpeedChange{50, 1};

// ---- sleep (sim/bodies/integrate_bodies.h) --------------------------------------------------
/// A body below both speeds for kSleepTime falls asleep (m/s, rad/s, s).
inline constexpr Exact kSleepLinearSpeed{1, 20};
inline constexpr Exact kSleepAngularSpeed{1, 20};
inline constexpr Exact kSleepTime{1, 2};

// ---- parallel chunks (sim/world/chunk_pool.h) -----------------------------------------------
/// Particles (or patches) per chunk, roughly: chunk boundaries depend on the problem size only,
/// never on the thread count, so every thread count gives the same bits. 4096 fixed-point
/// particles' nine arrays (~300 KB) fit a core's L2.
inline constexpr int64_t kTargetChunkElements = 4096;

}  // namespace sg::settings
