// Bodies on heightmap triangles (issue 15): planar heightmaps of fine cells behave as the plane
// they sample (no interior ghost normals), a sphere rests in a V valley on both of its faces, a
// box rests on a ridge line between its corners, and friction is a cone (a box on a slope
// diagonal to the friction axes slides straight down it). Analytic expectations; each tolerance
// is derived next to it. SIMGRASS_PRINT_TERRAIN=1 prints the measured values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>

#include "tests/test_support.h"

namespace sg {
namespace {

constexpr double kG = 9.81;
constexpr double kDt = 1.0 / 60.0;

template <class S>
double d(S v) {
  return ScalarTraits<S>::toDouble(v);
}

Rational q12(double v) { return *Rational::make(std::llround(v * 1e12), 1000000000000); }

bool printing() { return std::getenv("SIMGRASS_PRINT_TERRAIN") != nullptr; }

/// A planar heightmap of 64 x 64 samples, `cell` m apart, centred at the origin, rising by
/// (stepX, stepZ) sample levels per cell along x and z, a level being cell / 8 m: slope
/// (stepX, stepZ) / 8, exact at every sample (so the map *is* a plane).
Scenario planarMap(double cell, int stepX, int stepZ) {
  Scenario s = test::emptyWorld();
  s.terrain.flat = false;
  s.terrain.cellSize = q12(cell);
  s.terrain.maxHeight = q12(255 * cell / 8);
  s.terrain.heightmap.width = s.terrain.heightmap.height = 64;
  for (int z = 0; z < 64; ++z)
    for (int x = 0; x < 64; ++x) s.terrain.heightmap.samples.push_back(uint8_t(stepX * x + stepZ * z));
  return s;
}

/// Where a body of `radius` (sphere) or half edge `radius` (cube) rests on the plane of
/// planarMap at distance `uphill` m up the slope from the centre, yawed by `yawDeg` about the
/// plane's normal; initial speed `v0` downhill.
struct OnThePlane {
  double cell = 0.05;
  int stepX = 2, stepZ = 0;
  bool sphere = false;
  double yawDeg = 0;
  double friction = 0.5;
  double v0 = 0;
  double uphill = 0;
};

struct SlideResult {
  double along = 0, lateral = 0, expected = 0;
};

double slopeOf(const OnThePlane& p) { return std::hypot(p.stepX, p.stepZ) / 8; }

/// Distance down a slope of angle theta in `seconds` from speed v0 (no spin).
/// A block slides at a = g (sin - mu cos) (decelerating when mu > tan theta, and then stopping
/// for good). A ball (I = 2/5 m r^2) thrown without spin first slides: kinetic friction mu g cos
/// slows it (a1 = g (sin - mu cos)) and spins it up (alpha r = 5/2 mu g cos) until v = omega r,
/// at t* = v0 / (7/2 mu g cos - g sin); then it rolls at a2 = 5/7 g sin (mu >= 2/7 tan theta in
/// every case here, so it never slips again).
double analyticDistance(bool ball, double theta, double mu, double v0, double seconds) {
  const double s = std::sin(theta), c = std::cos(theta);
  const double a1 = kG * (s - mu * c);
  if (!ball) {
    if (a1 < 0 && v0 / -a1 < seconds) return v0 * v0 / (2 * -a1);
    return v0 * seconds + 0.5 * a1 * seconds * seconds;
  }
  const double a2 = 5.0 / 7.0 * kG * s;
  const double tStar = std::min(seconds, v0 / (3.5 * mu * kG * c - kG * s));
  const double vStar = v0 + a1 * tStar, rest = seconds - tStar;
  return v0 * tStar + 0.5 * a1 * tStar * tStar + vStar * rest + 0.5 * a2 * rest * rest;
}

template <class S>
SlideResult slideDownThePlane(const OnThePlane& p, double seconds) {
  Scenario s = planarMap(p.cell, p.stepX, p.stepZ);
  const double grade = slopeOf(p), theta = std::atan(grade);
  const double ux = p.stepX / std::hypot(p.stepX, p.stepZ), uz = p.stepZ / std::hypot(p.stepX, p.stepZ);
  // The map's height at world (x, z): sample (i, j) sits at ((i - 31.5) cell, (j - 31.5) cell).
  auto heightAt = [&](double x, double z) {
    return (p.stepX * (x / p.cell + 31.5) + p.stepZ * (z / p.cell + 31.5)) * p.cell / 8;
  };
  const double n[3] = {-std::sin(theta) * ux, std::cos(theta), -std::sin(theta) * uz};  // the plane's normal
  const double down[3] = {-ux * std::cos(theta), -std::sin(theta), -uz * std::cos(theta)};
  const double x0 = p.uphill * ux * std::cos(theta), z0 = p.uphill * uz * std::cos(theta);
  const double r = 0.25;
  BodySpec b;
  b.name = "body";
  ShapeSpec part;
  part.type = p.sphere ? ShapeType::Sphere : ShapeType::Box;
  part.radius = q12(r);
  part.halfExtents = {q12(r), q12(r), q12(r)};
  b.parts = {part};
  b.mass = Rational{1, 1};
  b.restitution = Rational{0, 1};
  b.friction = q12(p.friction);
  b.canSleep = false;
  // Tilt y onto the normal by theta about y x n / |y x n| = (-uz, 0, ux), then yaw about n.
  const double half = theta / 2;
  const double qt[4] = {std::cos(half), -uz * std::sin(half), 0, ux * std::sin(half)};
  const double yaw = p.yawDeg * std::numbers::pi / 180 / 2;
  const double qy[4] = {std::cos(yaw), n[0] * std::sin(yaw), n[1] * std::sin(yaw), n[2] * std::sin(yaw)};
  const double q[4] = {qy[0] * qt[0] - qy[1] * qt[1] - qy[2] * qt[2] - qy[3] * qt[3],
                       qy[0] * qt[1] + qy[1] * qt[0] + qy[2] * qt[3] - qy[3] * qt[2],
                       qy[0] * qt[2] - qy[1] * qt[3] + qy[2] * qt[0] + qy[3] * qt[1],
                       qy[0] * qt[3] + qy[1] * qt[2] - qy[2] * qt[1] + qy[3] * qt[0]};
  b.orientation = {q12(q[0]), q12(q[1]), q12(q[2]), q12(q[3])};
  b.position = {q12(x0 + r * n[0]), q12(heightAt(x0, z0) + r * n[1]), q12(z0 + r * n[2])};
  b.velocity = {q12(p.v0 * down[0]), q12(p.v0 * down[1]), q12(p.v0 * down[2])};
  s.bodies.list = {b};
  auto w = test::makeTyped<S>(s);
  const auto& body = w->bodies()[0];
  const double px = d(body.position.x()), py = d(body.position.y()), pz = d(body.position.z());
  const int64_t ticks = std::llround(seconds / kDt);
  for (int64_t t = 0; t < ticks; ++t) EXPECT_TRUE(w->step(TickInput{}).ok) << "tick " << t;
  const double ex = d(body.position.x()) - px, ey = d(body.position.y()) - py, ez = d(body.position.z()) - pz;
  SlideResult out;
  out.along = ex * down[0] + ey * down[1] + ez * down[2];
  out.lateral = -ex * uz + ez * ux;
  out.expected = analyticDistance(p.sphere, theta, p.friction, p.v0, seconds);
  return out;
}

// A box starting from rest or at 3 m/s, and a ball, on planar heightmaps of 5 cm and 25 cm cells
// (100 and 4 samples under the box), the slope along x, at 27 deg and at 45 deg to the grid, the
// box square to the slope or yawed 30 deg. Before the triangles, a box over 5 cm cells met
// sample points pushing it out through its side faces, up the slope, and stopped within
// centimetres (-100 %); over 25 cm cells it slid 5 to 10 % short.
template <class S>
void expectPlanarHeightmapsAreThePlane(const char* scalar) {
  for (const double cell : {0.05, 0.25})
    for (const auto& [stepX, stepZ] : {std::pair{2, 0}, std::pair{2, 1}, std::pair{2, 2}})
      for (const double yaw : {0.0, 30.0})
        for (const bool ball : {false, true})
          for (const double v0 : {0.0, 3.0}) {
            if (ball && yaw != 0.0) continue;  // a ball has no yaw
            OnThePlane p;
            p.cell = cell;
            p.stepX = stepX;
            p.stepZ = stepZ;
            p.sphere = ball;
            p.yawDeg = yaw;
            p.v0 = v0;
            // Box: mu = tan(theta) / 2 slides at half of g sin; the 3 m/s box at mu = 1.2 tan
            // decelerates. The ball rolls (mu = 0.5 >= 2/7 tan).
            p.friction = ball ? 0.5 : (v0 > 0 ? 1.2 : 0.5) * slopeOf(p);
            // The run stays on the map (3.15 m across at 5 cm cells: half a second there).
            const double seconds = cell < 0.1 && v0 > 0 ? 0.5 : 1.0;
            const double mapHalf = 31.5 * cell;
            p.uphill = std::min(0.8 * mapHalf, 0.5 * mapHalf + 1.5);
            const SlideResult r = slideDownThePlane<S>(p, seconds);
            const std::string name = std::string(scalar) + (ball ? " ball" : " box") + " cell " + std::to_string(cell) +
                                     " steps " + std::to_string(stepX) + "," + std::to_string(stepZ) + " yaw " +
                                     std::to_string(int(yaw)) + " v0 " + std::to_string(int(v0));
            if (printing())
              std::printf("[terrain %s] along %.4f m (analytic %.4f, %+.2f %%) lateral %+.4f m\n", name.c_str(),
                          r.along, r.expected, 100 * (r.along / r.expected - 1), r.lateral);
            // Along: the first tick starts without warm-start impulses, and one relax sweep per
            // sub-step lets a box slip about 0.8 cm/s before friction takes hold (see the
            // friction-angle test): 1 cm plus 2 % of the distance (contact softness and the
            // start from exact contact). A ball rolls with one contact: 0.5 %.
            const double tolerance = ball ? 0.005 * r.expected : 0.01 + 0.02 * r.expected;
            EXPECT_NEAR(r.along, r.expected, tolerance) << name;
            // Across: nothing pushes a body sideways on a plane; a yawed box's corners take
            // the load unevenly as it decelerates, which turns it a little (1.5 cm).
            EXPECT_LT(std::fabs(r.lateral), ball ? 0.001 : 0.015) << name;
          }
}
TEST(TerrainContacts, PlanarHeightmapsAreThePlaneFx32) { expectPlanarHeightmapsAreThePlane<Fx32>("fx32"); }
TEST(TerrainContacts, PlanarHeightmapsAreThePlaneDouble) { expectPlanarHeightmapsAreThePlane<double>("double"); }

/// A 0.5 m cube of 1 kg at (0, y, 0), level, restitution 0.
BodySpec cube(Rational y, Rational friction) {
  BodySpec box;
  box.name = "box";
  ShapeSpec part;
  part.type = ShapeType::Box;
  part.halfExtents = {Rational{1, 4}, Rational{1, 4}, Rational{1, 4}};
  box.parts = {part};
  box.position = {Rational{0, 1}, y, Rational{0, 1}};
  box.restitution = Rational{0, 1};
  box.friction = friction;
  return box;
}

/// A heightmap of 33 x 3 samples, 0.25 m apart, centred at the origin, whose height changes by
/// `rise` m per cell away from the middle column (x = 0): a V valley (rise > 0) or a ridge
/// (rise < 0, from `top` m). The profile is the same in every row, so the crease is a straight
/// line along z.
Scenario creaseMap(double rise, double top) {
  Scenario s = test::emptyWorld();
  s.terrain.flat = false;
  s.terrain.cellSize = Rational{1, 4};
  s.terrain.maxHeight = q12(255 * std::fabs(rise) / 10);  // a level is |rise| / 10
  s.terrain.heightmap.width = 33;
  s.terrain.heightmap.height = 3;
  const int topLevel = rise > 0 ? 0 : int(std::lround(top / (std::fabs(rise) / 10)));
  for (int z = 0; z < 3; ++z)
    for (int x = 0; x < 33; ++x) {
      const int level = rise > 0 ? 10 * std::abs(x - 16) : topLevel - 10 * std::abs(x - 16);
      s.terrain.heightmap.samples.push_back(uint8_t(level));
    }
  return s;
}

// A ball in a V valley of 1:2 sides rests on both faces at once: its centre sits r / cos(theta)
// above the crease line, on it, and still (asleep). Against the plane under its centre only (the
// thesis's sphere test), it touched one face at a time and rocked across the crease.
template <class S>
void expectBallRestsInAValley(const char* scalar) {
  Scenario s = creaseMap(0.125, 0);  // sides of slope 0.125 / 0.25 = 1:2
  const double r = 0.25, theta = std::atan(0.5);
  const double restY = r / std::cos(theta);  // the crease is at height 0
  s.bodies.list = {test::sphere("ball", Rational{1, 4}, {Rational{0, 1}, q12(restY + 0.05), Rational{0, 1}})};
  s.bodies.list[0].restitution = Rational{0, 1};
  auto w = test::makeTyped<S>(s);
  for (int t = 0; t < 240; ++t) ASSERT_TRUE(w->step(TickInput{}).ok) << scalar << " tick " << t;
  const auto& b = w->bodies()[0];
  if (printing())
    std::printf("[valley %s] x %+.5f y %.5f (analytic %.5f) %s\n", scalar, d(b.position.x()), d(b.position.y()), restY,
                b.asleep ? "asleep" : "awake");
  // Both faces hold it: no sideways offset but rounding (0.1 mm). Its height: the soft contacts
  // sink m g / k per face, millimetres (the flat-ground rest test allows 3 mm).
  EXPECT_NEAR(d(b.position.x()), 0.0, 1e-4) << scalar;
  EXPECT_NEAR(d(b.position.y()), restY, 0.003) << scalar;
  EXPECT_TRUE(b.asleep) << scalar;
}
TEST(TerrainContacts, BallRestsInAValleyFx32) { expectBallRestsInAValley<Fx32>("fx32"); }
TEST(TerrainContacts, BallRestsInAValleyFx16) { expectBallRestsInAValley<Fx16>("fx16"); }
TEST(TerrainContacts, BallRestsInAValleyDouble) { expectBallRestsInAValley<double>("double"); }

// A 0.5 m cube balanced on a straight ridge (1:2 sides) with its bottom face level touches the
// ground only along the ridge line, 0.125 m above the slopes under its corners. The ridge's
// samples inside the box are its contacts; the cube must rest on the ridge (bottom at the ridge
// height), not sink onto its corners (0.125 m lower).
template <class S>
void expectBoxRestsOnARidge(const char* scalar) {
  Scenario s = creaseMap(-0.125, 2.0);  // the ridge line at x = 0, 2 m high
  s.bodies.list = {cube(q12(2.25), Rational{1, 1})};
  auto w = test::makeTyped<S>(s);
  for (int t = 0; t < 60; ++t) ASSERT_TRUE(w->step(TickInput{}).ok) << scalar << " tick " << t;
  const auto& b = w->bodies()[0];
  if (printing())
    std::printf("[ridge %s] x %+.5f y %.5f (resting 2.25)\n", scalar, d(b.position.x()), d(b.position.y()));
  EXPECT_NEAR(d(b.position.y()), 2.25, 0.003) << scalar;  // the soft contacts' sink, as on flat ground
  EXPECT_NEAR(d(b.position.x()), 0.0, 0.001) << scalar;
}
TEST(TerrainContacts, BoxRestsOnARidgeFx32) { expectBoxRestsOnARidge<Fx32>("fx32"); }
TEST(TerrainContacts, BoxRestsOnARidgeFx16) { expectBoxRestsOnARidge<Fx16>("fx16"); }
TEST(TerrainContacts, BoxRestsOnARidgeDouble) { expectBoxRestsOnARidge<double>("double"); }

// Friction is a cone: on flat ground under gravity tilted by the friction angle +-0.25 deg
// towards a direction 27 deg or 45 deg off the contacts' fixed tangent axes, a box a quarter
// degree past the angle slides straight down the tilt (a pyramid of per-axis limits gave up to
// sqrt(2) mu N on the diagonal: the 45 deg box held at 1.3 times its friction angle, and the
// 27 deg one slid along one axis only); a quarter degree short of it, it holds and sleeps.
template <class S>
void expectFrictionConeOnTheDiagonal(const char* scalar) {
  const double theta = std::atan(0.25), quarter = 0.25 * std::numbers::pi / 180, seconds = 6;
  for (const double dirDeg : {26.57, 45.0})
    for (const bool slide : {true, false}) {
      const double mu = std::tan(slide ? theta - quarter : theta + quarter);
      const double dir = dirDeg * std::numbers::pi / 180;
      Scenario s = test::emptyWorld();
      s.bodies.gravity = {q12(kG * std::sin(theta) * std::cos(dir)), q12(-kG * std::cos(theta)),
                          q12(kG * std::sin(theta) * std::sin(dir))};
      s.bodies.list = {cube(Rational{1, 4}, q12(mu))};
      auto w = test::makeTyped<S>(s);
      for (int64_t t = 0; t < std::llround(seconds / kDt); ++t) ASSERT_TRUE(w->step(TickInput{}).ok);
      const auto& b = w->bodies()[0];
      const double x = d(b.position.x()), z = d(b.position.z());
      const double along = x * std::cos(dir) + z * std::sin(dir), across = -x * std::sin(dir) + z * std::cos(dir);
      const double a = kG * (std::sin(theta) - mu * std::cos(theta)),
                   expected = slide ? 0.5 * a * seconds * seconds : 0;
      if (printing())
        std::printf("[cone %s dir %.0f %s] along %.4f m (a t^2/2 %.4f) across %+.5f m %s\n", scalar, dirDeg,
                    slide ? "slide" : "hold", along, expected, across, b.asleep ? "asleep" : "awake");
      if (slide) {
        // As the friction-angle test on the tangent axes: 10 % (cold start) plus, in fixed
        // point, two units of friction impulse per sub-step (four corners rounding half a unit).
        double unitAccel = 0;
        if constexpr (ScalarTraits<S>::isFixed) unitAccel = 2 * d(S::fromRaw(1)) / (kDt / 4);
        EXPECT_NEAR(along, expected, 0.10 * expected + unitAccel * seconds * seconds / 2) << scalar << " " << dirDeg;
        EXPECT_LT(std::fabs(across), 0.01 * expected) << scalar << " " << dirDeg;  // straight down the tilt
        EXPECT_FALSE(b.asleep) << scalar << " " << dirDeg;
      } else {
        EXPECT_LT(std::hypot(along, across), 0.005) << scalar << " " << dirDeg;  // the static-friction creep bound
        EXPECT_TRUE(b.asleep) << scalar << " " << dirDeg;
      }
    }
}
TEST(TerrainContacts, FrictionConeOnTheDiagonalFx32) { expectFrictionConeOnTheDiagonal<Fx32>("fx32"); }
TEST(TerrainContacts, FrictionConeOnTheDiagonalFx16) { expectFrictionConeOnTheDiagonal<Fx16>("fx16"); }
TEST(TerrainContacts, FrictionConeOnTheDiagonalDouble) { expectFrictionConeOnTheDiagonal<double>("double"); }

}  // namespace
}  // namespace sg
