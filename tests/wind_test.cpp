// Wind timing: the first tick at which each particle row receives a gust, forward and backward.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>

#include "sim/scenario/derived.h"
#include "sim/wind/wind.h"

#include "tests/test_support.h"

namespace sg {
namespace {

// Thesis meadow: 151 particle rows 0.25 m apart, gusts travel at 7.5 m/s, dt = 1/60 s, so a gust
// front needs 0.25 / 7.5 * 60 = 2 ticks per row. Schedule: +z for 5 s (300 ticks), calm 6 s,
// -z for 4 s (240 ticks, starting at tick 660), calm 6 s; period 1260 ticks.
TEST(WindSchedule, ThesisScheduleInTicks) {
  const Scenario s = test::thesisMeadow();
  const WindSchedule w = WindSchedule::build(s, deriveConstants(s));
  ASSERT_EQ(w.gusts.size(), 4u);
  EXPECT_EQ(w.periodTicks, 1260);
  EXPECT_EQ(w.gusts[0].startTick, 0);
  EXPECT_EQ(w.gusts[0].durationTicks, 300);
  EXPECT_FALSE(w.gusts[0].backward);
  EXPECT_EQ(w.gusts[2].startTick, 660);
  EXPECT_EQ(w.gusts[2].durationTicks, 240);
  EXPECT_TRUE(w.gusts[2].backward);
  for (int64_t r : {0, 1, 2, 75, 150}) {
    EXPECT_EQ(w.firstTick(0, r), 2 * r) << "forward gust reaches row r after 2 ticks per row";
    EXPECT_EQ(w.firstTick(2, r), 660 + 2 * (150 - r)) << "backward gust starts at the last row";
  }
}

// The same, observed through the world: the z acceleration of row r turns on at the predicted tick.
void expectFirstForceTicks(WindTravel travel) {
  Scenario s = test::thesisMeadow();
  s.wind.travel = travel;
  auto w = std::make_unique<World<double>>(s, 1);
  std::vector<int64_t> firstPlus(151, -1), firstMinus(151, -1);
  for (int64_t t = 0; t < 1260; ++t) {
    ASSERT_TRUE(w->step(TickInput{}).ok);
    const auto& a = w->rowAcceleration();
    for (size_t r = 0; r < 151; ++r) {
      if (a.z[r] > 0 && firstPlus[r] < 0) firstPlus[r] = t;
      if (a.z[r] < 0 && firstMinus[r] < 0) firstMinus[r] = t;
    }
  }
  for (int64_t r = 0; r < 151; ++r) {
    EXPECT_EQ(firstPlus[size_t(r)], 2 * r) << "row " << r;
    const int64_t expectedMinus = travel == WindTravel::Direction ? 660 + 2 * (150 - r) : 660 + 2 * r;
    EXPECT_EQ(firstMinus[size_t(r)], expectedMinus) << "row " << r;
  }
}
TEST(WindSchedule, FirstForceTickPerRowDirectionTravel) { expectFirstForceTicks(WindTravel::Direction); }
TEST(WindSchedule, FirstForceTickPerRowForwardTravel) { expectFirstForceTicks(WindTravel::Forward); }

TEST(WindSchedule, NoForceBeforeArrivalAndRepeatsEveryPeriod) {
  const Scenario s = test::thesisMeadow();
  const WindSchedule w = WindSchedule::build(s, deriveConstants(s));
  EXPECT_FALSE(w.active(0, 100, 199));
  EXPECT_TRUE(w.active(0, 100, 200));
  EXPECT_TRUE(w.active(0, 100, 499));
  EXPECT_FALSE(w.active(0, 100, 500)) << "5 s = 300 ticks after arrival";
  EXPECT_TRUE(w.active(0, 100, 200 + 1260)) << "next period";
  EXPECT_FALSE(w.active(0, 100, 199 + 1260));
}

TEST(WindSchedule, DelaysRoundToNearestTick) {
  Scenario s = test::thesisMeadow();
  s.wind.travelSpeed = Rational{10, 1};  // 0.25 / 10 * 60 = 1.5 ticks per row
  s.field.patchesZ = 5;
  const WindSchedule w = WindSchedule::build(s, deriveConstants(s));
  EXPECT_EQ(w.delayFromFirstRow, (std::vector<int64_t>{0, 2, 3, 5, 6}));  // 1.5 -> 2, 4.5 -> 5
  EXPECT_EQ(w.delayFromLastRow, (std::vector<int64_t>{6, 5, 3, 2, 0}));
}

TEST(WindSchedule, InterpolatedRowsUseParticleRowSpacing) {
  Scenario s = test::thesisMeadow();
  s.particles.interpolation = 2;  // particle rows are 0.5 m apart: 4 ticks per row
  auto w = std::make_unique<World<Fx32>>(s, 1);
  EXPECT_EQ(w->wind().firstTick(0, 10), 40);
  EXPECT_EQ(w->wind().delayFromFirstRow.size(), 76u);
}

TEST(WindSchedule, OverlappingGustsAdd) {
  Scenario s = test::thesisMeadow();
  s.wind.schedule = {{{Rational{0, 1}, Rational{0, 1}, Rational{1, 1}}, Rational{1, 1}},
                     {{Rational{0, 1}, Rational{0, 1}, Rational{-1, 2}}, Rational{1, 1}}};
  s.particles.acceleration = {Rational{0, 1}, Rational{0, 1}, Rational{0, 1}};
  auto w = std::make_unique<World<double>>(s, 1);
  // Gust 1 (-z) starts at tick 60 and reaches row 150 at once; gust 0 reached row 150 at tick 300
  // and still blows there until 360: ticks 300..359 carry both.
  for (int t = 0; t <= 300; ++t) ASSERT_TRUE(w->step(TickInput{}).ok);
  EXPECT_DOUBLE_EQ(w->rowAcceleration().z[150], (1.0 - 0.5) / 60.0);
}

}  // namespace
}  // namespace sg

// ---- gust fronts in any horizontal direction ---------------------------------------------------

namespace sg {
namespace {

/// One gust of force (0, 0, 1) N with a front, then a long calm; thesis meadow otherwise.
Scenario frontScenario(int64_t fx, int64_t fz) {
  Scenario s = test::thesisMeadow();
  WindGust gust{test::r3(0, 0, 1), Rational{10, 1}};
  gust.front = std::array<Rational, 2>{Rational::integer(fx), Rational::integer(fz)};
  s.wind.schedule = {gust, {test::r3(0, 0, 0), Rational{100, 1}}};
  return s;
}

// A row's runs are exactly the per-column activity: for random fronts, ticks, rows and column
// ranges, every column of every run is under the gusts (and only those) the brute-force test says.
RC_GTEST_PROP(WindFront, RowRunsEqualTheColumnByColumnActivity,
              (int8_t fx, int8_t fz, uint16_t tickSeed, uint8_t rowSeed, uint8_t beginSeed, uint8_t lengthSeed)) {
  RC_PRE(fx != 0 || fz != 0);
  Scenario s = test::thesisMeadow();
  s.wind.travelSpeed = Rational{3, 4};  // slow: a front takes 20 ticks per particle, 3000 across
  s.wind.schedule = {
      {test::r3(1, 0, 0), Rational{1, 1}, std::array<Rational, 2>{Rational::integer(fx), Rational::integer(fz)}},
      {test::r3(0, 0, 1), Rational{2, 1}, std::array<Rational, 2>{Rational::integer(fz), Rational::integer(-fx)}},
      {test::r3(0, 1, 0), Rational{1, 2}},
      {test::r3(0, 0, 0), Rational{3, 1}}};
  const ScenarioConstants c = deriveConstants(s);
  const WindSchedule w = WindSchedule::build(s, c);
  WindConstants<double> k;
  k.forceX = {1, 0, 0, 0};
  k.forceY = {0, 0, 1, 0};
  k.forceZ = {0, 1, 0, 0};
  k.dt = 1;
  const int64_t tick = tickSeed % 8000, row = rowSeed % 151, begin = beginSeed % 151;
  const int64_t end = std::min<int64_t>(151, begin + 1 + lengthSeed);
  std::vector<WindRun<double>> runs;
  computeRowWind(w, k, tick, row, begin, end, &runs);
  RC_ASSERT(!runs.empty());
  RC_ASSERT(runs.front().begin == begin);
  RC_ASSERT(runs.back().end == end);
  for (size_t r = 0; r < runs.size(); ++r) {
    if (r > 0) RC_ASSERT(runs[r].begin == runs[r - 1].end);
    for (int64_t i = runs[r].begin; i < runs[r].end; ++i) {
      // A front along +-z is the thesis' row-uniform gust (its exact row delays).
      const auto on = [&](size_t g) { return w.gusts[g].swept ? w.activeAt(g, i, row, tick) : w.active(g, row, tick); };
      const double x = on(0) ? 1 : 0, z = on(1) ? 1 : 0;
      const double y = w.active(2, row, tick) ? 1 : 0;
      RC_ASSERT(runs[r].dvx == x);
      RC_ASSERT(runs[r].dvy == y);
      RC_ASSERT(runs[r].dvz == z);
    }
  }
}

// The front arrives where a straight line moving along the direction at the travel speed would:
// particle (i, j) first feels the gust at round(((i, j) - the first corner) . u * 2 ticks), 2
// ticks per 0.25 m spacing at 7.5 m/s (within one tick: the delay is rounded once, from Q32.32
// ticks per column and per row). Checked through the world, on every particle, for eight
// directions, by the tick its z velocity first changes.
TEST(WindFront, ArrivesWhereAStraightFrontWould) {
  for (const auto& [fx, fz] :
       std::vector<std::pair<int64_t, int64_t>>{{1, 0}, {0, 1}, {-1, 0}, {0, -1}, {1, 1}, {-3, 4}, {5, -2}, {-1, -7}}) {
    Scenario s = frontScenario(fx, fz);
    s.field.patchesX = 31;
    s.field.patchesZ = 21;
    s.particles.initialVelocity = test::r3(0, 0, 0);
    auto w = test::makeTyped<double>(s);
    const int64_t nx = 31, nz = 21;
    std::vector<int64_t> first(size_t(nx * nz), -1);
    for (int64_t t = 0; t < 200; ++t) {
      ASSERT_TRUE(w->step(TickInput{}).ok);
      const auto& p = w->particles();
      for (size_t q = 0; q < first.size(); ++q)
        if (first[q] < 0 && p.vz[q] > 0) first[q] = t;
    }
    const double len = std::hypot(double(fx), double(fz)), ux = fx / len, uz = fz / len;
    const double cornerX = ux < 0 ? nx - 1 : 0, cornerZ = uz < 0 ? nz - 1 : 0;
    for (int64_t j = 0; j < nz; ++j)
      for (int64_t i = 0; i < nx; ++i) {
        const double ideal = 2 * ((i - cornerX) * ux + (j - cornerZ) * uz);
        EXPECT_NEAR(double(first[size_t(j * nx + i)]), ideal, 1.0)
            << "front (" << fx << ", " << fz << ") particle (" << i << ", " << j << ")";
      }
  }
}

// A front along z gives the thesis' rows: the thesis meadow with explicit fronts (0, 1) for its
// +z gust and (0, -1) for its -z gust ends in the same state as without them; at 7.5 m/s (2 ticks
// a row) and at 18 m/s (5/6 of a tick a row: row 3's delay is exactly 2.5 ticks, which a front
// swept with Q32.32 ticks per row rounded to 2, the rows' exact fraction to 3: a reviewer's case).
class WindFrontAlongZ : public testing::TestWithParam<int> {};
TEST_P(WindFrontAlongZ, IsTheThesisRows) {
  Scenario plain = test::thesisMeadow();
  plain.wind.travelSpeed = Rational{GetParam(), 2};
  Scenario fronts = plain;
  fronts.wind.schedule[0].front = std::array<Rational, 2>{Rational{0, 1}, Rational{1, 1}};
  fronts.wind.schedule[2].front = std::array<Rational, 2>{Rational{0, 1}, Rational{-1, 1}};
  auto a = test::makeTyped<Fx32>(plain);
  auto b = test::makeTyped<Fx32>(fronts);
  for (int t = 0; t < 1300; ++t) {
    ASSERT_TRUE(a->step(TickInput{}).ok);
    ASSERT_TRUE(b->step(TickInput{}).ok);
  }
  const auto& pa = a->particles();
  const auto& pb = b->particles();
  EXPECT_TRUE(pa.px == pb.px && pa.pz == pb.pz && pa.vx == pb.vx && pa.vz == pb.vz);
}
INSTANTIATE_TEST_SUITE_P(WindFront, WindFrontAlongZ, testing::Values(15, 36));

// A slow front with short gusts crosses a row in many gust periods: the runs come from a column
// scan then, not one cut per period (a reviewer's 3 x 40 field at 1e-4 m/s with two one-tick
// gusts took 4 ms a tick after 20,000 ticks, growing with the tick). Checked against the
// per-column activity at tick 20,000.
TEST(WindFront, SlowFrontShortGustsStayExact) {
  Scenario s = test::thesisMeadow();
  s.field.patchesX = 40;
  s.field.patchesZ = 3;
  s.wind.travelSpeed = Rational{1, 10000};
  WindGust gust{test::r3(1, 0, 0), Rational{1, 60}};
  gust.front = std::array<Rational, 2>{Rational{1, 1}, Rational{0, 1}};
  s.wind.schedule = {gust, {test::r3(0, 0, 0), Rational{1, 60}}};
  const WindSchedule w = WindSchedule::build(s, deriveConstants(s));
  WindConstants<double> k;
  k.forceX = {1, 0};
  k.forceY = k.forceZ = {0, 0};
  k.dt = 1;
  std::vector<WindRun<double>> runs;
  computeRowWind(w, k, 20000, 1, 0, 40, &runs);
  ASSERT_FALSE(runs.empty());
  EXPECT_EQ(runs.front().begin, 0);
  EXPECT_EQ(runs.back().end, 40);
  for (const WindRun<double>& r : runs)
    for (int64_t i = r.begin; i < r.end; ++i) EXPECT_EQ(r.dvx, w.activeAt(0, i, 1, 20000) ? 1.0 : 0.0) << i;
}

// In a level-of-detail window whose columns wrap in storage, every particle gets its own lattice
// column's wind: after the window moved, particles set at rest and upright get, in one thesis
// tick, exactly (force dt) damping where the gust blows on their column and 0 where it does not.
TEST(WindFront, WindowedRowsGetTheirColumnsWind) {
  Scenario s = frontScenario(1, 1);
  s.field.patchesX = s.field.patchesZ = 301;
  s.lod.mode = LodMode::Window;
  s.lod.windowX = s.lod.windowZ = 61;
  s.particles.initialVelocity = test::r3(0, 0, 0);
  auto w = test::makeTyped<double>(s);
  TickInput moveTo;
  moveTo.hasCamera = true;
  moveTo.camera = InputVec3{int64_t(13) << 32, 0, int64_t(7) << 32};  // off the window's grid
  // The front (1, 1) from the corner (-37.5, -37.5) m reaches the window centre after about
  // 67 m / 7.5 m/s = 536 ticks: then it crosses the window.
  for (int t = 0; t < 536; ++t) ASSERT_TRUE(w->step(t == 0 ? moveTo : TickInput{}).ok);
  const LatticeWindow& win = w->particleGrid().window;
  ASSERT_NE(win.storageColumn(win.originI), 0) << "the test needs a wrapped window";
  auto& p = w->mutableParticles();
  for (size_t q = 0; q < p.px.size(); ++q) {
    p.px[q] = p.anchorX[q];
    p.py[q] = p.anchorY[q] + 1.0;
    p.pz[q] = p.anchorZ[q];
    p.vx[q] = p.vy[q] = p.vz[q] = 0;
  }
  const int64_t tick = w->tick();
  ASSERT_TRUE(w->step(TickInput{}).ok);
  const double damping = w->particleConstants().dampingPerTick, dt = 1.0 / 60;
  int blowing = 0;
  for (int64_t r = 0; r < win.sizeJ; ++r)
    for (int64_t col = 0; col < win.sizeI; ++col) {
      const size_t q = size_t(r * win.sizeI + col);
      const bool on = w->wind().activeAt(0, win.latticeColumn(col), win.latticeRow(r), tick);
      blowing += on;
      EXPECT_EQ(p.vz[q], on ? (1.0 * dt) * damping : 0.0) << "storage (" << col << ", " << r << ")";
    }
  EXPECT_GT(blowing, 0);
  EXPECT_LT(blowing, win.sizeI * win.sizeJ) << "the front should be inside the window";
}

}  // namespace
}  // namespace sg
