// Rigid-body accuracy and stability against analytic expectations: static friction on a slope
// (no creep), kinetic friction (sliding acceleration), a resting stack, a sphere coming to rest on
// a box, grass recovering after a body, and thread-count independence of all of it.
// Each tolerance is derived in a comment next to it; measured values are printed and recorded
// (RecordProperty) so they can be documented.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>

#include "tests/test_support.h"

namespace sg {
namespace {

using test::emptyWorld;
using test::r3;
using test::slope;
using test::sphere;

template <class S>
double d(S v) {
  return ScalarTraits<S>::toDouble(v);
}

constexpr double kG = 9.81;
constexpr double kDt = 1.0 / 60.0;
constexpr double kSlop = 0.0005;  // linearSlop of the position pass (world.cpp)

/// A double as an exact fraction with 1e-12 resolution (below every scalar's: Q32.32 has
/// 2.3e-10); the scalar then rounds that fraction once.
Rational q12(double v) { return *Rational::make(std::llround(v * 1e12), 1000000000000); }
Rational3 q12(double x, double y, double z) { return {q12(x), q12(y), q12(z)}; }

/// A cube of edge 0.5 m, mass 1 kg, restitution 0.
BodySpec cube(const std::string& name, Rational3 position, Rational friction) {
  BodySpec b;
  b.name = name;
  ShapeSpec p;
  p.type = ShapeType::Box;
  p.halfExtents = {Rational{1, 4}, Rational{1, 4}, Rational{1, 4}};
  b.parts = {p};
  b.position = position;
  b.mass = Rational{1, 1};
  b.restitution = Rational{0, 1};
  b.friction = friction;
  return b;
}

using test::makeTyped;

template <class S>
void run(World<S>& w, const Scenario& s, int64_t ticks) {
  for (int64_t t = 0; t < ticks; ++t) ASSERT_TRUE(w.step(scriptedInput(s, w.tick())).ok) << "tick " << w.tick();
}

const double kTheta = std::atan(0.25);  // 14.04 deg
const double kSin = std::sin(kTheta), kCos = std::cos(kTheta);

/// The 0.5 m cube resting on the slope with its bottom face on the plane, centred above the plane
/// point at x = px: rotated about z by +theta (that turns the box's x axis to (cos, sin, 0), up the
/// slope), centre = plane point + 0.25 m along the plane normal (-sin, cos, 0).
BodySpec cubeOnSlope(double px, Rational friction) {
  BodySpec b = cube("box", q12(px - 0.25 * kSin, (px + 8) / 4 + 0.25 * kCos, 0), friction);
  b.orientation = {q12(std::cos(kTheta / 2)), Rational{0, 1}, Rational{0, 1}, q12(std::sin(kTheta / 2))};
  return b;
}

/// Distance along the slope (up is positive) and above the plane of a point (x, y).
double alongSlope(double x, double y) { return x * kCos + y * kSin; }
double abovePlane(double x, double y) { return (y - (x + 8) / 4) * kCos; }

// ---- 1. static friction: a box below its friction angle does not creep ------------------------------
template <class S>
void expectNoCreepBelowFrictionAngle(const char* scalar) {
  Scenario s = slope();
  s.bodies.list = {cubeOnSlope(0.0, Rational{1, 2})};  // mu = 0.5 > tan(theta) = 0.25
  auto w = makeTyped<S>(s);
  run(*w, s, 60);  // 1 s to settle onto the plane
  const auto& b = w->bodies()[0];
  const double s0 = alongSlope(d(b.position.x()), d(b.position.y()));
  const double settleDrift = s0 - alongSlope(cubeOnSlope(0.0, Rational{1, 2}).position[0].toDouble(),
                                             cubeOnSlope(0.0, Rational{1, 2}).position[1].toDouble());
  double worst = 0, worstTilt = 0, lo = 1e9, hi = -1e9;
  for (int t = 0; t < 600; ++t) {
    ASSERT_TRUE(w->step(TickInput{}).ok) << scalar << " tick " << w->tick();
    const double x = d(b.position.x()), y = d(b.position.y());
    worst = std::max(worst, std::fabs(alongSlope(x, y) - s0));
    lo = std::min(lo, abovePlane(x, y));
    hi = std::max(hi, abovePlane(x, y));
    // The box's up axis (column 1 of the rotation) against the plane normal (-sin, cos, 0).
    const double c = -d(b.rotation(0, 1)) * kSin + d(b.rotation(1, 1)) * kCos;
    worstTilt = std::max(worstTilt, std::acos(std::min(1.0, c)));
  }
  const double drift = alongSlope(d(b.position.x()), d(b.position.y())) - s0;
  std::printf(
      "[creep %s] settle drift %.6f m, drift over 10 s %.6f m (max |.| %.6f), height above plane %.6f..%.6f m, "
      "max tilt %.3g rad\n",
      scalar, settleDrift, drift, worst, lo, hi, worstTilt);
  ::testing::Test::RecordProperty(std::string("creep_drift_m_") + scalar, std::to_string(drift));
  ::testing::Test::RecordProperty(std::string("creep_max_drift_m_") + scalar, std::to_string(worst));
  // Static friction holds when mu >= tan(theta): the exact answer is zero drift. The solver is
  // iterative (8 sweeps of sequential impulses), so a residual tangential velocity of a fraction of the
  // per-tick gravity increment g sin(theta) dt = 4 cm/s may survive a tick; 5 mm over 600 ticks
  // allows an average residual of 0.5 mm/s (1 % of that increment) — a box that creeps at the
  // rate of a real (viscous) residual fails.
  EXPECT_LT(worst, 0.005) << scalar << ": the box creeps down a slope it should stick to";
  EXPECT_LT(std::fabs(settleDrift), 0.005) << scalar << ": it slid while settling";
  // Resting on the plane: centre 0.25 m above it, minus up to the slop and one tick of gravity
  // sink (g dt^2 = 2.7 mm) when the contact is re-established.
  EXPECT_GT(lo, 0.25 - kSlop - kG * kDt * kDt) << scalar;
  EXPECT_LT(hi, 0.25 + 0.001) << scalar << ": lifts off";
  EXPECT_LT(worstTilt, 0.01) << scalar << ": the bottom face stays on the plane (0.6 deg)";
}
TEST(BodyAccuracy, BoxOnSlopeBelowFrictionAngleDoesNotCreepDouble) {
  expectNoCreepBelowFrictionAngle<double>("double");
}
TEST(BodyAccuracy, BoxOnSlopeBelowFrictionAngleDoesNotCreepFx32) { expectNoCreepBelowFrictionAngle<Fx32>("fx32"); }

// ---- 2. kinetic friction: above the friction angle it slides with g (sin - mu cos) -------------------
TEST(BodyAccuracy, BoxSlidesDownSlopeWithCoulombAcceleration) {
  Scenario s = slope();
  s.bodies.list = {cubeOnSlope(6.0, Rational{1, 10})};  // mu = 0.1 < tan(theta) = 0.25
  auto w = makeTyped<double>(s);
  run(*w, s, 15);  // a quarter second to land on the plane and start sliding
  // Least-squares quadratic s(t) = c0 + c1 t + c2 t^2 over the next second (60 ticks).
  std::vector<double> ts, ss;
  for (int t = 0; t <= 60; ++t) {
    if (t > 0) {
      ASSERT_TRUE(w->step(TickInput{}).ok);
    }
    const auto& b = w->bodies()[0];
    ts.push_back(t * kDt);
    ss.push_back(alongSlope(b.position.x(), b.position.y()));
  }
  const size_t n = ts.size();
  const double tm = ts[n / 2];
  double S[5] = {0, 0, 0, 0, 0}, R[3] = {0, 0, 0};
  for (size_t i = 0; i < n; ++i) {
    const double u = ts[i] - tm;
    double p = 1;
    for (int k = 0; k < 5; ++k, p *= u) S[k] += p;
    R[0] += ss[i], R[1] += ss[i] * u, R[2] += ss[i] * u * u;
  }
  // Solve [[S0 S1 S2][S1 S2 S3][S2 S3 S4]] c = R (Cramer).
  auto det3 = [](double a, double b, double c, double d_, double e, double f, double g, double h, double i) {
    return a * (e * i - f * h) - b * (d_ * i - f * g) + c * (d_ * h - e * g);
  };
  const double D = det3(S[0], S[1], S[2], S[1], S[2], S[3], S[2], S[3], S[4]);
  const double c2 = det3(S[0], S[1], R[0], S[1], S[2], R[1], S[2], S[3], R[2]) / D;
  double resid = 0;
  {
    const double c1 = det3(S[0], R[0], S[2], S[1], R[1], S[3], S[2], R[2], S[4]) / D;
    const double c0 = det3(R[0], S[1], S[2], R[1], S[2], S[3], R[2], S[3], S[4]) / D;
    for (size_t i = 0; i < n; ++i) {
      const double u = ts[i] - tm;
      resid = std::max(resid, std::fabs(ss[i] - (c0 + c1 * u + c2 * u * u)));
    }
  }
  const double measured = -2 * c2;                   // down the slope is -s
  const double analytic = kG * (kSin - 0.1 * kCos);  // 1.4276 m/s^2
  std::printf(
      "[slide] measured a = %.6f m/s^2, analytic g (sin - mu cos) = %.6f m/s^2, ratio %.5f, fit residual %.3g m\n",
      measured, analytic, measured / analytic, resid);
  ::testing::Test::RecordProperty("slide_accel_measured", std::to_string(measured));
  ::testing::Test::RecordProperty("slide_accel_analytic", std::to_string(analytic));
  // Semi-implicit Euler under a constant net force gives positions that are exactly quadratic in
  // t with exactly the acceleration a (the O(dt) error only shifts the linear term), so a fit
  // of positions recovers a exactly if the solver delivers the exact Coulomb impulse
  // mu m g cos(theta) dt every tick. Sequential impulses clamp each contact's friction to mu
  // times its own accumulated normal impulse, and later sweeps change those normals only by the
  // non-converged remainder; 2 % of a (0.03 m/s^2, i.e. 2 % of the friction impulse itself when
  // mu g cos = 0.95 m/s^2) covers that and per-tick contact jitter, while a frictionless slide
  // (2.38 m/s^2) or static friction (0) is far outside.
  EXPECT_NEAR(measured / analytic, 1.0, 0.02);
  // Contact jitter shows up as a non-quadratic residual: a sub-millimetre one means no bouncing.
  EXPECT_LT(resid, 0.001);
}

// ---- 3. a stack of five cubes stands ---------------------------------------------------------------
struct StackStats {
  double horizontal = 0;               // largest horizontal distance of a box from where it was placed (m)
  double topMin = 1e9, topMax = -1e9;  // top box height after the first second (m)
  double jitter = 0;                   // largest (max - min) height of a box over the last 10 s (m)
  double tilt = 0;                     // largest angle of a box's up axis from vertical (rad)
  double yaw = 0;                      // largest rotation of a box about the vertical (rad)
  int fellAt = -1;                     // first tick the top box is 5 cm below its standing height
};

Scenario stackScenario(int velocityIterations, int positionIterations) {
  Scenario s = emptyWorld();
  s.bodies.velocityIterations = velocityIterations;
  s.bodies.positionIterations = positionIterations;
  // Bottom face of box i at i * (0.5 + 0.001) + 0.001 m: 1 mm gaps between the boxes and above
  // the ground.
  for (int i = 0; i < 5; ++i)
    s.bodies.list.push_back(cube("box" + std::to_string(i), r3(0, 250 + 1 + 501 * i, 0, 1000), Rational{3, 5}));
  return s;
}

template <class S>
StackStats runStack(const Scenario& s, int ticks) {
  auto w = makeTyped<S>(s);
  StackStats st;
  std::vector<double> lo(5, 1e9), hi(5, -1e9);
  for (int t = 0; t < ticks; ++t) {
    EXPECT_TRUE(w->step(TickInput{}).ok) << "tick " << t;
    for (size_t i = 0; i < 5; ++i) {
      const auto& b = w->bodies()[i];
      const double x = d(b.position.x()), y = d(b.position.y()), z = d(b.position.z());
      st.horizontal = std::max(st.horizontal, std::hypot(x, z));
      st.tilt = std::max(st.tilt, std::acos(std::min(1.0, d(b.rotation(1, 1)))));
      st.yaw = std::max(st.yaw, std::fabs(std::atan2(d(b.rotation(0, 2)), d(b.rotation(0, 0)))));
      if (i == 4 && t >= 60) st.topMin = std::min(st.topMin, y), st.topMax = std::max(st.topMax, y);
      if (i == 4 && st.fellAt < 0 && y < 2.25 - 0.05) st.fellAt = t;
      if (t >= ticks / 2) lo[i] = std::min(lo[i], y), hi[i] = std::max(hi[i], y);
    }
  }
  for (size_t i = 0; i < 5; ++i) st.jitter = std::max(st.jitter, hi[i] - lo[i]);
  return st;
}

template <class S>
void expectStackStands(const std::string& label, int velocityIterations, int positionIterations) {
  const StackStats st = runStack<S>(stackScenario(velocityIterations, positionIterations), 1200);
  std::printf(
      "[stack %s] horizontal drift %.6f m, top height (after 1 s) %.6f..%.6f m, jitter (last 10 s) %.6f m, "
      "max tilt %.3g rad, max yaw %.3g rad, top box fell at tick %d\n",
      label.c_str(), st.horizontal, st.topMin, st.topMax, st.jitter, st.tilt, st.yaw, st.fellAt);
  ::testing::Test::RecordProperty("stack_horizontal_m_" + label, std::to_string(st.horizontal));
  ::testing::Test::RecordProperty("stack_jitter_m_" + label, std::to_string(st.jitter));
  ::testing::Test::RecordProperty("stack_top_min_m_" + label, std::to_string(st.topMin));
  ::testing::Test::RecordProperty("stack_fell_at_tick_" + label, std::to_string(st.fellAt));
  // Nothing pushes sideways: the exact answer is zero. 2 cm is 4 % of the box edge: a stack that
  // walks (a residual angular velocity each tick that friction turns into rolling, and a position
  // pass that un-rotates about the centre, not the contact) fails long before it falls.
  EXPECT_LT(st.horizontal, 0.02) << label;
  // At rest each of the five contacts keeps up to the 0.5 mm slop of overlap: the top centre sits
  // at 0.25 + 4 * 0.5 = 2.25 m minus up to 5 * 0.5 mm. (In the first ticks the boxes fall onto
  // each other through the 1 mm gaps and sink up to v dt = 1.4 cm before the projection pushes
  // them out; that transient is left out.) 1 cm below means a contact is being crushed or the
  // stack fell; above the placed height 2.254 m means it was thrown up.
  EXPECT_GT(st.topMin, 2.25 - 5 * kSlop - 0.01) << label << ": the stack sank or fell";
  EXPECT_LT(st.topMax, 2.255) << label << ": the stack jumped";
  // Once settled nothing moves: a contact lost for one tick drops a box by g dt^2 = 2.7 mm, the
  // projection re-establishes it within the slop; 1 mm over the last 10 s means it never does.
  EXPECT_LT(st.jitter, 0.001) << label << ": the stack jitters";
  // The slop lets a 0.5 m face lean by 0.5 mm / 0.5 m = 1 mrad per contact, five contacts 5 mrad;
  // 20 mrad (1.1 deg) means a box rocks. Nothing twists a stack about the vertical: 20 mrad too.
  EXPECT_LT(st.tilt, 0.02) << label << ": a box rocks";
  EXPECT_LT(st.yaw, 0.02) << label << ": a box twists";
}
// The scenario defaults (16 velocity sweeps since warm starting also matches contacts by point;
// 8 sweeps let the stack walk and fall, see below).
const Scenario::Bodies kDefaults{};
TEST(BodyAccuracy, StackOfFiveBoxesStandsDouble) {
  expectStackStands<double>("double", kDefaults.velocityIterations, kDefaults.positionIterations);
}
TEST(BodyAccuracy, StackOfFiveBoxesStandsFx32) {
  expectStackStands<Fx32>("fx32", kDefaults.velocityIterations, kDefaults.positionIterations);
}
// What the same solver needs to meet the bounds (measured horizontal drift over 20 s, double and
// fx32 alike unless noted). Without warm starting (before commit 8ef8199) the per-tick error falls only
// like 1 / sweeps: 8 and 32 sweeps collapse, 128: 5.6 cm, 256: 3.3 cm, 512: 1.4 cm, 1024: 0.5 cm.
// With warm starting (contact impulses carried over, keyed by bodies and features): 8 sweeps walk
// for the first 4 s and then lock (double, 8.7 cm) or tip over after 7 s (fx32); 12: 1.0 cm,
// 16: 1.0 cm, 32: 0.5 cm, 64: 0.8 mm. Position iterations (2..32) change little either way.
// While it walks, the box-box contacts keep changing feature ids (equal aligned faces: incident
// corners lie on the reference side planes, so a corner id and an edge-crossing id swap, and the
// reference face flips between the two boxes): 254 new contact keys after tick 10 in 10 s with
// 8 sweeps, 14 with 16. Each new key starts from zero impulse, which is what keeps it walking.
TEST(BodyAccuracy, StackOfFiveBoxesStandsWith16VelocitySweepsDouble) { expectStackStands<double>("double-16", 16, 8); }
TEST(BodyAccuracy, StackOfFiveBoxesStandsWith16VelocitySweepsFx32) { expectStackStands<Fx32>("fx32-16", 16, 8); }

// ---- 4. a sphere dropped on a box comes to rest on top of it ----------------------------------------
template <class S>
void expectSphereRestsOnBox(const char* scalar) {
  Scenario s = emptyWorld();
  BodySpec box = cube("box", r3(0, 250, 0, 1000), Rational{3, 5});
  BodySpec ball = sphere("ball", Rational{1, 5}, r3(0, 15, 0, 10));  // 0.8 m above the box top
  ball.restitution = Rational{3, 10};  // 4 m/s impact: bounces (above the 1 m/s threshold)
  ball.friction = Rational{3, 5};
  ball.mass = Rational{1, 2};
  s.bodies.list = {box, ball};
  auto w = makeTyped<S>(s);
  run(*w, s, 180);  // 3 s: bounce apexes 0.8 m, then e^2 0.8 m = 7 cm, then below the threshold
  const auto& sb = w->bodies()[1];
  const auto& bb = w->bodies()[0];
  const double y3 = d(sb.position.y());
  double off = 0, speed = 0, boxLo = 1e9, boxHi = -1e9;
  for (int t = 0; t < 420; ++t) {  // then 7 s at rest
    ASSERT_TRUE(w->step(TickInput{}).ok) << scalar << " tick " << w->tick();
    off = std::max(off, std::hypot(d(sb.position.x()), d(sb.position.z())));
    speed = std::max(speed, std::hypot(d(sb.velocity.x()), d(sb.velocity.y()), d(sb.velocity.z())));
    boxLo = std::min(boxLo, d(bb.position.y()));
    boxHi = std::max(boxHi, d(bb.position.y()));
  }
  const double y10 = d(sb.position.y());
  std::printf(
      "[sphere-on-box %s] sphere y %.6f at 3 s, %.6f at 10 s (expect 0.7 - slop); over 3..10 s: max off-centre "
      "%.4f m, max speed %.4f m/s; box y %.6f..%.6f, box up axis x %.2e z %.2e\n",
      scalar, y3, y10, off, speed, boxLo, boxHi, d(bb.rotation(0, 1)), d(bb.rotation(2, 1)));
  ::testing::Test::RecordProperty(std::string("sphere_on_box_offcentre_m_") + scalar, std::to_string(off));
  ::testing::Test::RecordProperty(std::string("sphere_on_box_speed_ms_") + scalar, std::to_string(speed));
  // On top: centre at box top 0.5 + radius 0.2, minus the slop of both contacts (box-ground and
  // sphere-box, 0.5 mm each) plus a tick of gravity sink (2.7 mm) if a contact was just re-made.
  EXPECT_NEAR(y3, 0.7 - 2 * kSlop, kG * kDt * kDt + 2 * kSlop) << scalar;
  EXPECT_NEAR(y10, 0.7 - 2 * kSlop, kG * kDt * kDt + 2 * kSlop) << scalar << ": rolled off";
  // A straight drop on the face centre has no sideways force, and a sphere on a level face has
  // nowhere to roll; but nothing resists rolling either, so any lean alpha of the box rolls it with
  // 5/7 g alpha. The slop would allow alpha = 0.5 mm / 0.5 m = 1 mrad (17 cm in 7 s: off the box).
  // Bounds: the sphere stays within 2 cm of the centre over 3..10 s (8 % of the half face; it also
  // covers the few-mm sideways kick of the first 4 m/s impact, solved contact by contact), which
  // a lean must stay below 2 * 2 cm / (5/7 g (7 s)^2) = 1.2e-4 rad for; at rest the solver
  // cancels each tick's g dt = 0.16 m/s, 1 cm/s of speed left is 6 % of that.
  const double lean = std::hypot(d(bb.rotation(0, 1)), d(bb.rotation(2, 1)));
  EXPECT_LT(off, 0.02) << scalar << ": the sphere rolls off-centre";
  EXPECT_LT(speed, 0.01) << scalar << ": the sphere does not come to rest";
  EXPECT_LT(lean, 1.2e-4) << scalar << ": the box leans (rad)";
  EXPECT_NEAR(boxLo, 0.25 - kSlop, kSlop + 1e-4) << scalar << ": the box stays on the ground";
  EXPECT_NEAR(boxHi, 0.25 - kSlop, kSlop + 1e-4) << scalar << ": the box stays on the ground";
}
TEST(BodyAccuracy, SphereDroppedOnBoxRestsOnTopDouble) { expectSphereRestsOnBox<double>("double"); }
TEST(BodyAccuracy, SphereDroppedOnBoxRestsOnTopFx32) { expectSphereRestsOnBox<Fx32>("fx32"); }

// ---- 5. grass recovers after a body leaves ----------------------------------------------------------
struct Recovery {
  double vyAtLeave = 0;           // hidden upward particle velocity (m/s) when the body left
  int bentTufts = 0;              // tufts that reached tilt level >= 1 while the body rolled
  double worstOffsetAtLeave = 0;  // largest tip offset (m) when the body left
  double firstUpright = -1;       // s after the body left: first tick with every tuft recovered
  double staysUpright = -1;       // s after the body left: from here on every tuft stays recovered
  double tiltZero = -1;           // s after the body left: from here on tilt level 0 everywhere
};

/// thesis-bodies.json with the bunny (r 0.4 m, 2 kg) alone, rolled through the meadow at 3 m/s
/// for 1.5 s, then teleported out of the meadow; no wind, no initial particle velocity (the
/// scenario's (0.2, 0.2, 0.2) m/s alone leans untouched thesis-mode tufts by more than 1 cm for
/// about 13 s, which would hide the body's effect). The field is cut to 8 m x 2 m around the
/// track (the rest of the meadow never sees the body). "Recovered": tilt level 0 and tip offset
/// below 1 cm for every tuft.
template <class S>
Recovery measureRecovery(GrassModel mode, double horizonSeconds) {
  Scenario s = loadScenarioFile(test::sourcePath("scenarios/thesis-bodies.json"));
  s.wind.schedule.clear();
  s.script.clear();
  s.particles.model = mode;
  s.particles.initialVelocity = r3(0, 0, 0);
  s.field.patchesX = 33;
  s.field.patchesZ = 9;
  BodySpec bunny = s.bodies.list[1];
  bunny.position = {Rational{-3, 1}, Rational{2, 5}, Rational{0, 1}};
  bunny.velocity = r3(3, 0, 0);
  s.bodies.list = {bunny};
  auto w = makeTyped<S>(s);
  const auto& p = w->patches();
  Recovery r;
  const int leaveTick = 90;
  std::vector<uint8_t> everTilted(p.tiltLevel.size(), 0);
  for (int t = 0; t < leaveTick; ++t) {
    EXPECT_TRUE(w->step(TickInput{}).ok);
    for (size_t i = 0; i < everTilted.size(); ++i) everTilted[i] |= p.tiltLevel[i] > 0;
  }
  for (uint8_t e : everTilted) r.bentTufts += e;
  r.vyAtLeave = d(w->particles().vy[0]);  // particle 0 (a corner, 1 m from the track) is untouched
  auto worstOffset = [&] {
    double worst = 0;
    for (size_t i = 0; i < p.tipOffsetX.size(); ++i)
      worst = std::max(worst, std::hypot(d(p.tipOffsetX[i]), d(p.tipOffsetZ[i])));
    return worst;
  };
  r.worstOffsetAtLeave = worstOffset();
  // Teleport far outside the meadow (the command a script would give).
  TickInput away;
  away.bodies.push_back(BodyCommand{0, BodyCommandKind::Teleport, InputVec3{int64_t(100) << 32, int64_t(1) << 32, 0}});
  const int horizon = int(std::lround(horizonSeconds / kDt));
  int lastBad = -1, lastTilted = -1;
  for (int t = 0; t < horizon; ++t) {
    EXPECT_TRUE(w->step(t == 0 ? away : TickInput{}).ok);
    const bool tilted = std::any_of(p.tiltLevel.begin(), p.tiltLevel.end(), [](uint8_t l) { return l > 0; });
    const bool upright = !tilted && worstOffset() < 0.01;
    if (tilted) lastTilted = t;
    if (!upright)
      lastBad = t;
    else if (r.firstUpright < 0)
      r.firstUpright = (t + 1) * kDt;
  }
  // Step t ends (t + 1) dt after the body left; recovered for good from the step after the last
  // bad one. Only known if that is at least 10 s inside the horizon.
  if (lastBad < horizon - 600) r.staysUpright = (lastBad + 2) * kDt;
  if (lastTilted < horizon - 600) r.tiltZero = (lastTilted + 2) * kDt;
  return r;
}

void report(const char* name, const Recovery& r) {
  std::printf(
      "[grass %s] %d tufts bent (tilt >= 1) by the body; when it left: hidden v_y %.3f m/s, worst tip offset "
      "%.3f m; after it left: first all recovered %.2f s, recovered for good %.2f s, tilt level 0 for good "
      "%.2f s\n",
      name, r.bentTufts, r.vyAtLeave, r.worstOffsetAtLeave, r.firstUpright, r.staysUpright, r.tiltZero);
  ::testing::Test::RecordProperty(std::string("grass_recovered_s_") + name, std::to_string(r.staysUpright));
  ::testing::Test::RecordProperty(std::string("grass_first_recovered_s_") + name, std::to_string(r.firstUpright));
  ::testing::Test::RecordProperty(std::string("grass_tilt_zero_s_") + name, std::to_string(r.tiltZero));
  EXPECT_GE(r.bentTufts, 10) << name << ": the body should have bent the grass";
  EXPECT_GT(r.worstOffsetAtLeave, 0.2) << name << ": tufts were bent when the body left";
}

constexpr double kRod = 0.5;                          // thesis-bodies.json constraintLength
const double kEndAngle = std::asin(0.01 / kRod);      // tip offset 1 cm: 0.02 rad
const double kTiltAngle = std::acos(1 - 0.1 / kRod);  // tilt level 1 at a 0.1 m sink: 0.6435 rad

TEST(BodyAccuracy, GrassRecoversAfterABodyLeavesThesisMode) {
  const Recovery r = measureRecovery<Fx32>(GrassModel::Thesis, 20);
  report("thesis", r);
  // A body moves particle positions only (thesis §4), so a pushed tuft keeps its purely vertical
  // hidden velocity v_y (v_inf (1 - q^n), v_inf = 32.8 m/s: 1.47 m/s after 1.5 s) and never gains
  // a sideways one. Each tick the tip moves v_y dt up and is projected back onto the rod, which
  // turns the tuft by dphi = -(v_y dt / L) sin(phi): tan(phi / 2) decays as exp(-int v_y dt / L).
  // With v_y(t) = v_y0 + a t (a = 1 m/s^2; the 3 %/s damping is negligible over 2 s), the time
  // from phi0 to the 1 cm angle solves v_y0 t + a t^2 / 2 = L ln(tan(phi0/2) / tan(phiEnd/2)).
  // (The 30-40 s of docs/physics-notes.md are a gust's: a gust leaves sideways velocity that only
  // the 0.97/s damping removes; a body push leaves none.)
  auto timeFrom = [&](double phi0) {
    const double rhs = kRod * std::log(std::tan(phi0 / 2) / std::tan(kEndAngle / 2));
    return -r.vyAtLeave + std::sqrt(r.vyAtLeave * r.vyAtLeave + 2 * rhs);  // a = 1
  };
  // Lower bound: the worst tuft was at least at asin(offset / L) when the body left; upper bound:
  // a tuft pressed 18 deg below horizontal (0.9 pi; the sphere presses the tips down and aside).
  // 20 % / 25 % margins for the small-step approximation and the v_y growth model.
  const double lo = 0.8 * timeFrom(std::asin(std::min(1.0, r.worstOffsetAtLeave / kRod)));
  const double hi = 1.25 * timeFrom(0.9 * std::numbers::pi);
  std::printf("[grass thesis] model: recovered within %.2f .. %.2f s\n", lo, hi);
  EXPECT_NEAR(r.vyAtLeave, 32.82 * (1 - std::pow(0.97, 1.5)), 0.01) << "hidden velocity (physics notes)";
  EXPECT_GT(r.staysUpright, lo) << "thesis: recovered faster than the rod projection allows";
  EXPECT_LT(r.staysUpright, hi) << "thesis: recovery slower than the hidden-velocity model";
  EXPECT_GT(r.tiltZero, 0);
  EXPECT_LE(r.tiltZero, r.staysUpright);
  EXPECT_LE(r.firstUpright, r.staysUpright);
}

TEST(BodyAccuracy, GrassRecoversAfterABodyLeavesPbdMode) {
  const Recovery r = measureRecovery<Fx32>(GrassModel::Pbd, 200);
  report("pbd", r);
  // A bent tuft is a pendulum under the upward a = 1 m/s^2 (omega^2 = a / L = 2 /s^2, period
  // 4.4 s). Its angular amplitude decays exponentially at gamma = c / 2 + omega^2 dt / 2:
  // c = -ln 0.97 = 0.0305 /s is the velocity damping; omega^2 dt / 2 = 0.0167 /s is the numerical
  // damping of the position-based step (Cyclone order p += v dt; v += a dt, then the projection
  // and v += correction / dt) — measured with one tuft: 0.0165 /s at dt = 1/60, half at dt = 1/120,
  // independent of the amplitude. gamma = 0.0319 /s: a time constant of 31 s, so a tuft released
  // at angle phi0 needs ln(phi0 / phiEnd) / gamma to settle (the 2.6 s of the physics notes is a
  // gust's tuft first swinging back, not settling).
  const double gamma = -std::log(0.97) / 2 + (1.0 / kRod) * kDt / 2;
  // Lower bound: the worst tuft's angle when the body left (asin(offset / L), a lower bound of its
  // amplitude); upper bound: a tuft pressed straight down (pi). Margins 20 % / 10 % for the
  // large-angle pendulum (whose damping per swing differs from the linear one).
  const double phiLeave = std::asin(std::min(1.0, r.worstOffsetAtLeave / kRod));
  const double lo = 0.8 * std::log(phiLeave / kEndAngle) / gamma;
  const double hi = 1.1 * std::log(std::numbers::pi / kEndAngle) / gamma;
  const double tiltLo = 0.8 * std::log(phiLeave / kTiltAngle) / gamma;
  const double tiltHi = 1.1 * std::log(std::numbers::pi / kTiltAngle) / gamma;
  std::printf("[grass pbd] model: recovered within %.1f .. %.1f s, tilt level 0 within %.1f .. %.1f s\n", lo, hi,
              tiltLo, tiltHi);
  EXPECT_GT(r.staysUpright, lo) << "pbd: settles faster than the damping allows";
  EXPECT_LT(r.staysUpright, hi) << "pbd: settles slower than the damped pendulum";
  EXPECT_GT(r.tiltZero, tiltLo);
  EXPECT_LT(r.tiltZero, tiltHi);
  // It swings: the first moment all tufts are within 1 cm comes before they stay so.
  EXPECT_LE(r.firstUpright, r.staysUpright);
}

// ---- 6. determinism: bodies give the same state for any thread count -------------------------------
template <class S>
void expectThreadCountIndependent(const char* scalar) {
  for (int which = 0; which < 2; ++which) {
    Scenario s = which == 0 ? stackScenario(8, 8) : slope();
    if (which == 1) s.bodies.list = {cubeOnSlope(0.0, Rational{1, 2}), cubeOnSlope(5.0, Rational{1, 10})};
    // A meadow under the bodies (about 9,400 particles: several chunks), so there is parallel work
    // whose split could differ, and grass the bodies push.
    s.field.patchesX = s.field.patchesZ = 96;
    s.field.centerX = Rational{0, 1};
    s.scalar = ScalarTraits<S>::kind;
    auto one = makeWorld(s, 1);
    auto two = makeWorld(s, 2);
    for (int t = 0; t < 240; ++t) {
      ASSERT_TRUE(one->step(TickInput{}).ok) << scalar << " 1 thread, tick " << t;
      ASSERT_TRUE(two->step(TickInput{}).ok) << scalar << " 2 threads, tick " << t;
      if (t % 60 == 59) {
        ASSERT_EQ(one->stateHash(), two->stateHash()) << scalar << (which == 0 ? " stack" : " slope") << " tick " << t;
      }
    }
  }
}
TEST(BodyAccuracy, StackAndSlopeAreThreadCountIndependentFx32) { expectThreadCountIndependent<Fx32>("fx32"); }
TEST(BodyAccuracy, StackAndSlopeAreThreadCountIndependentDouble) { expectThreadCountIndependent<double>("double"); }

}  // namespace
}  // namespace sg

namespace sg {
namespace {
// A box resting on the level ground beyond a heightmap's edge (issue 15): the ground there is the
// edge samples extended, level along x, but its normal kept the edge cell's 1:4 slope and the
// box slid away down a slope that is not there. It must stay put, at the edge height (4 m).
template <class S>
void expectBoxBeyondTheEdgeStaysPut(const char* name) {
  Scenario s = test::slope();  // the map spans x in [-8, 8]; beyond x = 8 the ground is 4 m high
  // Friction 0.1: below the 1:4 slope's friction angle, so a tilted normal would let it slide.
  s.bodies.list = {cube("box", test::r3(48, 17, 0, 4), Rational{1, 10})};  // x = 12, resting at y = 4.25
  s.bodies.list[0].canSleep = false;
  auto w = makeTyped<S>(s);
  run(*w, s, 300);
  const auto& b = w->bodies()[0];
  EXPECT_NEAR(ScalarTraits<S>::toDouble(b.position.x()), 12.0, 0.001) << name;
  EXPECT_NEAR(ScalarTraits<S>::toDouble(b.position.z()), 0.0, 0.001) << name;
  EXPECT_NEAR(ScalarTraits<S>::toDouble(b.position.y()), 4.25, 0.003) << name;  // gravity's g dt^2 sink, as flat ground
}
TEST(BodyAccuracy, BoxBeyondAHeightmapEdgeStaysPutDouble) { expectBoxBeyondTheEdgeStaysPut<double>("double"); }
TEST(BodyAccuracy, BoxBeyondAHeightmapEdgeStaysPutFx32) { expectBoxBeyondTheEdgeStaysPut<Fx32>("fx32"); }
TEST(BodyAccuracy, BoxBeyondAHeightmapEdgeStaysPutFx16) { expectBoxBeyondTheEdgeStaysPut<Fx16>("fx16"); }
}  // namespace
}  // namespace sg

namespace sg {
namespace {
// Friction angle +-0.25 deg (issue 15): a quarter degree past it the box accelerates at only
// 4 cm/s^2, slow enough to pass the sleep test's speeds, and it fell asleep and never slid. A
// contact whose friction is at its Coulomb limit now keeps its body awake. A quarter degree short
// of it the box holds and sleeps. On flat ground under tilted gravity and on the 1:4 heightmap.
struct FrictionAngleRun {
  double along = 0;  // m moved along the slope, downhill positive
  double accel = 0;  // m/s^2 along the slope from the speed at 1 s and at the end (flat ground only)
  bool asleep = false;
};

template <class S>
FrictionAngleRun onTheSlope(bool heightmap, double mu, double seconds) {
  Scenario s = heightmap ? slope() : test::emptyWorld();
  const Rational friction = q12(mu);
  if (heightmap) {
    s.bodies.list = {cubeOnSlope(0.0, friction)};
  } else {  // flat ground, gravity tilted by theta towards +x
    s.bodies.gravity = q12(kG * kSin, -kG * kCos, 0);
    s.bodies.list = {cube("box", q12(0, 0.25, 0), friction)};
  }
  auto w = makeTyped<S>(s);
  const auto& b = w->bodies()[0];
  const double x0 = d(b.position.x()), y0 = d(b.position.y());
  const int64_t ticks = std::llround(seconds / kDt), second = std::llround(1 / kDt);
  double v1 = 0;
  for (int64_t t = 0; t < ticks; ++t) {
    EXPECT_TRUE(w->step(TickInput{}).ok) << "tick " << t;
    if (t + 1 == second) v1 = d(b.velocity.x());
  }
  FrictionAngleRun r;
  r.accel = (d(b.velocity.x()) - v1) / (seconds - 1);
  r.along =
      heightmap ? -(alongSlope(d(b.position.x()), d(b.position.y())) - alongSlope(x0, y0)) : d(b.position.x()) - x0;
  r.asleep = b.asleep;
  return r;
}

template <class S>
void expectFrictionAngleBoundary(const char* name, bool heightmap) {
  const double quarter = 0.25 * std::numbers::pi / 180;
  const double seconds = 6;
  const double slideMu = std::tan(kTheta - quarter), holdMu = std::tan(kTheta + quarter);
  const FrictionAngleRun slide = onTheSlope<S>(heightmap, slideMu, seconds);
  const FrictionAngleRun hold = onTheSlope<S>(heightmap, holdMu, seconds);
  const double a = kG * (kSin - slideMu * kCos);  // 0.043 m/s^2
  const double expected = 0.5 * a * seconds * seconds;
  if (std::getenv("SIMGRASS_PRINT_FRICTION"))
    std::printf("[friction angle %s %s] slide %.4f m (a t^2/2 = %.4f m), %s; hold %.5f m, %s\n", name,
                heightmap ? "heightmap" : "flat", slide.along, expected, slide.asleep ? "asleep" : "awake", hold.along,
                hold.asleep ? "asleep" : "awake");
  // Sliding: awake and near a t^2 / 2 (0.79 m). On flat ground the acceleration (from the speeds
  // at 1 s and 6 s) within 2 % of g (sin - mu cos): a Coulomb impulse mu N per sub-step, where N
  // is off by 0.1 % already misses by 2 %. The distance also holds the cold start: the first tick
  // has no warm-start impulses, and the box slips 3.3 mm/s before friction takes hold (less than
  // a sub-step of unopposed sliding, g sin h = 1.0 cm/s), 2 cm over 6 s: within 10 %.
  // On the heightmap the box meets the surface's sample points as
  // contacts of their own (triangle contacts are issue 15's next step) and slides up to 18 % too
  // far in double (2.7 % in fx32): held to [-5 %, +25 %] until then.
  EXPECT_FALSE(slide.asleep) << name;
  if (heightmap) {
    EXPECT_GT(slide.along, 0.95 * expected) << name << " heightmap";
    EXPECT_LT(slide.along, 1.25 * expected) << name << " heightmap";
  } else {
    // In fixed point a friction impulse of mu m g cos h per sub-step (0.0094 N s) is rounded to
    // a unit of the format; near the friction angle that unit is a whole acceleration of
    // unit / (m h): 2^-16 / (1 kg x 1/240 s) = 0.0037 m/s^2 in fx16 (8 % of a), 6e-8 in fx32.
    // The box has four corner contacts, each rounding its cone-scaled impulse by up to half a
    // unit: up to two units in all.
    double unitAccel = 0;
    if constexpr (ScalarTraits<S>::isFixed)
      unitAccel = 2 * d(S::fromRaw(1)) / (1.0 * kDt / Scenario::Bodies{}.substeps);
    EXPECT_NEAR(slide.accel, a, 0.02 * a + unitAccel) << name << " flat";
    EXPECT_NEAR(slide.along, expected, 0.10 * expected + unitAccel * seconds * seconds / 2) << name << " flat";
  }
  // Holding: asleep, moved less than 5 mm (the creep bound of the static-friction test).
  EXPECT_TRUE(hold.asleep) << name;
  EXPECT_LT(std::fabs(hold.along), 0.005) << name << (heightmap ? " heightmap" : " flat");
}
TEST(BodyAccuracy, FrictionAngleBoundaryOnFlatGroundFx32) { expectFrictionAngleBoundary<Fx32>("fx32", false); }
TEST(BodyAccuracy, FrictionAngleBoundaryOnFlatGroundFx16) { expectFrictionAngleBoundary<Fx16>("fx16", false); }
TEST(BodyAccuracy, FrictionAngleBoundaryOnFlatGroundDouble) { expectFrictionAngleBoundary<double>("double", false); }
TEST(BodyAccuracy, FrictionAngleBoundaryOnAHeightmapFx32) { expectFrictionAngleBoundary<Fx32>("fx32", true); }
TEST(BodyAccuracy, FrictionAngleBoundaryOnAHeightmapDouble) { expectFrictionAngleBoundary<double>("double", true); }
}  // namespace
}  // namespace sg

namespace sg {
namespace {
// A ball on a gentle slope rolls (issue 15, "sleep never freezes a body whose contact forces cannot
// hold it"): one contact point with friction turns the ball about its centre, so no contact
// force holds it, however far the friction is from its limit. At 0.5 degrees it rolls at
// 5/7 g sin(theta) = 0.061 m/s^2, 3 cm/s after the half second the speed test waits: it fell
// asleep there, 7.7 mm from where it started (an independent pass, 2026-11-28). On level ground it
// still sleeps: gravity has no tangential part, the friction is exactly 0.
template <class S>
void expectBallOnAGentleSlopeRolls(const char* name) {
  for (const double degrees : {0.5, 0.15, 0.0}) {
    const double theta = degrees * std::numbers::pi / 180;
    Scenario s = test::emptyWorld();
    s.bodies.gravity = q12(kG * std::sin(theta), -kG * std::cos(theta), 0);
    BodySpec ball = test::sphere("ball", Rational{1, 4}, q12(0, 0.25, 0));
    ball.mass = Rational{1, 1};
    ball.restitution = Rational{0, 1};
    ball.friction = Rational{1, 2};
    s.bodies.list = {ball};
    auto w = makeTyped<S>(s);
    const double seconds = 6;
    run(*w, s, std::llround(seconds / kDt));
    const auto& b = w->bodies()[0];
    const double rolled = d(b.position.x());
    // Rolling without slipping: a = 5/7 g sin(theta) (a solid sphere, I = 2/5 m r^2). Within
    // 3 %: the first tick's cold start slips a little before friction takes hold, and the speed
    // of a sub-step's gravity is rounded in fixed point.
    const double expected = 0.5 * (5.0 / 7.0) * kG * std::sin(theta) * seconds * seconds;
    if (degrees > 0) {
      EXPECT_FALSE(b.asleep) << name << " " << degrees << " deg";
      EXPECT_NEAR(rolled, expected, 0.03 * expected) << name << " " << degrees << " deg";
    } else {
      EXPECT_TRUE(b.asleep) << name << " on level ground";
      EXPECT_NEAR(rolled, 0.0, 1e-6) << name << " on level ground";
    }
  }
}
TEST(BodyAccuracy, BallOnAGentleSlopeRollsAndOnLevelGroundSleepsFx32) { expectBallOnAGentleSlopeRolls<Fx32>("fx32"); }
TEST(BodyAccuracy, BallOnAGentleSlopeRollsAndOnLevelGroundSleepsFx16) { expectBallOnAGentleSlopeRolls<Fx16>("fx16"); }
TEST(BodyAccuracy, BallOnAGentleSlopeRollsAndOnLevelGroundSleepsDouble) {
  expectBallOnAGentleSlopeRolls<double>("double");
}
}  // namespace
}  // namespace sg

namespace sg {
namespace {
// Removing a support wakes what rested on it (issue 15): a box asleep on another box stayed
// asleep in mid-air when the lower one was teleported away, displaced or reset.
template <class S>
void expectRemovedSupportWakesTheBodyOnIt(BodyCommandKind how, const char* name) {
  Scenario s = test::emptyWorld();
  s.bodies.list = {cube("lower", q12(0, 0.25, 0), Rational{1, 2}), cube("upper", q12(0, 0.75, 0), Rational{1, 2})};
  s.bodies.list[1].name = "upper";
  auto w = makeTyped<S>(s);
  run(*w, s, 120);  // 2 s: both fall asleep (0.5 s below the speeds)
  ASSERT_TRUE(w->bodies()[0].asleep && w->bodies()[1].asleep) << name << ": the stack did not fall asleep";
  TickInput in;
  const InputVec3 away{int64_t(20) << 32, int64_t(1) << 31, 0};  // 20 m aside (teleport) or by (displace)
  in.bodies.push_back(BodyCommand{0, how, how == BodyCommandKind::Reset ? InputVec3{} : away});
  if (how == BodyCommandKind::Reset) {  // a reset puts it back: move it first, let it sleep there
    TickInput move;
    move.bodies.push_back(BodyCommand{0, BodyCommandKind::Teleport, away});
    ASSERT_TRUE(w->step(move).ok);
    run(*w, s, 180);  // the upper box falls onto the ground and sleeps again
    ASSERT_TRUE(w->bodies()[1].asleep) << name;
    // Now the upper box rests on the ground at the lower one's start: the reset puts the lower
    // box back into it, and the upper box must wake (and be pushed out).
  }
  ASSERT_TRUE(w->step(in).ok) << name;
  EXPECT_FALSE(w->bodies()[1].asleep) << name << ": the body on the support stays asleep";
  run(*w, s, 60);
  if (how != BodyCommandKind::Reset) {  // it fell the 0.5 m onto the ground
    EXPECT_NEAR(d(w->bodies()[1].position.y()), 0.25, 0.01) << name;
  }
}
TEST(BodyAccuracy, RemovedSupportWakesTheBodyOnItTeleportFx32) {
  expectRemovedSupportWakesTheBodyOnIt<Fx32>(BodyCommandKind::Teleport, "teleport fx32");
}
TEST(BodyAccuracy, RemovedSupportWakesTheBodyOnItDisplaceDouble) {
  expectRemovedSupportWakesTheBodyOnIt<double>(BodyCommandKind::Displace, "displace double");
}
TEST(BodyAccuracy, RemovedSupportWakesTheBodyOnItResetFx16) {
  expectRemovedSupportWakesTheBodyOnIt<Fx16>(BodyCommandKind::Reset, "reset fx16");
}
}  // namespace
}  // namespace sg
namespace sg {
namespace {
// A box a quarter degree past its friction angle on steep slopes (27 and 45 deg; flat ground,
// gravity tilted): its speed must grow at g (sin - mu cos) from the start. The friction axes turned
// onto the slide at 1 cm/s, slower than a tick of kinetic friction (mu g cos dt: 7 and 12 cm/s)
// can take off a sideways speed, so the sideways speed flipped and grew 4-fold a tick and
// friction along the swinging axis let the box gain 4 to 9 cm/s in four ticks: slides 27 % and
// 44 % too long. The speed at 6 s is now a t, give or take the cold start (the first tick has no
// warm-start impulses; it slips less than one sub-step of unopposed sliding, g sin h) and 2 % of
// a t (the flat-ground acceleration tolerance above).
template <class S>
void expectSteepSlideWithoutBurst(const char* name, double degrees) {
  const double theta = degrees * std::numbers::pi / 180, quarter = 0.25 * std::numbers::pi / 180;
  const double mu = std::tan(theta - quarter), seconds = 6;
  Scenario s = test::emptyWorld();
  s.bodies.gravity = q12(kG * std::sin(theta), -kG * std::cos(theta), 0);
  s.bodies.list = {cube("box", q12(0, 0.25, 0), q12(mu))};
  auto w = makeTyped<S>(s);
  const auto& b = w->bodies()[0];
  double sideways = 0;
  for (int64_t t = 0; t < std::llround(seconds / kDt); ++t) {
    ASSERT_TRUE(w->step(TickInput{}).ok) << name << " tick " << t;
    sideways = std::max(sideways, std::fabs(d(b.velocity.z())));
  }
  const double a = kG * (std::sin(theta) - mu * std::cos(theta));
  const double h = kDt / Scenario::Bodies{}.substeps;
  const double v = d(b.velocity.x());
  std::printf("[steep slide %s %.1f deg] v(6 s) %.5f m/s, a t %.5f m/s, largest sideways speed %.5f m/s\n", name,
              degrees, v, a * seconds, sideways);
  // fx16 rounds each corner's friction impulse to a unit of 2^-16 N s: up to two units a sub-step
  // in all, an acceleration of 2 unit / (m h) (0.0073 m/s^2; the flat-ground test above).
  double unitAccel = 0;
  if constexpr (ScalarTraits<S>::isFixed) unitAccel = 2 * d(S::fromRaw(1)) / (1.0 * h);
  EXPECT_NEAR(v, a * seconds, kG * std::sin(theta) * h + 0.02 * a * seconds + unitAccel * seconds)
      << name << " " << degrees << " deg";
  EXPECT_LT(sideways, 0.001) << name << " " << degrees << " deg: nothing pushes the box sideways";
}
TEST(BodyAccuracy, SteepSlideHasNoBurstFx32) {
  expectSteepSlideWithoutBurst<Fx32>("fx32", 26.565);
  expectSteepSlideWithoutBurst<Fx32>("fx32", 45);
}
TEST(BodyAccuracy, SteepSlideHasNoBurstFx16) {
  expectSteepSlideWithoutBurst<Fx16>("fx16", 26.565);
  expectSteepSlideWithoutBurst<Fx16>("fx16", 45);
}
TEST(BodyAccuracy, SteepSlideHasNoBurstDouble) {
  expectSteepSlideWithoutBurst<double>("double", 26.565);
  expectSteepSlideWithoutBurst<double>("double", 45);
}
}  // namespace
}  // namespace sg
