// Wind timing: the first tick at which each particle row receives a gust, forward and backward.
#include <gtest/gtest.h>

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
