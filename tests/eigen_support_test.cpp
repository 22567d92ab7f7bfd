// Eigen 3.4 over the fixed-point scalars (sim/math/eigen_support.h): Vec3, Mat3 and Quaternion
// of Fx32 and Fx16 compile and compute what the fixed-point operators promise.
//
// References are computed in long double from the fixed-point inputs themselves (toLd below is
// exact: every raw fits a 64-bit mantissa), so input rounding never enters a tolerance. Each
// tolerance is an error bound in ulps u = 2^-F derived from how many roundings Eigen's formula
// performs: a fixed-point product rounds once (<= u/2), + and - are exact. The long double
// reference itself errs by < 1e-15 u for the magnitudes used here (|values| < 100, 64-bit
// mantissa), covered by a slack of 1e-3 u.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "sim/math/eigen_support.h"
#include "sim/math/fixed.h"
#include "tests/printers.h"

namespace {

using sg::Fx16;
using sg::Fx32;

template <class Fx>
long double toLd(Fx x) {
  return static_cast<long double>(x.raw()) / static_cast<long double>(Fx::kOneRaw);
}
template <class Fx>
long double ulp() {
  return std::ldexp(1.0L, -Fx::kFracBits);
}
constexpr long double kSlack = 1e-3L;

/// |got - want| <= tolUlps ulps (+ the reference slack).
template <class Fx>
::testing::AssertionResult within(Fx got, long double want, long double tolUlps) {
  const long double err = fabsl(toLd(got) - want) / ulp<Fx>();
  if (err <= tolUlps + kSlack) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got " << double(toLd(got)) << " (raw " << int64_t(got.raw()) << "), want "
                                       << double(want) << ": error " << double(err) << " ulps > " << double(tolUlps);
}

/// Exact element-wise equality of two matrices or vectors (prints raw values on failure; the
/// fixed-point types have no operator<<, so EXPECT_EQ could not print them).
template <class A, class B>
::testing::AssertionResult same(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b) {
  const auto ea = a.eval();
  const auto eb = b.eval();
  if (ea.rows() != eb.rows() || ea.cols() != eb.cols()) return ::testing::AssertionFailure() << "shape differs";
  for (Eigen::Index i = 0; i < ea.rows(); ++i)
    for (Eigen::Index j = 0; j < ea.cols(); ++j)
      if (ea(i, j) != eb(i, j))
        return ::testing::AssertionFailure()
               << "(" << i << "," << j << "): raw " << int64_t(ea(i, j).raw()) << " vs " << int64_t(eb(i, j).raw());
  return ::testing::AssertionSuccess();
}

template <class Fx>
Fx randomFx(std::mt19937_64& g, double limit) {
  const int64_t m = int64_t(limit * double(Fx::kOneRaw));
  return Fx::fromRaw(static_cast<typename Fx::RawType>(std::uniform_int_distribution<int64_t>(-m, m)(g)));
}
template <class Fx>
sg::Vec3<Fx> randomVec(std::mt19937_64& g, double limit) {
  return {randomFx<Fx>(g, limit), randomFx<Fx>(g, limit), randomFx<Fx>(g, limit)};
}
template <class Fx>
sg::Mat3<Fx> randomMat(std::mt19937_64& g, double limit) {
  sg::Mat3<Fx> m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = randomFx<Fx>(g, limit);
  return m;
}
/// A nearly-unit quaternion: a random direction in 4D, normalised in double, then rounded.
template <class Fx>
sg::Quat<Fx> randomUnitQuat(std::mt19937_64& g) {
  std::normal_distribution<double> n;
  double c[4];
  double s = 0;
  do {
    s = 0;
    for (double& v : c) {
      v = n(g);
      s += v * v;
    }
  } while (s < 1e-3);
  s = std::sqrt(s);
  return sg::Quat<Fx>(Fx::fromDouble(c[0] / s), Fx::fromDouble(c[1] / s), Fx::fromDouble(c[2] / s),
                      Fx::fromDouble(c[3] / s));
}

template <class Fx>
class EigenFixed : public ::testing::Test {
 protected:
  void SetUp() override { sg::takeFixedFaults(); }
  // All the work below stays far inside the range: no fault may be raised.
  void TearDown() override { EXPECT_EQ(sg::takeFixedFaults(), 0u) << "an in-range Eigen operation raised a fault"; }
};
using FixedTypes = ::testing::Types<Fx32, Fx16>;
TYPED_TEST_SUITE(EigenFixed, FixedTypes);

TYPED_TEST(EigenFixed, ConstructionAndIntegerLiterals) {
  using Fx = TypeParam;
  using V = sg::Vec3<Fx>;
  const V v(Fx(1), Fx(-2), Fx(3));
  // NumTraits::Literal = Fx: integer literals convert exactly through Fx(int).
  const V a = v * 2, b = 2 * v, c = v / 2;
  EXPECT_TRUE(same(a, V(Fx(2), Fx(-4), Fx(6))));
  EXPECT_TRUE(same(b, a));
  EXPECT_TRUE(same(c, V(Fx::fromRaw(Fx::kOneRaw / 2), Fx(-1), Fx::fromRaw(3 * Fx::kOneRaw / 2))));
  EXPECT_TRUE(same(v * Fx(3), V(Fx(3), Fx(-6), Fx(9))));
  EXPECT_TRUE(same(-v, V(Fx(-1), Fx(2), Fx(-3))));
  EXPECT_TRUE(same(v + a - b, v));
  EXPECT_TRUE(same(V::Zero(), V(Fx(0), Fx(0), Fx(0))));
  EXPECT_EQ(V::Ones().sum(), Fx(3));
  EXPECT_TRUE(same(V::UnitY(), V(Fx(0), Fx(1), Fx(0))));
  EXPECT_EQ(v.sum(), Fx(2));
  EXPECT_EQ(v.maxCoeff(), Fx(3));
  EXPECT_EQ(v.minCoeff(), Fx(-2));
  EXPECT_TRUE(same(v.cwiseAbs(), V(Fx(1), Fx(2), Fx(3))));
  const sg::Mat3<Fx> id = sg::Mat3<Fx>::Identity();
  EXPECT_TRUE(same(id * v, v));
  EXPECT_EQ(id.trace(), Fx(3));
  EXPECT_EQ((id * 5).determinant(), Fx(125));
  EXPECT_EQ(sg::Quat<Fx>::Identity().w(), Fx(1));
  EXPECT_TRUE(same(sg::Quat<Fx>::Identity() * v, v));
}

TYPED_TEST(EigenFixed, DotAndCross) {
  using Fx = TypeParam;
  std::mt19937_64 g(1);
  for (int i = 0; i < 20000; ++i) {
    const auto a = randomVec<Fx>(g, 10), b = randomVec<Fx>(g, 10);
    // dot: three rounded products -> <= 1.5 u.
    const long double dot = toLd(a.x()) * toLd(b.x()) + toLd(a.y()) * toLd(b.y()) + toLd(a.z()) * toLd(b.z());
    ASSERT_TRUE(within(a.dot(b), dot, 1.5L)) << "dot, sample " << i;
    // cross: two rounded products per component -> <= 1 u.
    const auto c = a.cross(b);
    const long double cx = toLd(a.y()) * toLd(b.z()) - toLd(a.z()) * toLd(b.y());
    const long double cy = toLd(a.z()) * toLd(b.x()) - toLd(a.x()) * toLd(b.z());
    const long double cz = toLd(a.x()) * toLd(b.y()) - toLd(a.y()) * toLd(b.x());
    ASSERT_TRUE(within(c.x(), cx, 1.0L) && within(c.y(), cy, 1.0L) && within(c.z(), cz, 1.0L)) << "cross " << i;
    // Anti-commutative exactly (same products, negated).
    ASSERT_TRUE(same(b.cross(a), -c));
  }
  // Exact cases.
  using V = sg::Vec3<Fx>;
  EXPECT_TRUE(same(V::UnitX().cross(V::UnitY()), V::UnitZ()));
  EXPECT_EQ(V(Fx(1), Fx(2), Fx(3)).dot(V(Fx(4), Fx(-5), Fx(6))), Fx(12));
}

TYPED_TEST(EigenFixed, NormAndNormalizedAgainstLongDouble) {
  using Fx = TypeParam;
  std::mt19937_64 g(2);
  int checked = 0;
  while (checked < 20000) {
    const auto v = randomVec<Fx>(g, 10);
    const long double n = sqrtl(toLd(v.x()) * toLd(v.x()) + toLd(v.y()) * toLd(v.y()) + toLd(v.z()) * toLd(v.z()));
    if (n < 1) continue;
    ++checked;
    // norm() = sqrt(squaredNorm()): the sum of three rounded squares errs by <= 1.5 u, which
    // moves the root by <= 1.5 u / (2 n) <= 0.75 u / n; the nearest-rounded root adds 0.5 u.
    const long double normTol = 0.5L + 0.75L / n;
    ASSERT_TRUE(within(v.norm(), n, normTol)) << "norm, sample " << checked;
    // sg::length3 rounds once from the exact sum: <= 0.5 u.
    ASSERT_TRUE(within(sg::length3(v.x(), v.y(), v.z()), n, 0.5L)) << "length3, sample " << checked;
    // normalized() = v / norm(): the norm's relative error normTol u / n scales each |v_i / n| <= 1
    // component by at most that, plus 0.5 u for the rounded quotient.
    const auto u = v.normalized();
    const long double compTol = normTol / n + 0.5L;
    for (int k = 0; k < 3; ++k) ASSERT_TRUE(within(u[k], toLd(v[k]) / n, compTol)) << "normalized " << checked;
    // And the unit vector has length 1 within sqrt(3) compTol + 0.5 u (length3 rounding).
    ASSERT_TRUE(within(sg::length3(u.x(), u.y(), u.z()), 1.0L, 1.7321L * compTol + 0.5L)) << checked;
    // normalize() in place is the same computation.
    auto w = v;
    w.normalize();
    ASSERT_TRUE(same(w, u));
  }
  using V = sg::Vec3<Fx>;
  EXPECT_EQ(V(Fx(3), Fx(-4), Fx(0)).norm(), Fx(5));
  EXPECT_TRUE(same(V(Fx(0), Fx(-7), Fx(0)).normalized(), V(Fx(0), Fx(-1), Fx(0))));
  EXPECT_EQ(V(Fx(2), Fx(3), Fx(6)).squaredNorm(), Fx(49));
}

TYPED_TEST(EigenFixed, MatrixProductsAndTranspose) {
  using Fx = TypeParam;
  std::mt19937_64 g(3);
  for (int i = 0; i < 5000; ++i) {
    const auto a = randomMat<Fx>(g, 5), b = randomMat<Fx>(g, 5);
    const auto v = randomVec<Fx>(g, 5);
    const auto av = a * v;
    const sg::Mat3<Fx> ab = a * b;
    const sg::Mat3<Fx> at = a.transpose();
    for (int r = 0; r < 3; ++r) {
      // Each entry: three rounded products -> <= 1.5 u.
      long double want = 0;
      for (int k = 0; k < 3; ++k) want += toLd(a(r, k)) * toLd(v[k]);
      ASSERT_TRUE(within(av[r], want, 1.5L)) << "matrix * vector row " << r << ", sample " << i;
      for (int c = 0; c < 3; ++c) {
        long double w = 0;
        for (int k = 0; k < 3; ++k) w += toLd(a(r, k)) * toLd(b(k, c));
        ASSERT_TRUE(within(ab(r, c), w, 1.5L)) << "matrix * matrix (" << r << "," << c << "), sample " << i;
        ASSERT_EQ(at(r, c), a(c, r));  // transpose is exact
      }
    }
    // (A B)^T == B^T A^T exactly: the same rounded products, summed in the same order.
    ASSERT_TRUE(same(sg::Mat3<Fx>(ab.transpose()), sg::Mat3<Fx>(b.transpose() * a.transpose())));
  }
}

/// Eigen's 3x3 determinant: sum over a of +-m(0,a) * (m(1,b) m(2,c) - m(1,c) m(2,b)). The bracket
/// errs by <= 1 u (two rounded products); multiplying by m(0,a) scales that by |m(0,a)| and rounds
/// once more (0.5 u). Bound: sum_a (|m(0,a)| + 0.5) u.
template <class Fx>
long double detRef(const sg::Mat3<Fx>& m) {
  auto e = [&](int r, int c) { return toLd(m(r, c)); };
  return e(0, 0) * (e(1, 1) * e(2, 2) - e(1, 2) * e(2, 1)) - e(0, 1) * (e(1, 0) * e(2, 2) - e(1, 2) * e(2, 0)) +
         e(0, 2) * (e(1, 0) * e(2, 1) - e(1, 1) * e(2, 0));
}

/// A well-conditioned matrix: diagonal magnitudes in [2, 3], off-diagonal entries in (-1/2, 1/2).
/// Every Gershgorin disc excludes |z| < 1, so every eigenvalue has |lambda| >= 1 and |det| >= 1.
template <class Fx>
sg::Mat3<Fx> wellConditioned(std::mt19937_64& g) {
  sg::Mat3<Fx> m = randomMat<Fx>(g, 0.4999);
  for (int i = 0; i < 3; ++i) {
    const Fx d = Fx(2) + sg::abs(randomFx<Fx>(g, 1));
    m(i, i) = (g() & 1) ? d : -d;
  }
  return m;
}

TYPED_TEST(EigenFixed, Determinant) {
  using Fx = TypeParam;
  std::mt19937_64 g(4);
  for (int i = 0; i < 5000; ++i) {
    const auto m = (i & 1) ? randomMat<Fx>(g, 5) : wellConditioned<Fx>(g);
    long double tol = 0;
    for (int a = 0; a < 3; ++a) tol += fabsl(toLd(m(0, a))) + 0.5L;
    ASSERT_TRUE(within(m.determinant(), detRef(m), tol)) << "sample " << i;
  }
  sg::Mat3<Fx> m;
  m << Fx(2), Fx(0), Fx(1), Fx(1), Fx(3), Fx(0), Fx(0), Fx(1), Fx(4);  // 2*12 - 0 + 1*1 = 25
  EXPECT_EQ(m.determinant(), Fx(25));
}

TYPED_TEST(EigenFixed, InverseOfWellConditionedMatrix) {
  using Fx = TypeParam;
  std::mt19937_64 g(5);
  auto check = [&](const sg::Mat3<Fx>& m, int sample) {
    const sg::Mat3<Fx> inv = m.inverse();
    // Exact cofactors C(i, j) and determinant of the fixed-point input, in long double.
    auto e = [&](int r, int c) { return toLd(m(r, c)); };
    long double cof[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
        cof[i][j] = e(i1, j1) * e(i2, j2) - e(i1, j2) * e(i2, j1);
      }
    const long double det = cof[0][0] * e(0, 0) + cof[1][0] * e(1, 0) + cof[2][0] * e(2, 0);
    // Error bound of Eigen's computation (InverseImpl.h: cofactors, det = sum cof(i,0) m(i,0),
    // invdet = 1 / det, inv(i, j) = cofactor(j, i) * invdet), in ulps:
    //   each cofactor: two rounded products               dc   = 1
    //   det: three products of m(i,0) with a cofactor       ddet = sum |m(i,0)| dc + 3 * 0.5
    //   invdet = round(1 / det~)                              dinv = ddet / (|det| (|det| - ddet u)) + 0.5
    //   inv(i, j) = round(cof~ * invdet~)                     |cof| dinv + |invdet| dc + dc dinv u + 0.5
    long double ddet = 1.5L;
    for (int i = 0; i < 3; ++i) ddet += fabsl(e(i, 0));
    const long double u = ulp<Fx>();
    const long double dinv = ddet / (fabsl(det) * (fabsl(det) - ddet * u)) + 0.5L;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const long double want = cof[j][i] / det;
        const long double tol = fabsl(cof[j][i]) * dinv + 1.0L / fabsl(det) + dinv * u + 0.5L;
        ASSERT_TRUE(within(inv(i, j), want, tol)) << "inverse (" << i << "," << j << "), sample " << sample;
      }
    // A A^-1 is the identity to within isApprox's precision (2^-16 for Q32.32, 2^-8 for Q16.16).
    ASSERT_TRUE((m * inv).isApprox(sg::Mat3<Fx>::Identity())) << "sample " << sample;
  };
  for (int i = 0; i < 5000; ++i) check(wellConditioned<Fx>(g), i);
  sg::Mat3<Fx> m;  // exact binary fractions
  m << Fx(2), Fx(1) / Fx(2), Fx(1) / Fx(4), Fx(1) / Fx(8), Fx(3) / Fx(2), Fx(-1) / Fx(2), Fx(3) / Fx(4), Fx(-1) / Fx(4),
      Fx(3);
  check(m, -1);
  // The inverse of a diagonal matrix of powers of two is exact.
  sg::Mat3<Fx> d = sg::Mat3<Fx>::Zero();
  d(0, 0) = Fx(2);
  d(1, 1) = Fx(-4);
  d(2, 2) = Fx(1) / Fx(2);
  sg::Mat3<Fx> dinv = sg::Mat3<Fx>::Zero();
  dinv(0, 0) = Fx(1) / Fx(2);
  dinv(1, 1) = Fx(-1) / Fx(4);
  dinv(2, 2) = Fx(2);
  EXPECT_TRUE(same(sg::Mat3<Fx>(d.inverse()), dinv));
}

/// Hamilton product in long double from the fixed-point components.
template <class Fx>
void quatRef(const sg::Quat<Fx>& a, const sg::Quat<Fx>& b, long double out[4]) {
  const long double aw = toLd(a.w()), ax = toLd(a.x()), ay = toLd(a.y()), az = toLd(a.z());
  const long double bw = toLd(b.w()), bx = toLd(b.x()), by = toLd(b.y()), bz = toLd(b.z());
  out[0] = aw * bw - ax * bx - ay * by - az * bz;
  out[1] = aw * bx + ax * bw + ay * bz - az * by;
  out[2] = aw * by + ay * bw + az * bx - ax * bz;
  out[3] = aw * bz + az * bw + ax * by - ay * bx;
}

TYPED_TEST(EigenFixed, QuaternionMultiplyAndNormalize) {
  using Fx = TypeParam;
  using Q = sg::Quat<Fx>;
  std::mt19937_64 g(6);
  for (int i = 0; i < 20000; ++i) {
    const Q a(randomFx<Fx>(g, 2), randomFx<Fx>(g, 2), randomFx<Fx>(g, 2), randomFx<Fx>(g, 2));
    const Q b(randomFx<Fx>(g, 2), randomFx<Fx>(g, 2), randomFx<Fx>(g, 2), randomFx<Fx>(g, 2));
    const Q p = a * b;
    long double want[4];
    quatRef(a, b, want);
    // Four rounded products per component: <= 2 u.
    ASSERT_TRUE(within(p.w(), want[0], 2.0L) && within(p.x(), want[1], 2.0L) && within(p.y(), want[2], 2.0L) &&
                within(p.z(), want[3], 2.0L))
        << "product, sample " << i;
    // normalized(): norm from four rounded squares (2 u in the sum -> 1 u / n in the root, plus
    // 0.5 u rounding), then four quotients: component error <= (0.5 + 1/n) / n + 0.5 u.
    const long double n = sqrtl(toLd(a.w()) * toLd(a.w()) + toLd(a.x()) * toLd(a.x()) + toLd(a.y()) * toLd(a.y()) +
                                toLd(a.z()) * toLd(a.z()));
    if (n < 1) continue;
    const long double tol = (0.5L + 1.0L / n) / n + 0.5L;
    const Q an = a.normalized();
    ASSERT_TRUE(within(an.w(), toLd(a.w()) / n, tol) && within(an.x(), toLd(a.x()) / n, tol) &&
                within(an.y(), toLd(a.y()) / n, tol) && within(an.z(), toLd(a.z()) / n, tol))
        << "normalized, sample " << i;
    Q a2 = a;
    a2.normalize();
    ASSERT_TRUE(same(a2.coeffs(), an.coeffs()));
    ASSERT_TRUE(within(an.norm(), 1.0L, 2.0L * tol + 1.5L)) << "sample " << i;
  }
  // Exact cases: i * j = k, j * i = -k, i * i = -1.
  const Q qi(Fx(0), Fx(1), Fx(0), Fx(0)), qj(Fx(0), Fx(0), Fx(1), Fx(0)), qk(Fx(0), Fx(0), Fx(0), Fx(1));
  EXPECT_TRUE(same((qi * qj).coeffs(), qk.coeffs()));
  EXPECT_TRUE(same((qj * qi).coeffs(), (-qk.coeffs()).eval()));
  EXPECT_TRUE(same((qi * qi).coeffs(), Q(Fx(-1), Fx(0), Fx(0), Fx(0)).coeffs()));
  // q * conj(q) = |q|^2 for a nearly-unit q: 4 products in w, the vector part cancels exactly.
  const Q q = randomUnitQuat<Fx>(g);
  const Q qq = q * q.conjugate();
  EXPECT_TRUE(same(qq.vec(), sg::Vec3<Fx>::Zero()));
  // w = sum of four rounded squares (<= 2 u) of components within u/2 of a unit quaternion
  // (|q|^2 - 1 <= sum |q_i| u <= 2 u): <= 4 u from 1.
  EXPECT_TRUE(within(qq.w(), 1.0L, 4.0L));
}

/// The 90 degree rotation about z from exact components w = z = sqrt(1/2) (nearest-rounded).
/// s = round(sqrt(1/2)) satisfies s^2 = 1/2 + d with |d| < 0.1 u (Q32.32: 3037000500^2 / 2^64
/// - 1/2 = 0.034 u; Q16.16: 46341^2 / 2^32 - 1/2 = 0.071 u), so the products s s, 2s s and
/// 4s s that Eigen forms round to exactly 1/2, 1 and 2: the matrix and the rotated vector are exact.
TYPED_TEST(EigenFixed, NinetyDegreeRotationIsExact) {
  using Fx = TypeParam;
  using V = sg::Vec3<Fx>;
  const Fx s = sg::sqrt(Fx(1) / Fx(2));
  ASSERT_EQ(int64_t(s.raw()), Fx::kFracBits == 32 ? int64_t(3037000500) : int64_t(46341));
  const sg::Quat<Fx> q(s, Fx(0), Fx(0), s);
  sg::Mat3<Fx> want;
  want << Fx(0), Fx(-1), Fx(0), Fx(1), Fx(0), Fx(0), Fx(0), Fx(0), Fx(1);
  const sg::Mat3<Fx> r = q.toRotationMatrix();
  EXPECT_TRUE(same(r, want));
  const V v(Fx(1), Fx(2), Fx(3));
  EXPECT_TRUE(same(V(q * v), V(Fx(-2), Fx(1), Fx(3))));
  EXPECT_TRUE(same(V(r * v), V(Fx(-2), Fx(1), Fx(3))));
  EXPECT_TRUE(same(V(q * V::UnitX()), V::UnitY()));
  // Twice is 180 degrees: (s, 0, 0, s)^2 = (2 s^2 - ... ) = (0, 0, 0, 1) exactly.
  const sg::Quat<Fx> q2 = q * q;
  EXPECT_TRUE(same(q2.coeffs(), sg::Quat<Fx>(Fx(0), Fx(0), Fx(0), Fx(1)).coeffs()));
  EXPECT_TRUE(same(V(q2 * v), V(Fx(-1), Fx(-2), Fx(3))));
  EXPECT_TRUE(same(sg::Mat3<Fx>(q.conjugate().toRotationMatrix()), sg::Mat3<Fx>(want.transpose())));
}

/// Rotation matrix of Eigen's formula (R = (1 - 2|u|^2) I + 2 u u^T + 2 w [u]x, valid for any
/// quaternion, unit or not) in long double from the fixed-point components.
template <class Fx>
void rotRef(const sg::Quat<Fx>& q, long double r[3][3]) {
  const long double w = toLd(q.w()), x = toLd(q.x()), y = toLd(q.y()), z = toLd(q.z());
  r[0][0] = 1 - 2 * (y * y + z * z);
  r[0][1] = 2 * (x * y - w * z);
  r[0][2] = 2 * (x * z + w * y);
  r[1][0] = 2 * (x * y + w * z);
  r[1][1] = 1 - 2 * (x * x + z * z);
  r[1][2] = 2 * (y * z - w * x);
  r[2][0] = 2 * (x * z - w * y);
  r[2][1] = 2 * (y * z + w * x);
  r[2][2] = 1 - 2 * (x * x + y * y);
}

TYPED_TEST(EigenFixed, RotationMatrixAndVectorRotation) {
  using Fx = TypeParam;
  using V = sg::Vec3<Fx>;
  std::mt19937_64 g(7);
  for (int i = 0; i < 20000; ++i) {
    const sg::Quat<Fx> q = randomUnitQuat<Fx>(g);
    long double ref[3][3];
    rotRef(q, ref);
    // Eigen: tx = 2x (exact), then every entry is 1 - (t_a a + t_b b) or t_a b +- t_c w: two
    // rounded products -> <= 1 u.
    const sg::Mat3<Fx> r = q.toRotationMatrix();
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) ASSERT_TRUE(within(r(a, b), ref[a][b], 1.0L)) << "R(" << a << "," << b << ") " << i;
    // q * v (Eigen: uv = u x v; uv += uv; v + w uv + u x uv): u x v <= 1 u, doubled 2 u;
    // w uv <= 2 |w| + 0.5 u; u x uv <= (|u_a| + |u_b|) 2 + 1 u; |w| <= 1 and |u_a| + |u_b| <= sqrt 2
    // for a unit quaternion: <= 2 + 0.5 + 2.83 + 1 = 6.33 u, independent of |v|.
    const V v = randomVec<Fx>(g, 10);
    const V rv = q * v;
    for (int a = 0; a < 3; ++a) {
      long double want = 0;
      for (int b = 0; b < 3; ++b) want += ref[a][b] * toLd(v[b]);
      ASSERT_TRUE(within(rv[a], want, 6.34L)) << "q * v [" << a << "], sample " << i;
    }
    // The rotation keeps the length: |q v| vs |v| differ by the rounding error above (<= sqrt 3
    // * 6.34 u), the length3 rounding (0.5 u), and the non-unit quaternion: |q|^2 = 1 + e with
    // |e| <= sum |q_i| u/2 * 2 <= 2 u, and Eigen's formula is R = |q|^2 Rot + (1 - |q|^2) I (it
    // writes 1 - 2|u|^2 for w^2 - |u|^2), so |R v| is within 2 |e| |v| <= 4 u |v| of |v|.
    const long double lenV = sqrtl(toLd(v.x()) * toLd(v.x()) + toLd(v.y()) * toLd(v.y()) + toLd(v.z()) * toLd(v.z()));
    ASSERT_TRUE(within(sg::length3(rv.x(), rv.y(), rv.z()), lenV, 1.7321L * 6.34L + 0.5L + 4.0L * lenV)) << i;
  }
}

TYPED_TEST(EigenFixed, IsApproxUsesANonZeroPrecision) {
  using Fx = TypeParam;
  using V = sg::Vec3<Fx>;
  using NT = Eigen::NumTraits<Fx>;
  // dummy_precision is 2^(F/2) ulps: 2^-16 (Q32.32), 2^-8 (Q16.16) -- the default would be 0.
  EXPECT_EQ(int64_t(NT::dummy_precision().raw()), int64_t(1) << (Fx::kFracBits / 2));
  EXPECT_GT(NT::dummy_precision(), Fx(0));
  EXPECT_EQ(NT::epsilon(), Fx::epsilon());
  EXPECT_EQ(NT::highest(), Fx::max());
  EXPECT_EQ(NT::lowest(), Fx::min());
  const V v(Fx(1), Fx(2), Fx(3));
  const V near = v + V(Fx::epsilon(), -Fx::epsilon(), Fx(0));  // one ulp: far below 2^(F/2) ulps
  const V far = v * (Fx(1) + Fx(1) / Fx(100));                 // 1 % off: far above 2^-8
  EXPECT_TRUE(v.isApprox(v));
  EXPECT_TRUE(v.isApprox(near));
  EXPECT_TRUE(near.isApprox(v));
  EXPECT_FALSE(v.isApprox(far));
  EXPECT_FALSE(v.isApprox(-v));
  // Relative precision: 0.2 * dummy_precision relative is approx, 4 * dummy_precision is not.
  const Fx p = NT::dummy_precision();
  const V close = v * (Fx(1) + p / Fx(5));
  const V off = v * (Fx(1) + p * Fx(4));
  EXPECT_TRUE(v.isApprox(close));
  EXPECT_FALSE(v.isApprox(off));
  EXPECT_TRUE(V(Fx::epsilon(), Fx(0), Fx(0)).isZero());
  EXPECT_FALSE(V(Fx(1) / Fx(10), Fx(0), Fx(0)).isZero());
  EXPECT_TRUE(Eigen::internal::isApprox(Fx(7), Fx(7) + Fx::epsilon()));
  EXPECT_FALSE(Eigen::internal::isApprox(Fx(7), Fx(7) + Fx(1) / Fx(10)));
  EXPECT_TRUE(sg::Quat<Fx>::Identity().isApprox(sg::Quat<Fx>(Fx(1), Fx::epsilon(), Fx(0), Fx(0))));
  EXPECT_FALSE(sg::Quat<Fx>::Identity().isApprox(sg::Quat<Fx>(Fx(1), Fx(1) / Fx(10), Fx(0), Fx(0))));
}

}  // namespace
