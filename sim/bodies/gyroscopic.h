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

/// w <- w + dw for an awake body with unequal principal inertias (a sphere or a cube has
/// w x I w = 0 exactly; skipping them keeps fixed-point rounding from making a torque of zero).
/// In body axes, the implicit midpoint rule (it conserves both kinetic energy and |L| of Euler's
/// equations, where implicit Euler lost a quarter of the energy of a box in 20 s at 60 Hz):
///   f(w') = I (w' - w) + dt m x I m = 0 with m = (w + w') / 2, one Newton step from w' = w:
///   J = I + dt/2 ([w]x I - [I w]x),  w' = w - J^-1 dt (w x I w).
/// Both sides are multiplied by I^-1 first, so the matrix solved is 1 + O(dt) (its determinant
/// stays near 1 however small the inertias are, where I1 I2 I3 would underflow fixed point).
template <class S>
void applyGyroscopicTerm(RigidBody<S>& b, S dt) {
  const Vec3<S>& invI = b.invInertiaLocal;
  const Vec3<S>& inertia = b.inertiaLocal;
  if (b.asleep || (inertia.x() == inertia.y() && inertia.y() == inertia.z())) return;
  if (invI.x() == S(0) || invI.y() == S(0) || invI.z() == S(0)) return;  // an axis that cannot turn
  const Vec3<S> w = b.rotation.transpose() * b.angularVelocity;          // body axes
  // m = 1 + I^-1 ([w]x I - [I w]x) dt/2, formed from the half turn w dt/2 (< pi/8 under the
  // angular-speed cap): I w itself leaves fx16's range for a large body spinning fast.
  const Vec3<S> halfTurn = w * (dt / S(2));
  Mat3<S> m = skew(halfTurn) * inertia.asDiagonal();
  m -= skew(Vec3<S>(inertia.cwiseProduct(halfTurn)));
  m = invI.asDiagonal() * m;
  m += Mat3<S>::Identity();
  // I^-1 (w x I w) dt, per component (w x I w)_x = w_y w_z (I_z - I_y), and so on: the
  // inertia ratio (I_z - I_y) / I_x first (bounded by the body's shape), then the speeds.
  // Above 16 rad/s dt goes before the second speed (w^2 overflows fx16 past 181 rad/s); not
  // below: a slow wobble's w^2 dt is under fx16's unit at h = 1/960 s and vanished.
  const Vec3<S> ratio(invI.x() * S(inertia.z() - inertia.y()), invI.y() * S(inertia.x() - inertia.z()),
                      invI.z() * S(inertia.y() - inertia.x()));
  S fastest(0);
  for (int k = 0; k < 3; ++k) fastest = maxS(fastest, abs(w[k]));
  const bool fast = fastest > S(16);
  auto term = [&](S ratioK, S wi, S wj) {
    return fast ? S(ratioK * S(wi * S(wj * dt))) : S(S(ratioK * S(wi * wj)) * dt);
  };
  const Vec3<S> rhs(term(ratio.x(), w.y(), w.z()), term(ratio.y(), w.z(), w.x()), term(ratio.z(), w.x(), w.y()));
  Vec3<S> next = w - solve3(m, rhs);
  // The midpoint rule keeps energy to O(dt^2) but lets it wander up by ~1e-4 of itself; a torque-
  // free body may not gain energy, so a step that would is scaled back onto the energy it had
  // (as Jolt scales its step back onto |L|).
  // Above 64 rad/s compared on w and w' divided by their largest component, and always with
  // the inertias divided by the largest: the ratio is the same, and no sum can overflow (fx16's
  // range ends at 3 x 64^2 x 1, where a 200 kg m^2 body at 18 rad/s had overflowed). Speeds
  // are not divided below 64 rad/s: that costs fx16 bits a slow spin needs (its energy drifted
  // 17 % in 20 s).
  using std::sqrt;
  S largest(1);
  for (int k = 0; k < 3; ++k) largest = maxS(largest, maxS(abs(w[k]), abs(next[k])));
  if (!(largest > S(64))) largest = S(1);
  const Vec3<S> a = w / largest, c = next / largest;
  const Vec3<S> shape = inertia / maxS(inertia.x(), maxS(inertia.y(), inertia.z()));
  const S before = shape.dot(a.cwiseProduct(a)), after = shape.dot(c.cwiseProduct(c));
  if (after > before && after > S(0)) next *= sqrt(before / after);
  // Only the change goes back through R: a rounded R is orthonormal to ~1e-5 in fx16, and
  // sending the whole of w out and back scaled it by that every step (|L| +22 %, energy +49 %
  // in 20 s of fx16 sub-steps at 960 Hz); the change is small, and so is its error.
  b.angularVelocity += b.rotation * Vec3<S>(next - w);
}

}  // namespace sg
