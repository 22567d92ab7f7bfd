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
  for (RigidBody<S>& b : bodies) b.velocity += gravityDt;
}

/// p += v dt; q += dt/2 (0, w) q, renormalised; then v, w *= damping^dt.
template <class S>
inline void integrateBodyPositions(std::vector<RigidBody<S>>& bodies, S dt) {
  for (RigidBody<S>& b : bodies) {
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

}  // namespace sg
