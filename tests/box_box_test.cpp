// Box-box narrow phase (sim/collision/box_box.h): hand-built configurations with known answers,
// their mirror (A and B swapped), agreement of the four scalars, determinism, and a fuzz loop
// against a double-precision separating-axis test.
//
// Tolerances. Every check on a length uses tol(S, M) = K * u * max(M, 1 m), with u the unit in
// the last place at 1 (2^-32 fx32, 2^-16 fx16, 2^-23 float, 2^-52 double) and M the magnitude
// that sets the rounding (m): the lever arm (box size) for fixed point, whose products round to
// u/2 in absolute terms and whose differences of positions are exact; lever arm plus the world
// coordinates for float and double, which round relative to the value. A rotation entry carries
// u/2 from its conversion, so a point at lever arm M errs by about u * M per rounded step; the
// longest chain (relative pose, clip interpolation, midpoint, back to world) has about a dozen
// rounded steps, so K = 64 leaves a factor of ~4 of slack. (Measured on the named
// configurations: at most 4 u against double, for a bound of 256 u.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "sim/collision/box_box.h"
#include "sim/math/scalar.h"

namespace sg {
namespace {

using Eigen::Matrix3d;
using Eigen::Quaterniond;
using Eigen::Vector3d;

// ---- conversions ---------------------------------------------------------------------------

template <class S>
S toS(double v) {
  if constexpr (ScalarTraits<S>::isFixed) {
    return S::fromDouble(v);
  } else {
    return S(v);
  }
}
template <class S>
double toD(S v) {
  return ScalarTraits<S>::toDouble(v);
}
template <class S>
Vector3d toD(const Vec3<S>& v) {
  return Vector3d(toD(v.x()), toD(v.y()), toD(v.z()));
}

template <class S>
double ulpAtOne() {
  switch (ScalarTraits<S>::kind) {
    case ScalarKind::Fx32:
      return std::ldexp(1.0, -32);
    case ScalarKind::Fx16:
      return std::ldexp(1.0, -16);
    case ScalarKind::Float:
      return std::ldexp(1.0, -23);
    case ScalarKind::Double:
      break;
  }
  return std::ldexp(1.0, -52);
}
/// Length tolerance for lengths built from lever arms up to `lever` (m) at world coordinates up
/// to `pos` (m); see the header comment. Fixed point subtracts positions exactly, so only the
/// lever arm counts there; float and double round relative to the coordinate itself.
template <class S>
double tol(double lever, double pos = 0) {
  const double m = ScalarTraits<S>::isFixed ? lever : lever + pos;
  return 64.0 * ulpAtOne<S>() * std::max(m, 1.0);
}

/// A box as the test describes it, in double: rotation from a quaternion (normalised here).
struct BoxD {
  Vector3d half;
  Vector3d pos;
  Quaterniond q = Quaterniond::Identity();
};
struct Config {
  std::string name;
  BoxD a, b;
};

Quaterniond about(const Vector3d& axis, double degrees) {
  return Quaterniond(Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, axis.normalized()));
}

template <class S>
Vec3<S> vecS(const Vector3d& v) {
  return Vec3<S>(toS<S>(v.x()), toS<S>(v.y()), toS<S>(v.z()));
}
template <class S>
Pose<S> poseS(const BoxD& box) {
  Pose<S> p;
  p.position = vecS<S>(box.pos);
  const Matrix3d r = box.q.normalized().toRotationMatrix();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) p.rotation(i, j) = toS<S>(r(i, j));
  return p;
}

/// The box exactly as S sees it (converted inputs), in double: the reference for checks.
struct BoxM {
  Vector3d h, c;
  Matrix3d R;
};
template <class S>
BoxM quantised(const BoxD& box) {
  const Pose<S> p = poseS<S>(box);
  BoxM m;
  m.h = toD(vecS<S>(box.half));
  m.c = toD(p.position);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m.R(i, j) = toD(p.rotation(i, j));
  return m;
}

struct ContactD {
  int32_t bodyA, bodyB;
  uint32_t featureA, featureB;
  Vector3d point, normal;
  double pen;
};

template <class S>
std::vector<ContactD> collide(const BoxD& a, const BoxD& b, int* count = nullptr) {
  std::vector<Contact<S>> out;
  const int n = collideBoxBox<S>(7, vecS<S>(a.half), poseS<S>(a), 9, vecS<S>(b.half), poseS<S>(b), out);
  if (count) *count = n;
  std::vector<ContactD> r;
  for (const auto& c : out)
    r.push_back({c.bodyA, c.bodyB, c.featureA, c.featureB, toD(c.point), toD(c.normal), toD(c.penetration)});
  return r;
}
template <class S>
std::vector<ContactD> collide(const Config& c) {
  return collide<S>(c.a, c.b);
}

void sortByFeatures(std::vector<ContactD>& cs) {
  std::sort(cs.begin(), cs.end(), [](const ContactD& x, const ContactD& y) {
    return x.featureA != y.featureA ? x.featureA < y.featureA : x.featureB < y.featureB;
  });
}

// ---- double-precision reference geometry -----------------------------------------------------

/// Overlap of the two boxes along a unit axis (m; negative = separated by that much).
double overlapAlong(const BoxM& A, const BoxM& B, const Vector3d& axis) {
  double rA = 0, rB = 0;
  for (int k = 0; k < 3; ++k) {
    rA += A.h[k] * std::abs(A.R.col(k).dot(axis));
    rB += B.h[k] * std::abs(B.R.col(k).dot(axis));
  }
  return rA + rB - std::abs((B.c - A.c).dot(axis));
}

/// Separating-axis test in double: the overlap along each of the 15 axes (edge pairs with
/// |a_i x b_j| < 1e-9 get +inf: they cannot separate).
std::vector<double> axisOverlaps(const BoxM& A, const BoxM& B) {
  std::vector<double> o;
  for (int i = 0; i < 3; ++i) o.push_back(overlapAlong(A, B, A.R.col(i).normalized()));
  for (int j = 0; j < 3; ++j) o.push_back(overlapAlong(A, B, B.R.col(j).normalized()));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const Vector3d L = A.R.col(i).cross(B.R.col(j));
      o.push_back(L.norm() < 1e-9 ? HUGE_VAL : overlapAlong(A, B, L / L.norm()));
    }
  return o;
}
double minOverlap(const BoxM& A, const BoxM& B) {
  const auto o = axisOverlaps(A, B);
  return *std::min_element(o.begin(), o.end());
}

/// How far p lies outside the box (0 inside), measured per axis in the box frame (m).
double outside(const BoxM& box, const Vector3d& p) {
  const Vector3d local = box.R.transpose() * (p - box.c);
  double d = 0;
  for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(local[k]) - box.h[k]);
  return d;
}

// ---- configurations ---------------------------------------------------------------------------

const double kR2 = std::numbers::sqrt2;

/// A small box lying face down on a big one, axis aligned; overlap 1/8 m. Every number is a
/// dyadic rational, exact in all four scalars.
Config restingAxisAligned() { return {"resting", {{0.5, 0.25, 0.5}, {0.25, 1.125, -0.125}}, {{2, 1, 2}, {0, 0, 0}}}; }
/// The same box turned 45 degrees about y (its corners point along x and z in plan view).
Config restingTurned45() {
  return {"turned45", {{0.5, 0.25, 0.5}, {0.25, 1.125, -0.125}, about(Vector3d::UnitY(), 45)}, {{2, 1, 2}, {0, 0, 0}}};
}
/// Equal footprints, one turned 45 degrees about y: the overlap in plan view is an octagon.
Config octagon() {
  return {"octagon", {{1, 0.25, 1}, {0, 1.125, 0}, about(Vector3d::UnitY(), 45)}, {{1, 1, 1}, {0, 0, 0}}};
}
/// A cube balanced on its edge (turned 45 degrees about z) on a flat box, sunk 0.05 m.
Config onEdge() {
  return {"onEdge",
          {{0.5, 0.5, 0.5}, {0.1, 1 + 0.5 * kR2 - 0.05, 0.2}, about(Vector3d::UnitZ(), 45)},
          {{2, 1, 2}, {0, 0, 0}}};
}
/// Crossed edges: A turned 45 degrees about x (lowest edge along x), B turned 45 degrees about z
/// (highest edge along z); the edges cross at (0, sqrt2 - 0.05, 0.2), overlap 0.1.
Config crossed() {
  return {"crossed",
          {{1, 1, 1}, {0.3, 2 * kR2 - 0.1, 0.2}, about(Vector3d::UnitX(), 45)},
          {{1, 1, 1}, {0, 0, 0}, about(Vector3d::UnitZ(), 45)}};
}
/// Crossed edges at 60 degrees: B's top edge is turned 30 degrees about y as well.
Config crossedSkew() {
  return {"crossedSkew",
          {{1, 1, 1}, {0.3, 2 * kR2 - 0.1, 0.2}, about(Vector3d::UnitX(), 45)},
          {{1, 1, 1}, {0, 0, 0}, about(Vector3d::UnitY(), 30) * about(Vector3d::UnitZ(), 45)}};
}
std::vector<Config> touchingConfigs() {
  return {restingAxisAligned(), restingTurned45(), octagon(), onEdge(), crossed(), crossedSkew()};
}

Config swapped(const Config& c) { return {c.name + "/swapped", c.b, c.a}; }

// ---- typed suite over the four scalars ---------------------------------------------------------

template <class S>
class BoxBoxTyped : public ::testing::Test {};
using Scalars = ::testing::Types<Fx32, Fx16, float, double>;
TYPED_TEST_SUITE(BoxBoxTyped, Scalars);

TYPED_TEST(BoxBoxTyped, SeparatedBoxesGiveNoContacts) {
  using S = TypeParam;
  const BoxD unit{{1, 1, 1}, {0, 0, 0}};
  std::vector<Config> cases = {
      {"x", unit, {{1, 1, 1}, {2.01, 0, 0}}},
      {"y", unit, {{1, 0.5, 1}, {0.3, -1.51, 0.2}}},
      {"z", unit, {{0.5, 0.5, 0.5}, {0.5, 0.5, 1.7}, about(Vector3d::UnitX(), 20)}},
      // Only B's face x separates (and the edge pairs parallel to it): A is turned 45 degrees
      // about z, its own faces overlap B.
      {"faceB", {{1, 1, 1}, {0, 0, 0}, about(Vector3d::UnitZ(), 45)}, {{1, 1, 1}, {2.5, 0, 0}}},
      // Only the edge pair separates: crossed() lifted by 0.2 (gap 0.1).
      {"edge",
       {{1, 1, 1}, {0.3, 2 * kR2 + 0.1, 0.2}, about(Vector3d::UnitX(), 45)},
       {{1, 1, 1}, {0, 0, 0}, about(Vector3d::UnitZ(), 45)}},
      {"far", unit, {{1, 1, 1}, {50, -40, 30}, about(Vector3d(1, 2, 3), 33)}},
  };
  for (const Config& c : cases) {
    const BoxM A = quantised<S>(c.a), B = quantised<S>(c.b);
    const auto o = axisOverlaps(A, B);
    if (c.name == "faceB") {
      for (int k = 0; k < 3; ++k) ASSERT_GT(o[size_t(k)], 0.1) << "A's face axes must not separate";
      ASSERT_LT(o[3], -0.05);
    }
    if (c.name == "edge") {
      for (int k = 0; k < 6; ++k) ASSERT_GT(o[size_t(k)], 0.1) << "no face axis may separate";
      ASSERT_NEAR(minOverlap(A, B), -0.1, 1e-3);
    }
    EXPECT_EQ(collide<S>(c).size(), 0u) << c.name;
    EXPECT_EQ(collide<S>(swapped(c)).size(), 0u) << c.name;
  }
  EXPECT_EQ(takeFixedFaults(), 0u);
}

TYPED_TEST(BoxBoxTyped, RestingFaceDownGivesFourCornersExactly) {
  using S = TypeParam;
  const Config c = restingAxisAligned();
  int n = -1;
  std::vector<ContactD> cs = collide<S>(c.a, c.b, &n);
  ASSERT_EQ(n, 4);
  ASSERT_EQ(cs.size(), 4u);
  sortByFeatures(cs);
  std::vector<Vector3d> corners;
  for (const ContactD& k : cs) {
    EXPECT_EQ(k.bodyA, 7);
    EXPECT_EQ(k.bodyB, 9);
    // Dyadic inputs, identity rotations: every step is exact in every scalar.
    EXPECT_EQ(k.normal, Vector3d(0, 1, 0));
    EXPECT_EQ(k.pen, 0.125);
    EXPECT_EQ(k.point.y(), 0.9375);                      // halfway between A's bottom (0.875) and B's top (1)
    EXPECT_EQ(k.featureA, 3u);                           // A's -y face is the reference (tie with B's +y: A wins)
    EXPECT_EQ(k.featureB / kBoxIncidentFaceStride, 2u);  // B's +y face is incident
    corners.push_back(k.point);
  }
  for (double x : {-0.25, 0.75})
    for (double z : {-0.625, 0.375})
      EXPECT_NE(std::find(corners.begin(), corners.end(), Vector3d(x, 0.9375, z)), corners.end()) << x << " " << z;
  if constexpr (std::is_same_v<S, Fx32>) {
    // Exact on the raw values too.
    std::vector<Contact<S>> out;
    collideBoxBox<S>(0, vecS<S>(c.a.half), poseS<S>(c.a), 1, vecS<S>(c.b.half), poseS<S>(c.b), out);
    for (const auto& k : out) {
      EXPECT_EQ(k.penetration, S(1) / S(8));
      EXPECT_EQ(k.normal, Vec3<S>::UnitY());
    }
  }
}

/// Common checks of a touching configuration: count, normal, penetration of every contact.
template <class S>
void expectContacts(const Config& c, size_t count, const Vector3d& normal, double pen) {
  const auto cs = collide<S>(c);
  ASSERT_EQ(cs.size(), count) << c.name;
  const double t = tol<S>(4);
  for (const ContactD& k : cs) {
    EXPECT_NEAR((k.normal - normal).norm(), 0, t) << c.name;
    EXPECT_NEAR(k.pen, pen, t) << c.name;
  }
}

TYPED_TEST(BoxBoxTyped, TurnedAboutYStillRestsOnItsFace) {
  using S = TypeParam;
  expectContacts<S>(restingTurned45(), 4, {0, 1, 0}, 0.125);
  // Octagon: eight points, each on one side of both squares, at the same height.
  const Config c = octagon();
  expectContacts<S>(c, 8, {0, 1, 0}, 0.125);
  const double t = tol<S>(4);
  const double r = kR2 - 1;  // the octagon's vertices lie at (+-1, +-(sqrt2 - 1)) and swapped
  for (const ContactD& k : collide<S>(c)) {
    EXPECT_NEAR(k.point.y(), 0.9375, t);
    const double ax = std::abs(k.point.x()), az = std::abs(k.point.z());
    EXPECT_NEAR(std::max(ax, az), 1.0, t);
    EXPECT_NEAR(std::min(ax, az), r, t);
  }
}

TYPED_TEST(BoxBoxTyped, CubeOnItsEdgeGivesTwoContactsAlongTheEdge) {
  using S = TypeParam;
  const Config c = onEdge();
  expectContacts<S>(c, 2, {0, 1, 0}, 0.05);
  const double t = tol<S>(4);
  std::vector<ContactD> cs = collide<S>(c);
  for (const ContactD& k : cs) {
    EXPECT_EQ(k.featureB, 2u);  // B's +y face is the reference
    EXPECT_NEAR(k.point.x(), 0.1, t);
    EXPECT_NEAR(k.point.y(), 1 - 0.025, t);
    EXPECT_NEAR(std::abs(k.point.z() - 0.2), 0.5, t);
  }
  ASSERT_EQ(cs.size(), 2u);
  EXPECT_NEAR(std::abs(cs[0].point.z() - cs[1].point.z()), 1.0, t);
}

TYPED_TEST(BoxBoxTyped, CrossedEdgesGiveOneEdgeContact) {
  using S = TypeParam;
  // Perpendicular edges: a_x x b_z = -y, oriented from B (below) to A: +y.
  {
    const Config c = crossed();
    expectContacts<S>(c, 1, {0, 1, 0}, 0.1);
    const ContactD k = collide<S>(c)[0];
    EXPECT_GE(k.featureA, kBoxEdgeFeature);
    EXPECT_GE(k.featureB, kBoxEdgeFeature);
    EXPECT_EQ(k.featureA, kBoxEdgeFeature + 2);         // A's edge along x (axis 0) at local -y, +z (code 2)
    EXPECT_EQ((k.featureB - kBoxEdgeFeature) / 4, 2u);  // B's edge along its z axis
    EXPECT_NEAR((k.point - Vector3d(0, kR2 - 0.05, 0.2)).norm(), 0, tol<S>(4));
  }
  // Edges at 60 degrees: B's top edge runs along (sin 30, 0, cos 30) through (0, sqrt2, 0); A's
  // bottom edge along x through (., 2 sqrt2 - 0.1 - sqrt2, 0.2). The normal is still +y.
  {
    const Config c = crossedSkew();
    expectContacts<S>(c, 1, {0, 1, 0}, 0.1);
    const ContactD k = collide<S>(c)[0];
    const double u = 0.2 / std::cos(std::numbers::pi / 6);
    EXPECT_NEAR((k.point - Vector3d(0.5 * u, kR2 - 0.05, 0.2)).norm(), 0, tol<S>(4));
  }
}

TYPED_TEST(BoxBoxTyped, SwappingBoxesFlipsTheNormalOnly) {
  using S = TypeParam;
  const double t = tol<S>(4);
  for (const Config& c : touchingConfigs()) {
    const auto ab = collide<S>(c);
    const auto ba = collide<S>(swapped(c));
    ASSERT_EQ(ab.size(), ba.size()) << c.name;
    for (const ContactD& k : ab) {
      // The same point (halfway between the surfaces either way), flipped normal, same depth.
      auto it = std::min_element(ba.begin(), ba.end(), [&](const ContactD& x, const ContactD& y) {
        return (x.point - k.point).norm() < (y.point - k.point).norm();
      });
      EXPECT_NEAR((it->point - k.point).norm(), 0, t) << c.name;
      EXPECT_NEAR((it->normal + k.normal).norm(), 0, t) << c.name;
      EXPECT_NEAR(it->pen, k.pen, t) << c.name;
      EXPECT_EQ(it->bodyA, 7);
      EXPECT_EQ(it->bodyB, 9);
    }
  }
}

TYPED_TEST(BoxBoxTyped, AgreesWithDoubleWithinTolerance) {
  using S = TypeParam;
  const double t = tol<S>(4) + tol<double>(4);
  for (const Config& base : touchingConfigs())
    for (const Config& c : {base, swapped(base)}) {
      auto got = collide<S>(c);
      auto want = collide<double>(c);
      ASSERT_EQ(got.size(), want.size()) << c.name;
      sortByFeatures(got);
      sortByFeatures(want);
      for (size_t k = 0; k < got.size(); ++k) {
        EXPECT_EQ(got[k].featureA, want[k].featureA) << c.name;
        EXPECT_EQ(got[k].featureB, want[k].featureB) << c.name;
        EXPECT_NEAR((got[k].point - want[k].point).norm(), 0, t) << c.name;
        EXPECT_NEAR((got[k].normal - want[k].normal).norm(), 0, t) << c.name;
        EXPECT_NEAR(got[k].pen, want[k].pen, t) << c.name;
      }
    }
}

TYPED_TEST(BoxBoxTyped, ContactPointsLieInBothBoxesExpandedByThePenetration) {
  using S = TypeParam;
  for (const Config& base : touchingConfigs())
    for (const Config& c : {base, swapped(base)}) {
      const BoxM A = quantised<S>(c.a), B = quantised<S>(c.b);
      for (const ContactD& k : collide<S>(c)) {
        EXPECT_LE(outside(A, k.point), k.pen + tol<S>(4)) << c.name;
        EXPECT_LE(outside(B, k.point), k.pen + tol<S>(4)) << c.name;
      }
    }
}

TYPED_TEST(BoxBoxTyped, DeterministicAndAppending) {
  using S = TypeParam;
  using Bits = typename ScalarTraits<S>::Bits;
  auto bits = [](const std::vector<Contact<S>>& cs) {
    std::vector<Bits> r;
    for (const auto& c : cs) {
      r.push_back(Bits(c.bodyA));
      r.push_back(Bits(c.bodyB));
      r.push_back(Bits(c.featureA));
      r.push_back(Bits(c.featureB));
      for (int k = 0; k < 3; ++k) r.push_back(ScalarTraits<S>::bits(c.point[k]));
      for (int k = 0; k < 3; ++k) r.push_back(ScalarTraits<S>::bits(c.normal[k]));
      r.push_back(ScalarTraits<S>::bits(c.penetration));
    }
    return r;
  };
  for (const Config& c : touchingConfigs()) {
    const auto ha = vecS<S>(c.a.half), hb = vecS<S>(c.b.half);
    const auto pa = poseS<S>(c.a), pb = poseS<S>(c.b);
    std::vector<Contact<S>> first, second(3);  // the second call appends after three entries
    const int n1 = collideBoxBox<S>(1, ha, pa, 2, hb, pb, first);
    const int n2 = collideBoxBox<S>(1, ha, pa, 2, hb, pb, second);
    ASSERT_EQ(n1, n2);
    ASSERT_EQ(second.size(), size_t(n2) + 3);
    second.erase(second.begin(), second.begin() + 3);
    EXPECT_EQ(bits(first), bits(second)) << c.name;
    // Canonical keys: no two contacts of one call share (featureA, featureB).
    for (size_t x = 0; x < first.size(); ++x)
      for (size_t y = x + 1; y < first.size(); ++y)
        EXPECT_FALSE(first[x].featureA == first[y].featureA && first[x].featureB == first[y].featureB) << c.name;
  }
}

TYPED_TEST(BoxBoxTyped, DegenerateCasesStayFinite) {
  using S = TypeParam;
  const double rangeP = ScalarTraits<S>::kind == ScalarKind::Fx16 ? 100 : 1000;
  std::vector<Config> cases = {
      {"sameBox", {{1, 1, 1}, {0, 0, 0}}, {{1, 1, 1}, {0, 0, 0}}},
      {"sameCentreTurned",
       {{1, 0.5, 0.25}, {3, 2, 1}, about(Vector3d(1, 1, 0), 30)},
       {{0.5, 2, 1}, {3, 2, 1}, about(Vector3d(0, 1, 1), 70)}},
      // Both turned 45 degrees about z, A's lowest edge sunk 0.1 into B's highest: parallel edges.
      {"parallelEdges",
       {{1, 1, 1}, {0, 2 * kR2 - 0.1, 0}, about(Vector3d::UnitZ(), 45)},
       {{1, 1, 1}, {0, 0, 0}, about(Vector3d::UnitZ(), 45)}},
      {"edgeOnEdge",
       {{1, 1, 1}, {0, 2 * kR2 - 0.01, 0}, about(Vector3d::UnitZ(), 45)},
       {{1, 1, 1}, {0, 0, 0}, about(Vector3d::UnitZ(), 45)}},
      {"cornerOnCorner", {{1, 1, 1}, {1.99, 1.99, 1.99}}, {{1, 1, 1}, {0, 0, 0}}},
      {"tinyOnHuge",
       {{0.005, 0.005, 0.005}, {rangeP - 1, 50.004, rangeP - 1}, about(Vector3d(1, 3, 2), 10)},
       {{50, 50, 50}, {rangeP - 1, 0, rangeP - 1}}},
      {"hugeOnHuge",
       {{50, 50, 50}, {-rangeP, 99.5, -rangeP}, about(Vector3d(1, 1, 1), 1)},
       {{50, 50, 50}, {-rangeP, 0, -rangeP}}},
      {"almostParallel", {{1, 1, 1}, {0, 1.99, 0}, about(Vector3d(1, 0, 1), 1e-4)}, {{1, 1, 1}, {0, 0, 0}}},
  };
  for (const Config& base : cases)
    for (const Config& c : {base, swapped(base)}) {
      takeFixedFaults();
      const auto cs = collide<S>(c);
      EXPECT_EQ(takeFixedFaults(), 0u) << c.name;
      EXPECT_GE(cs.size(), 1u) << c.name;
      EXPECT_LE(cs.size(), 8u) << c.name;
      for (const ContactD& k : cs) {
        EXPECT_TRUE(k.point.allFinite() && k.normal.allFinite() && std::isfinite(k.pen)) << c.name;
        EXPECT_NEAR(k.normal.norm(), 1, tol<S>(1)) << c.name;
        EXPECT_GE(k.pen, 0) << c.name;
      }
    }
  // Exact expectations where they are obvious.
  const auto same = collide<S>(cases[0]);
  ASSERT_EQ(same.size(), 4u);
  for (const ContactD& k : same) {
    EXPECT_EQ(k.pen, 2.0);
    EXPECT_EQ(k.normal, Vector3d(-1, 0, 0));  // A's +x face (coincident centres: + side) is the reference
  }
  const auto parallel = collide<S>(cases[2]);
  // In the plane normal to the edges it is two squares corner to corner: the least overlap is
  // along a face normal at 45 degrees, 0.1 * cos 45.
  ASSERT_FALSE(parallel.empty());
  for (const ContactD& k : parallel) EXPECT_NEAR(k.pen, 0.1 / kR2, tol<S>(4));
}

// ---- fuzz: random poses against the double-precision test ------------------------------------

/// The implementation's rounding margin (box_box.h: 16 units in the last place of a rotation
/// entry times the sum of the half extents plus 1 m); unnormalised on an edge axis.
template <class S>
double edgeMargin(const BoxM& A, const BoxM& B) {
  return 16 * ulpAtOne<S>() * (A.h.sum() + B.h.sum() + 1);
}
/// Edge pairs closer to parallel than this never give contacts (box_box.h).
template <class S>
double edgeMinSin() {
  return ScalarTraits<S>::kind == ScalarKind::Fx16 ? 1.0 / 16 : 1.0 / 1024;
}

constexpr int kFuzzSamples = 4000;

struct FuzzStats {
  int overlapping = 0, separated = 0, banded = 0, edge = 0, maxCount = 0;
};

template <class S>
FuzzStats fuzz(int samples, uint32_t seed) {
  const double rangeP = ScalarTraits<S>::kind == ScalarKind::Fx16 ? 100 : 1000;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u01(0, 1), sym(-1, 1);
  // One draw per statement: the order of evaluation of function arguments is unspecified (GCC
  // and Clang differ), and the samples must not depend on the compiler.
  auto logUniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, u01(rng)); };
  auto vec3 = [&](auto&& draw) {
    Vector3d v;
    for (int k = 0; k < 3; ++k) v[k] = draw();
    return v;
  };
  auto symmetric = [&] { return sym(rng); };
  auto rotation = [&] {
    Eigen::Vector4d c;
    for (int k = 0; k < 4; ++k) c[k] = sym(rng);
    Quaterniond q(c[0], c[1], c[2], c[3]);
    if (q.norm() < 1e-3) q = Quaterniond::Identity();
    return q.normalized();
  };
  FuzzStats st;
  for (int s = 0; s < samples; ++s) {
    // Sizes 0.01..100 m (half extents 0.005..50), B within a factor 10 of A; every fourth pair
    // keeps a face of B parallel to one of A (resting, stacking: parallel edge pairs).
    BoxD a, b;
    const double scale = logUniform(0.005, 50);
    const double scaleB = std::clamp(scale * logUniform(0.1, 10), 0.005, 50.0);
    a.half = vec3([&] { return scale * (0.2 + 0.8 * u01(rng)); });
    b.half = vec3([&] { return scaleB * (0.2 + 0.8 * u01(rng)); });
    a.q = rotation();
    b.q = s % 4 == 0 ? a.q * about(Vector3d::UnitY(), 90 * sym(rng)) : rotation();
    const double reach = a.half.norm() + b.half.norm();
    a.pos = vec3(symmetric) * std::max(0.0, rangeP - 1.1 * reach);
    const Vector3d dir = vec3(symmetric).normalized();
    const double t = tol<S>(reach, rangeP);
    double lambda = reach * 1.1 * u01(rng);
    if (s % 2 == 1) {
      // Near touching: bisect (in double) for the distance along dir where the boxes just
      // touch, then step off it by 1 .. 1000 tolerances, in or out.
      auto overlapsAt = [&](double l) {
        BoxD bb = b;
        bb.pos = a.pos + dir * l;
        return minOverlap(quantised<double>(a), quantised<double>(bb)) > 0;
      };
      double lo = 0, hi = 2 * reach;
      for (int it = 0; it < 60; ++it) (overlapsAt(0.5 * (lo + hi)) ? lo : hi) = 0.5 * (lo + hi);
      const double step = t * logUniform(1, 1000);
      lambda = std::max(0.0, u01(rng) < 0.5 ? lo - step : lo + step);
    }
    b.pos = a.pos + dir * lambda;

    const BoxM A = quantised<S>(a), B = quantised<S>(b);
    takeFixedFaults();
    const auto cs = collide<S>(a, b);
    EXPECT_EQ(takeFixedFaults(), 0u) << "sample " << s;

    // Presence against the double test. Each computed overlap errs by at most t on a face axis
    // and by (t + margin) / |L| on an edge axis, where the implementation also needs the margin
    // before it separates (box_box.h). So: every axis overlapping by more than t => contacts;
    // some face axis separating by more than t, or an edge axis by more than t + 2 margin / |L|
    // => none; anything else is the band.
    const auto o = axisOverlaps(A, B);
    double must = HUGE_VAL, may = HUGE_VAL, eligible = HUGE_VAL;
    for (int k = 0; k < 15; ++k) {
      const double len = k < 6 ? 1.0 : A.R.col((k - 6) / 3).cross(B.R.col((k - 6) % 3)).norm();
      const double ok = o[size_t(k)];
      must = std::min(must, ok - t);
      may = std::min(may, ok + t + (k < 6 ? 0.0 : 2 * edgeMargin<S>(A, B) / len));
      if (k < 6 || len >= edgeMinSin<S>()) eligible = std::min(eligible, ok);
    }
    if (must > 0) {
      ++st.overlapping;
      EXPECT_FALSE(cs.empty()) << "sample " << s << ": overlap " << must + t << " but no contact";
    } else if (may < 0) {
      ++st.separated;
      EXPECT_TRUE(cs.empty()) << "sample " << s << ": separated by " << t - may << " but " << cs.size() << " contacts";
    } else {
      ++st.banded;
    }

    st.maxCount = std::max(st.maxCount, int(cs.size()));
    EXPECT_LE(cs.size(), 8u);
    for (const ContactD& k : cs) {
      if (k.featureA >= kBoxEdgeFeature) ++st.edge;
      EXPECT_EQ(k.bodyA, 7);
      EXPECT_EQ(k.bodyB, 9);
      EXPECT_NEAR(k.normal.norm(), 1, tol<S>(1)) << "sample " << s;
      EXPECT_GE(k.pen, 0) << "sample " << s;
      EXPECT_EQ(k.normal, cs[0].normal) << "one normal per pair";
      // The chosen axis is at most the tie tolerance worse than the best eligible axis.
      EXPECT_LE(k.pen, (std::max(eligible, 0.0) + t) * (1 + 1.0 / 16) + edgeMargin<S>(A, B) + t) << "sample " << s;
      // The normal points from B to A, and no contact is deeper than the overlap along it; the
      // point lies in both boxes, expanded by the penetration. An edge pair may touch within its
      // margin (penetration 0 while the double test sees a gap up to 2 margin / |L|).
      double slack = t;
      if (k.featureA >= kBoxEdgeFeature) {
        const int i = int(k.featureA - kBoxEdgeFeature) / 4, j = int(k.featureB - kBoxEdgeFeature) / 4;
        slack += 2 * edgeMargin<S>(A, B) / A.R.col(i).cross(B.R.col(j)).norm();
      }
      EXPECT_GE((A.c - B.c).dot(k.normal), -t) << "sample " << s;
      EXPECT_LE(k.pen, overlapAlong(A, B, k.normal.normalized()) + slack) << "sample " << s;
      EXPECT_LE(outside(A, k.point), k.pen + slack) << "sample " << s;
      EXPECT_LE(outside(B, k.point), k.pen + slack) << "sample " << s;
    }
    if (::testing::Test::HasFailure()) break;
  }
  return st;
}

TYPED_TEST(BoxBoxTyped, FuzzAgainstDoubleSeparatingAxisTest) {
  using S = TypeParam;
  const FuzzStats st = fuzz<S>(kFuzzSamples, 12345);
  std::printf("[ fuzz     ] must overlap %d, must separate %d, in band %d, edge contacts %d, max count %d\n",
              st.overlapping, st.separated, st.banded, st.edge, st.maxCount);
  // The loop must exercise both outcomes and the edge path, not sit in the band.
  EXPECT_GT(st.overlapping, kFuzzSamples / 4);
  EXPECT_GT(st.separated, kFuzzSamples / 4);
  EXPECT_LT(st.banded, kFuzzSamples / 5);
  EXPECT_GT(st.edge, kFuzzSamples / 100);
  EXPECT_EQ(st.maxCount, 8);
}

}  // namespace
}  // namespace sg
