// The gyroscopic term of a free rigid body: Euler's equations I dw/dt = -w x (I w) in the body
// frame. Without it the angular velocity stayed fixed in world space, so angular momentum was not
// conserved for an asymmetric body and a spin about the middle principal axis never flipped
// (the Dzhanibekov effect). Integrated implicitly with one Newton step, as Bullet does
// (btRigidBody::computeGyroscopicImpulseImplicit_Body), but on the midpoint rule rather than
// implicit Euler, and never adding kinetic energy.
#pragma once

#include <vector>

#include "sim/bodies/rigid_body.h"
#include "sim/math/scalar_ops.h"

namespace sg {

/// Solves M x = b for a 3x3 M by Cramer's rule; x = 0 when M is singular. M here is the identity
/// plus a dt-sized term, so its determinant is near 1 in every scalar.
template <class S>
Vec3<S> solve3(const Mat3<S>& m, const Vec3<S>& b) {
  const Vec3<S> c0 = m.col(0), c1 = m.col(1), c2 = m.col(2);
  const S det = c0.dot(c1.cross(c2));
  if (det == S(0)) return Vec3<S>::Zero();
  return Vec3<S>(b.dot(c1.cross(c2)), c0.dot(b.cross(c2)), c0.dot(c1.cross(b))) / det;
}

/// The skew matrix [v]x with [v]x u = v x u.
template <class S>
Mat3<S> skew(const Vec3<S>& v) {
  Mat3<S> m;
  m << S(0), -v.z(), v.y(), v.z(), S(0), -v.x(), -v.y(), v.x(), S(0);
  return m;
}

/// w <- w + dw for every awake body with unequal principal inertias (a sphere or a cube has
/// w x I w = 0 exactly; skipping them keeps fixed-point rounding from making a torque of zero).
/// In body axes, the implicit midpoint rule (it conserves both kinetic energy and |L| of Euler's
/// equations, where implicit Euler lost a quarter of the energy of a box in 20 s at 60 Hz):
///   f(w') = I (w' - w) + dt m x I m = 0 with m = (w + w') / 2, one Newton step from w' = w:
///   J = I + dt/2 ([w]x I - [I w]x),  w' = w - J^-1 dt (w x I w).
/// Both sides are multiplied by I^-1 first, so the matrix solved is 1 + O(dt) (its determinant
/// stays near 1 however small the inertias are, where I1 I2 I3 would underflow fixed point).
template <class S>
void applyGyroscopicTerm(std::vector<RigidBody<S>>& bodies, S dt) {
  for (RigidBody<S>& b : bodies) {
    const Vec3<S>& invI = b.invInertiaLocal;
    const Vec3<S>& inertia = b.inertiaLocal;
    if (b.asleep || (inertia.x() == inertia.y() && inertia.y() == inertia.z())) continue;
    if (invI.x() == S(0) || invI.y() == S(0) || invI.z() == S(0)) continue;  // an axis that cannot turn
    const Vec3<S> w = b.rotation.transpose() * b.angularVelocity;            // body axes
    const Vec3<S> momentum = inertia.cwiseProduct(w);
    Mat3<S> m = skew(w) * inertia.asDiagonal();
    m -= skew(momentum);
    m = invI.asDiagonal() * m;
    m *= dt / S(2);
    m += Mat3<S>::Identity();
    // I^-1 (w x I w) dt. Above 16 rad/s dt goes first: w x I w grows with |w|^2 and I^-1 is large
    // for a small body (300 rad/s on a 1 kg box overflowed fx16 in the other order). Not below:
    // a slow wobble's w x I w dt is under fx16's unit at h = 1/960 s and vanished.
    const Vec3<S> torque = w.cross(momentum);
    S fastest(0);
    for (int k = 0; k < 3; ++k) fastest = maxS(fastest, abs(w[k]));
    const Vec3<S> rhs =
        fastest > S(16) ? Vec3<S>(invI.cwiseProduct(Vec3<S>(torque * dt))) : Vec3<S>(invI.cwiseProduct(torque) * dt);
    Vec3<S> next = w - solve3(m, rhs);
    // The midpoint rule keeps energy to O(dt^2) but lets it wander up by ~1e-4 of itself; a torque-
    // free body may not gain energy, so a step that would is scaled back onto the energy it had
    // (as Jolt scales its step back onto |L|).
    // Above 128 rad/s compared on w and w' divided by their largest component: the ratio is the
    // same, and no square can overflow (fx16's range ends at 181 rad/s squared). Not below: the
    // division costs fx16 bits a slow spin needs (its energy drifted 17 % in 20 s).
    using std::sqrt;
    S largest(1);
    for (int k = 0; k < 3; ++k) largest = maxS(largest, maxS(abs(w[k]), abs(next[k])));
    if (!(largest > S(128))) largest = S(1);
    const Vec3<S> a = w / largest, c = next / largest;
    const S before = inertia.dot(a.cwiseProduct(a)), after = inertia.dot(c.cwiseProduct(c));
    if (after > before && after > S(0)) next *= sqrt(before / after);
    // Only the change goes back through R: a rounded R is orthonormal to ~1e-5 in fx16, and
    // sending the whole of w out and back scaled it by that every step (|L| +22 %, energy +49 %
    // in 20 s of fx16 sub-steps at 960 Hz); the change is small, and so is its error.
    b.angularVelocity += b.rotation * Vec3<S>(next - w);
  }
}

}  // namespace sg
