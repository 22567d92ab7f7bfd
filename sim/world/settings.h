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
/// Approaches slower than this (m/s) do not bounce (Box2D's b2_velocityThreshold): below it,
/// restitution plus the energy the position projection adds keeps a ball hopping forever.
inline constexpr Exact kRestitutionThreshold{1, 1};
/// Penetration the position projection leaves alone (m): resting contacts stay in contact, so
/// they neither jitter nor lose their warm-start impulses (Box2D's b2_linearSlop is 5 mm).
inline constexpr Exact kLinearSlop{1, 2000};

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
