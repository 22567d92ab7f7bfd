// Rigid-body integration, split around the contact solver (semi-implicit Euler, Cyclone's
// RigidBody::integrate reordered): velocities take gravity before the solver sees them, so a
// resting contact cancels gravity in the same tick instead of sinking by g dt^2 first; positions
// integrate with the solved velocities in the integrate stage.
#pragma once

#include <vector>

#include "sim/bodies/rigid_body.h"

namespace sg {

/// v += g dt for every body.
template <class S>
inline void applyGravity(std::vector<RigidBody<S>>& bodies, const Vec3<S>& gravityDt) {
  for (RigidBody<S>& b : bodies)
    if (!b.asleep) b.velocity += gravityDt;
}

/// p += v dt; q += dt/2 (0, w) q, renormalised; then v, w *= damping^dt.
template <class S>
inline void integrateBodyPositions(std::vector<RigidBody<S>>& bodies, S dt) {
  for (RigidBody<S>& b : bodies) {
    if (b.asleep) continue;
    b.position += b.velocity * dt;
    const Vec3<S> w = b.angularVelocity * (dt / S(2));
    const Quat<S> spin(S(0), w.x(), w.y(), w.z());
    Quat<S> q = b.orientation;
    q.coeffs() += (spin * b.orientation).coeffs();
    b.orientation = normalizedQuat(q);
    b.velocity *= b.linearDampingPerTick;
    b.angularVelocity *= b.angularDampingPerTick;
    b.updateDerived();
  }
}

/// |v| < threshold, without squaring a large component: in fx16 a speed above 181 m/s squared
/// overflows Q16.16 (a fast body faulted at tick 0 in the sleep test). A component at or above
/// the threshold decides at once; below it every square is smaller than threshold^2.
template <class S>
inline bool slowerThan(const Vec3<S>& v, S threshold) {
  for (int k = 0; k < 3; ++k)
    if (!(abs(v[k]) < threshold)) return false;
  return v.squaredNorm() < threshold * threshold;
}

/// Sleeping (a deterministic rule: integer counters and comparisons only). A body whose speed and
/// angular speed both stay below the thresholds, and none of whose contacts slid, for
/// `ticksToSleep` consecutive ticks falls asleep with zero velocities; it wakes when a command
/// moves it or a body near it, or when an awake body touches it.
template <class S>
inline void updateSleep(std::vector<RigidBody<S>>& bodies, S linearThreshold, S angularThreshold,
                        int32_t ticksToSleep) {
  for (RigidBody<S>& b : bodies) {
    if (!b.canSleep || b.asleep) continue;
    const bool still = !b.slidingThisTick && slowerThan(b.velocity, linearThreshold) &&
                       slowerThan(b.angularVelocity, angularThreshold);
    b.stillTicks = still ? b.stillTicks + 1 : 0;
    if (b.stillTicks >= ticksToSleep) {
      b.asleep = true;
      b.velocity = Vec3<S>::Zero();
      b.angularVelocity = Vec3<S>::Zero();
    }
  }
}

inline void wake(auto& body) {
  body.asleep = false;
  body.stillTicks = 0;
}

}  // namespace sg
