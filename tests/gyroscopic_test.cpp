// The gyroscopic term against Euler's equations (issue 15). A free box with three different
// principal inertias, spun about its middle axis with a small wobble, flips over and back
// periodically (the Dzhanibekov effect); the flip times are compared with a high-precision
// reference (RK4 on Euler's equations at dt = 1e-5 s), and energy and |L| are checked. Without
// the term the angular velocity stayed fixed in world space and the box never flipped.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "tests/test_support.h"

namespace sg {
namespace {

using test::emptyWorld;
using test::makeTyped;
using test::r3;

// A 1 kg box 0.8 x 0.4 x 0.2 m: I = m/3 (hb^2 + hc^2) per axis.
constexpr std::array<double, 3> kHalf = {0.4, 0.2, 0.1};
constexpr double kSpin = 4.0;     // rad/s about the middle (y) axis
constexpr double kWobble = 0.02;  // rad/s about x only (equal x and z wobbles of one sign lie on the decaying mode)

std::array<double, 3> inertia() {
  std::array<double, 3> i{};
  for (int a = 0; a < 3; ++a) {
    const double b = kHalf[size_t((a + 1) % 3)], c = kHalf[size_t((a + 2) % 3)];
    i[size_t(a)] = (b * b + c * c) / 3.0;
  }
  return i;
}

Scenario spinningBox(Rational dt) {
  Scenario s = emptyWorld();
  s.timeStep = dt;
  s.bodies.gravity = r3(0, 0, 0);
  BodySpec b;
  b.name = "box";
  ShapeSpec p;
  p.type = ShapeType::Box;
  p.halfExtents = {Rational{2, 5}, Rational{1, 5}, Rational{1, 10}};
  b.parts = {p};
  b.mass = Rational{1, 1};
  b.position = r3(0, 100, 0);
  b.angularVelocity = {*Rational::make(2, 100), Rational::integer(4), Rational{0, 1}};
  b.canSleep = false;
  s.bodies.list = {b};
  return s;
}

/// Times (s) at which the body-frame angular velocity about the middle axis changes sign.
std::vector<double> referenceFlips(double seconds) {
  const std::array<double, 3> I = inertia();
  auto rate = [&](const std::array<double, 3>& w) {
    return std::array<double, 3>{(I[1] - I[2]) * w[1] * w[2] / I[0], (I[2] - I[0]) * w[2] * w[0] / I[1],
                                 (I[0] - I[1]) * w[0] * w[1] / I[2]};
  };
  std::array<double, 3> w = {kWobble, kSpin, 0.0};
  const double h = 1e-5;
  std::vector<double> flips;
  for (int64_t n = 0; n < int64_t(seconds / h); ++n) {
    auto add = [](std::array<double, 3> a, const std::array<double, 3>& d, double s) {
      for (int k = 0; k < 3; ++k) a[size_t(k)] += s * d[size_t(k)];
      return a;
    };
    const auto k1 = rate(w), k2 = rate(add(w, k1, h / 2)), k3 = rate(add(w, k2, h / 2)), k4 = rate(add(w, k3, h));
    const double before = w[1];
    for (int k = 0; k < 3; ++k)
      w[size_t(k)] += h / 6 * (k1[size_t(k)] + 2 * k2[size_t(k)] + 2 * k3[size_t(k)] + k4[size_t(k)]);
    if ((before > 0) != (w[1] > 0)) flips.push_back(double(n + 1) * h);
  }
  return flips;
}

struct Run {
  std::vector<double> flips;
  double energyFirst = 0, energyMax = 0, energyLast = 0;  // rotational kinetic energy, J
  double momentumFirst = 0, momentumLast = 0;             // |L|, kg m^2/s
};

template <class S>
Run simulate(Rational dt, double seconds) {
  const Scenario s = spinningBox(dt);
  auto w = makeTyped<S>(s);
  const std::array<double, 3> I = inertia();
  Run run;
  double before = kSpin;
  const int64_t ticks = std::llround(seconds / dt.toDouble());
  for (int64_t t = 0; t < ticks; ++t) {
    EXPECT_TRUE(w->step(TickInput{}).ok) << "tick " << t;
    const auto& b = w->bodies()[0];
    std::array<double, 3> wb{}, world{};
    for (int k = 0; k < 3; ++k) world[size_t(k)] = ScalarTraits<S>::toDouble(b.angularVelocity[k]);
    for (int r = 0; r < 3; ++r)  // body axes: R^T w
      for (int k = 0; k < 3; ++k) wb[size_t(r)] += ScalarTraits<S>::toDouble(b.rotation(k, r)) * world[size_t(k)];
    double energy = 0, l2 = 0;
    for (int k = 0; k < 3; ++k) {
      energy += 0.5 * I[size_t(k)] * wb[size_t(k)] * wb[size_t(k)];
      l2 += I[size_t(k)] * wb[size_t(k)] * I[size_t(k)] * wb[size_t(k)];
    }
    if (t == 0) run.energyFirst = energy, run.momentumFirst = std::sqrt(l2);
    run.energyMax = std::max(run.energyMax, energy);
    run.energyLast = energy, run.momentumLast = std::sqrt(l2);
    if ((before > 0) != (wb[1] > 0)) run.flips.push_back(double(t + 1) * dt.toDouble());
    before = wb[1];
  }
  return run;
}

/// `coarse`: fx16. The wobble that grows into a flip changes w by ~6e-5 rad/s per sub-step at
/// dt = 1/240 with 4 sub-steps (h = 1/960 s): 4 units of Q16.16, so its exponential growth is
/// resolved to a quarter and the flips come early (measured: first flip 2.41 s against 2.71 s).
/// At dt = 1/60 (h = 1/240 s) the first flip is within 5 % (2.65 s); energy and |L| drift down by
/// a few per cent in 20 s (measured -3.6 %) and never up. Held to those at dt = 1/60.
template <class S>
void expectFlipsAsEulersEquations(const char* name, bool coarse = false) {
  const double seconds = 20;
  const std::vector<double> reference = referenceFlips(seconds);
  ASSERT_GE(reference.size(), 3u) << "the reference flips at least three times in 20 s";
  const Run r60 = simulate<S>(Rational{1, 60}, seconds);
  const Run r240 = simulate<S>(Rational{1, 240}, seconds);
  if (std::getenv("SIMGRASS_PRINT_GYRO")) {
    std::printf("%s reference flips:", name);
    for (double t : reference) std::printf(" %.3f", t);
    for (const Run* r : {&r60, &r240}) {
      std::printf("\n%s %s flips:", name, r == &r60 ? "dt=1/60 " : "dt=1/240");
      for (double t : r->flips) std::printf(" %.3f", t);
      std::printf("  energy %.6f -> %.6f J, |L| %.6f -> %.6f", r->energyFirst, r->energyLast, r->momentumFirst,
                  r->momentumLast);
    }
    std::printf("\n");
  }
  // The box flips: the same number of times as the reference (within one at the end of the run).
  ASSERT_GE(r240.flips.size() + 1, reference.size()) << name;
  ASSERT_GE(r60.flips.size(), 1u) << name << ": never flipped";
  // The first flip within 5 % of the reference at 1/240, and every flip within 2 % of the
  // reference's period (2.7 s, 5.4 s apart) at both steps: the midpoint rule is second order and
  // a flip's time is measured to one tick.
  const double e60 = std::fabs(r60.flips[0] - reference[0]), e240 = std::fabs(r240.flips[0] - reference[0]);
  if (coarse) {
    EXPECT_LT(e60, 0.05 * reference[0]) << name << ": " << e60 << " s at 1/60";
    EXPECT_LE(r60.energyMax, r60.energyFirst * (1 + 1e-3)) << name << ": gained energy";
    EXPECT_GT(r60.energyLast, r60.energyFirst * 0.9) << name;
    return;
  }
  EXPECT_LT(e240, 0.05 * reference[0]) << name << ": " << e60 << " s at 1/60, " << e240 << " s at 1/240";
  for (const Run* r : {&r60, &r240}) {
    ASSERT_GE(r->flips.size() + 1, reference.size()) << name;
    for (size_t k = 0; k < std::min(r->flips.size(), reference.size()); ++k)
      EXPECT_NEAR(r->flips[k], reference[k], 0.02 * (reference[1] - reference[0]) + 1.0 / 60) << name << " flip " << k;
    // A torque-free body never gains energy, and keeps |L| to the energy it loses (0.2 % here).
    EXPECT_LE(r->energyMax, r->energyFirst * (1 + 1e-5)) << name;
    EXPECT_GT(r->energyLast, r->energyFirst * (1 - 0.005)) << name;
    EXPECT_NEAR(r->momentumLast, r->momentumFirst, 0.005 * r->momentumFirst) << name;
  }
}

TEST(Gyroscopic, MiddleAxisSpinFlipsAsEulersEquationsFx32) { expectFlipsAsEulersEquations<Fx32>("fx32"); }
TEST(Gyroscopic, MiddleAxisSpinFlipsAsEulersEquationsDouble) { expectFlipsAsEulersEquations<double>("double"); }
TEST(Gyroscopic, MiddleAxisSpinFlipsAsEulersEquationsFx16) { expectFlipsAsEulersEquations<Fx16>("fx16", true); }

// A spin about the largest or the smallest axis is stable: it stays where it is.
TEST(Gyroscopic, SpinAboutAStableAxisStays) {
  for (int axis : {0, 2}) {
    Scenario s = spinningBox(Rational{1, 60});
    auto& wv = s.bodies.list[0].angularVelocity;
    wv = {*Rational::make(2, 100), *Rational::make(2, 100), *Rational::make(2, 100)};
    wv[size_t(axis)] = Rational::integer(4);
    auto w = makeTyped<double>(s);
    double minAlong = 4;
    for (int t = 0; t < 1200; ++t) {
      ASSERT_TRUE(w->step(TickInput{}).ok);
      const auto& b = w->bodies()[0];
      minAlong = std::min(minAlong, (b.rotation.transpose() * b.angularVelocity)[axis]);
    }
    EXPECT_GT(minAlong, 3.9) << "axis " << axis;
  }
}

// The angular-speed cap (Box2D v3's b2_maxRotation): a quarter turn per sub-step, (pi / 4) x 4 x
// 60 = 188.5 rad/s at the defaults (pi as 355/113), in every scalar. It applies before each
// sub-step's gyroscopic term, which then keeps the rotational energy but not |w|: a capped body
// has at most the energy of the cap about its largest axis, so |w| <= cap sqrt(I_max / I_min).
template <class S>
void expectAngularSpeedIsCapped(const char* name) {
  Scenario s = spinningBox(Rational{1, 60});
  s.bodies.list[0].angularVelocity = {Rational{600, 1}, Rational{800, 1}, Rational{0, 1}};  // 1,000 rad/s
  auto w = makeTyped<S>(s);
  ASSERT_TRUE(w->step(TickInput{}).ok) << name;
  const auto& b = w->bodies()[0];
  const double wx = ScalarTraits<S>::toDouble(b.angularVelocity.x()),
               wy = ScalarTraits<S>::toDouble(b.angularVelocity.y());
  const double wz = ScalarTraits<S>::toDouble(b.angularVelocity.z());
  const double cap = 355.0 / 113.0 / 4 * 240, speed = std::sqrt(wx * wx + wy * wy + wz * wz);
  const auto& I = b.inertiaLocal;
  const Vec3<S> wb = b.rotation.transpose() * b.angularVelocity;
  double energy = 0, largest = 0, smallest = 1e9;
  for (int k = 0; k < 3; ++k) {
    const double ik = ScalarTraits<S>::toDouble(I[k]), wk = ScalarTraits<S>::toDouble(wb[k]);
    energy += ik * wk * wk;
    largest = std::max(largest, ik);
    smallest = std::min(smallest, ik);
  }
  EXPECT_LE(energy, largest * cap * cap * (1 + 1e-3)) << name;
  EXPECT_LE(speed, cap * std::sqrt(largest / smallest) * (1 + 1e-3)) << name;
  EXPECT_GT(speed, 0.9 * cap) << name;  // capped, not stopped
}
TEST(Gyroscopic, AngularSpeedIsCappedFx32) { expectAngularSpeedIsCapped<Fx32>("fx32"); }
TEST(Gyroscopic, AngularSpeedIsCappedFx16) { expectAngularSpeedIsCapped<Fx16>("fx16"); }
TEST(Gyroscopic, AngularSpeedIsCappedDouble) { expectAngularSpeedIsCapped<double>("double"); }

// fx16: a large body (200 kg, 3 x 1 x 0.6 m: principal inertias up to 167 kg m^2) tumbling at
// 18 rad/s. The gyroscopic term formed I w^2 (and its energy check I w^2 unscaled below
// 128 rad/s): past fx16's range, a fixed-point overflow at the first sub-step. It now steps, and
// keeps its energy within the midpoint rule's wander.
TEST(Gyroscopic, LargeTumblingBodyStaysInFx16Range) {
  Scenario s = spinningBox(Rational{1, 60});
  s.bodies.list[0].mass = Rational{200, 1};
  s.bodies.list[0].parts[0].halfExtents = {Rational{3, 2}, Rational{1, 2}, Rational{3, 10}};
  s.bodies.list[0].angularVelocity = {Rational{1, 1}, Rational{18, 1}, Rational{1, 2}};
  auto w = makeTyped<Fx16>(s);
  for (int t = 0; t < 600; ++t) ASSERT_TRUE(w->step(TickInput{}).ok) << "tick " << t;
  const auto& b = w->bodies()[0];
  const Vec3<Fx16> wb = b.rotation.transpose() * b.angularVelocity;
  const auto& I = b.inertiaLocal;
  double energy = 0, start = 0;
  const double w0[3] = {1, 18, 0.5};
  for (int k = 0; k < 3; ++k) {
    energy += I[k].toDouble() * wb[k].toDouble() * wb[k].toDouble();
    start += I[k].toDouble() * w0[k] * w0[k];
  }
  EXPECT_LE(energy, start * (1 + 1e-3));
  EXPECT_GT(energy, start * 0.98);
}

}  // namespace
}  // namespace sg
