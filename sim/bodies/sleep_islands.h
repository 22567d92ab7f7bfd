// Sleep by islands (Box2D v3's b2TrySleepIsland, Jolt's IslandBuilder): bodies linked by contacts
// this tick form an island, and an island falls asleep only as a whole, when every member has
// been still for `ticksToSleep` ticks. A body alone is an island of one. Sleeping bodies keep no
// contacts; an awake body that touches one wakes it and, transitively, the sleeping bodies near
// it (World::wakeIsland), so a stack sleeps and wakes together. Deterministic: integer counters,
// comparisons and a union-find whose roots depend only on the canonical contact order.
#pragma once

#include <algorithm>
#include <numeric>
#include <vector>

#include "sim/bodies/rigid_body.h"

namespace sg {

/// |v| < threshold, without squaring a large component: in fx16 a speed above 181 m/s squared
/// overflows Q16.16 (a fast body faulted at tick 0 in the sleep test). A component at or above
/// the threshold decides at once; below it every square is smaller than threshold^2.
template <class S>
inline bool slowerThan(const Vec3<S>& v, S threshold) {
  for (int k = 0; k < 3; ++k)
    if (!(abs(v[k]) < threshold)) return false;
  return v.squaredNorm() < threshold * threshold;
}

/// The island of every body: union-find over this tick's body-body contacts (terrain contacts
/// link nothing: the terrain holds any number of islands). Returns each body's root.
template <class S>
inline std::vector<int32_t> contactIslands(size_t bodyCount, const std::vector<Contact<S>>& contacts) {
  std::vector<int32_t> parent(bodyCount);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int32_t x) {
    while (parent[size_t(x)] != x) x = parent[size_t(x)] = parent[size_t(parent[size_t(x)])];
    return x;
  };
  for (const Contact<S>& c : contacts) {
    if (c.bodyB == kTerrainBody) continue;
    const int32_t a = find(c.bodyA), b = find(c.bodyB);
    if (a != b) parent[size_t(std::max(a, b))] = std::min(a, b);  // the lower id is the root
  }
  for (size_t i = 0; i < bodyCount; ++i) parent[i] = find(int32_t(i));
  return parent;
}

/// Counts each awake body's still ticks (both speeds below the thresholds, held by its contacts),
/// then puts to sleep, with zero velocities, every island whose members can all sleep and have
/// all been still for `ticksToSleep` ticks.
template <class S>
inline void updateSleep(std::vector<RigidBody<S>>& bodies, const std::vector<Contact<S>>& contacts, S linearThreshold,
                        S angularThreshold, int32_t ticksToSleep) {
  // The count saturates at ticksToSleep (a still body in an island that is not ready waits there;
  // the state format allows 0..ticksToSleep), and a body that may never sleep keeps 0.
  for (RigidBody<S>& b : bodies) {
    if (b.asleep || !b.canSleep) continue;
    const bool still =
        b.heldThisTick && slowerThan(b.velocity, linearThreshold) && slowerThan(b.angularVelocity, angularThreshold);
    b.stillTicks = still ? std::min(b.stillTicks + 1, ticksToSleep) : 0;
  }
  const std::vector<int32_t> island = contactIslands(bodies.size(), contacts);
  std::vector<uint8_t> ready(bodies.size(), 1);  // per root: every member may sleep now
  for (size_t i = 0; i < bodies.size(); ++i) {
    const RigidBody<S>& b = bodies[i];
    if (b.asleep) continue;
    if (!b.canSleep || b.stillTicks < ticksToSleep) ready[size_t(island[i])] = 0;
  }
  for (size_t i = 0; i < bodies.size(); ++i) {
    RigidBody<S>& b = bodies[i];
    if (b.asleep || !ready[size_t(island[i])]) continue;
    b.asleep = true;
    b.velocity = Vec3<S>::Zero();
    b.angularVelocity = Vec3<S>::Zero();
  }
}

}  // namespace sg
