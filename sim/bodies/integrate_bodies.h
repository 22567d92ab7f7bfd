// Rigid-body integration, split around the contact solver (semi-implicit Euler, as Box2D v3's
// b2IntegrateVelocities / b2IntegratePositions): in every sub-step velocities take gravity before
// the solver sees them, so a resting contact cancels gravity in the same sub-step instead of
// sinking by g h^2 first; positions integrate with the solved velocities; damping once a tick.
#pragma once

#include <vector>

#include "sim/bodies/rigid_body.h"

namespace sg {

/// v += g h for an awake body (gravityH = g h).
template <class S>
inline void applyGravity(RigidBody<S>& b, const Vec3<S>& gravityH) {
  if (!b.asleep) b.velocity += gravityH;
}

/// |w| capped at maxAngularSpeed (rad/s), about the same axis. Box2D v3 caps a body's rotation
/// at a quarter turn per sub-step (b2_maxRotation) and Jolt at mMaxAngularVelocity: past it the
/// position step's small-angle quaternion update is wrong anyway, and w^2 I (the gyroscopic
/// term, a contact's r x w) left fx16's range: a 10 kg box hit at 200 m/s on a spiky heightmap
/// spun past 1,000 rad/s and overflowed. Every scalar caps alike, so variants stay comparable.
template <class S>
inline void clampAngularSpeed(RigidBody<S>& b, S maxAngularSpeed) {
  if (b.asleep) return;
  const Vec3<S>& w = b.angularVelocity;
  if (!(abs(w.x()) > maxAngularSpeed / S(2)) && !(abs(w.y()) > maxAngularSpeed / S(2)) &&
      !(abs(w.z()) > maxAngularSpeed / S(2)))
    return;  // |w| <= sqrt(3)/2 of the cap: the common case without a square root
  const S speed = length3(w.x(), w.y(), w.z());
  if (speed > maxAngularSpeed) b.angularVelocity *= maxAngularSpeed / speed;
}

/// p += v h; q += h/2 (0, w) q, renormalised (h: one sub-step, s). Updates the rotation matrix;
/// the world inverse inertia is left to the caller (RigidBody::updateInvInertiaWorld, once a tick).
template <class S>
inline void integrateBodyPosition(RigidBody<S>& b, S h) {
  if (b.asleep) return;
  b.position += b.velocity * h;
  const Vec3<S> w = b.angularVelocity * (h / S(2));
  const Quat<S> spin(S(0), w.x(), w.y(), w.z());
  Quat<S> q = b.orientation;
  q.coeffs() += (spin * b.orientation).coeffs();
  b.orientation = normalizedQuat(q);
  b.updateRotation();
}

/// v, w *= damping^dt, once a tick.
template <class S>
inline void applyDamping(std::vector<RigidBody<S>>& bodies) {
  for (RigidBody<S>& b : bodies) {
    if (b.asleep) continue;
    b.velocity *= b.linearDampingPerTick;
    b.angularVelocity *= b.angularDampingPerTick;
  }
}

inline void wake(auto& body) {
  body.asleep = false;
  body.stillTicks = 0;
}

}  // namespace sg
