// Eigen 3.4 support for the fixed-point scalars: Eigen::Matrix<Fx32, 3, 1>, Matrix3,
// Quaternion and friends compile and compute with the deterministic operators.
//
// Per Eigen's "Using custom scalar types" page: NumTraits is specialised fully (the default
// dummy_precision() is Real(0), which would break isApprox), infinity()/quiet_NaN() exist (the
// fixed types have neither, so they return the extreme value and zero), and sqrt/abs/abs2 are
// found by argument-dependent lookup in namespace sg. Eigen does not vectorise custom scalars;
// the particle hot loops are plain SoA loops, Eigen is for the small 3x3 and quaternion work.
// Quaternion slerp, angularDistance, AngleAxis and Euler angles call trigonometry: they are
// not used inside the step.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sim/math/fixed.h"

namespace sg {
template <class R, class W, int F>
constexpr Fixed<R, W, F> abs2(Fixed<R, W, F> a) noexcept {
  return a * a;
}
template <class R, class W, int F>
constexpr Fixed<R, W, F> conj(Fixed<R, W, F> a) noexcept {
  return a;
}
template <class R, class W, int F>
constexpr Fixed<R, W, F> real(Fixed<R, W, F> a) noexcept {
  return a;
}
template <class R, class W, int F>
constexpr Fixed<R, W, F> imag(Fixed<R, W, F>) noexcept {
  return {};
}
template <class R, class W, int F>
constexpr bool isfinite(Fixed<R, W, F>) noexcept {
  return true;
}
template <class R, class W, int F>
constexpr bool isnan(Fixed<R, W, F>) noexcept {
  return false;
}
template <class R, class W, int F>
constexpr bool isinf(Fixed<R, W, F>) noexcept {
  return false;
}
}  // namespace sg

namespace Eigen {
template <class R, class W, int F>
struct NumTraits<sg::Fixed<R, W, F>> : GenericNumTraits<sg::Fixed<R, W, F>> {
  using Fx = sg::Fixed<R, W, F>;
  using Real = Fx;
  using NonInteger = Fx;
  using Nested = Fx;
  using Literal = Fx;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 1,
    AddCost = 2,
    MulCost = 6,
  };
  static constexpr Fx epsilon() { return Fx::epsilon(); }
  /// isApprox tolerance: 2^(F/2) ulps, i.e. about 1.5e-5 for Q32.32 and 4e-3 for Q16.16.
  static constexpr Fx dummy_precision() { return Fx::fromRaw(R(1) << (F / 2)); }
  static constexpr Fx highest() { return Fx::max(); }
  static constexpr Fx lowest() { return Fx::min(); }
  static constexpr int digits10() { return F * 3 / 10; }
  static constexpr int digits() { return int(sizeof(R) * 8) - 1; }
  static constexpr Fx infinity() { return Fx::max(); }
  static constexpr Fx quiet_NaN() { return Fx(); }
};
}  // namespace Eigen

namespace sg {
template <class S>
using Vec3 = Eigen::Matrix<S, 3, 1>;
template <class S>
using Mat3 = Eigen::Matrix<S, 3, 3>;
template <class S>
using Quat = Eigen::Quaternion<S>;

/// a . b with Eigen's own bits, always inlined. For the fixed-point scalars Eigen's dot is a
/// function call GCC will not inline (its unrolled reduction is too large for the inliner), a
/// third of the work of a contact row's relative velocity; this is the same sum in the same
/// order, a0 b0 + (a1 b1 + a2 b2) (Eigen's redux_novec_unroller halves the range), so the same
/// bits and the same overflow faults. float and double keep Eigen's dot, which may vectorise
/// and then adds in another order.
template <class S>
[[gnu::always_inline]] inline S dot3(const Vec3<S>& a, const Vec3<S>& b) {
  if constexpr (requires { S::kFracBits; })
    return a.x() * b.x() + (a.y() * b.y() + a.z() * b.z());
  else
    return a.dot(b);
}

/// v += d s and v -= d s, element by element as Eigen computes them (the same bits in every
/// scalar), always inlined: Eigen's expression for a fixed-point scalar is another call GCC keeps.
template <class S>
[[gnu::always_inline]] inline void addScaled(Vec3<S>& v, const Vec3<S>& d, S s) {
  v.x() = v.x() + d.x() * s;
  v.y() = v.y() + d.y() * s;
  v.z() = v.z() + d.z() * s;
}
template <class S>
[[gnu::always_inline]] inline void subtractScaled(Vec3<S>& v, const Vec3<S>& d, S s) {
  v.x() = v.x() - d.x() * s;
  v.y() = v.y() - d.y() * s;
  v.z() = v.z() - d.z() * s;
}
/// m v with Eigen's bits, always inlined: for the fixed-point scalars each row is dot3's sum
/// (Eigen's lazy product reduces each row the same way); float and double keep Eigen's product.
template <class S>
[[gnu::always_inline]] inline Vec3<S> times3(const Mat3<S>& m, const Vec3<S>& v) {
  if constexpr (requires { S::kFracBits; })
    return Vec3<S>(m(0, 0) * v.x() + (m(0, 1) * v.y() + m(0, 2) * v.z()),
                   m(1, 0) * v.x() + (m(1, 1) * v.y() + m(1, 2) * v.z()),
                   m(2, 0) * v.x() + (m(2, 1) * v.y() + m(2, 2) * v.z()));
  else
    return m * v;
}
}  // namespace sg
