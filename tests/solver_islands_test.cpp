// The contact solver's islands (sim/collision/solver_islands.h): the partition itself, and the
// promise that solving islands apart, on any number of threads, gives the bits of one sequence.
#include <gtest/gtest.h>

#include <string>

#include "sim/collision/solver_islands.h"
#include "tests/test_support.h"

namespace sg {
namespace {

Contact<Fx32> touching(int32_t a, int32_t b) {
  Contact<Fx32> c;
  c.bodyA = a;
  c.bodyB = b;
  return c;
}

TEST(SolverIslands, JoinBodiesThroughBodyContactsOnlyAndLeaveSleepersOut) {
  // Bodies 0..6: 0-2 and 2-5 touch (one island), 1 rests on the terrain, 3 is alone in the air,
  // 4 sleeps, 6 touches the terrain twice.
  std::vector<RigidBody<Fx32>> bodies(7);
  bodies[4].asleep = true;
  const std::vector<Contact<Fx32>> contacts = {touching(0, 2), touching(1, kTerrainBody), touching(2, 5),
                                               touching(6, kTerrainBody), touching(6, kTerrainBody)};
  const SolverIslands islands = solverIslands(bodies, contacts);
  ASSERT_EQ(islands.count(), 4u);
  auto list = [](std::span<const int32_t> s) { return std::vector<int32_t>(s.begin(), s.end()); };
  EXPECT_EQ(list(islands.bodiesOf(0)), (std::vector<int32_t>{0, 2, 5}));
  EXPECT_EQ(list(islands.rowsOf(0)), (std::vector<int32_t>{0, 2}));
  EXPECT_EQ(list(islands.bodiesOf(1)), (std::vector<int32_t>{1}));
  EXPECT_EQ(list(islands.rowsOf(1)), (std::vector<int32_t>{1}));
  EXPECT_EQ(list(islands.bodiesOf(2)), (std::vector<int32_t>{3}));
  EXPECT_TRUE(islands.rowsOf(2).empty());
  EXPECT_EQ(list(islands.bodiesOf(3)), (std::vector<int32_t>{6}));
  EXPECT_EQ(list(islands.rowsOf(3)), (std::vector<int32_t>{3, 4}));
}

// tests/data/solver_pile.json: 7 box columns of 1-4 boxes and 9 balls thrown into them, on a
// 40 x 40 meadow, so that islands of one to a dozen bodies merge and split from tick to tick.
Scenario pile() { return loadScenarioFile(test::sourcePath("tests/data/solver_pile.json")); }

// Each tick's state is the same on 1, 2 and 3 threads (2 and 3 solve the islands on the pool),
// and the fixed-point runs end on the hashes the solver gave before it had islands (one sweep
// over all rows; `simgrass run tests/data/solver_pile.json --ticks 160 --scalar fx32|fx16` at
// ec60f04).
template <class S>
void expectThreadsGiveTheSequencesBits(const char* scalar, uint64_t sequenceHash) {
  Scenario s = pile();
  s.scalar = ScalarTraits<S>::kind;
  validateForScalar(s, s.scalar, 0);
  World<S> one(s, 1), two(s, 2), three(s, 3);
  for (int t = 0; t < 160; ++t) {
    ASSERT_TRUE(one.step(TickInput{}).ok) << scalar << " tick " << t;
    ASSERT_TRUE(two.step(TickInput{}).ok);
    ASSERT_TRUE(three.step(TickInput{}).ok);
    ASSERT_EQ(two.stateHash(), one.stateHash()) << scalar << " tick " << t << ", 2 threads";
    ASSERT_EQ(three.stateHash(), one.stateHash()) << scalar << " tick " << t << ", 3 threads";
  }
  if (sequenceHash != 0) {
    EXPECT_EQ(one.stateHash(), sequenceHash) << scalar;
  }
}
TEST(SolverIslands, ThreadsGiveTheSequencesBitsFx32) {
  expectThreadsGiveTheSequencesBits<Fx32>("fx32", 0xdffce905493eccf4ull);
}
TEST(SolverIslands, ThreadsGiveTheSequencesBitsFx16) {
  expectThreadsGiveTheSequencesBits<Fx16>("fx16", 0x851001cfea968300ull);
}
// float and double: the same bits on every thread count (no golden: their bits are the machine's).
TEST(SolverIslands, ThreadsGiveTheSequencesBitsFloat) { expectThreadsGiveTheSequencesBits<float>("float", 0); }
TEST(SolverIslands, ThreadsGiveTheSequencesBitsDouble) { expectThreadsGiveTheSequencesBits<double>("double", 0); }

// A fixed-point fault inside one island's sub-steps, raised on whichever thread solved that
// island, is reported as the sequence reports it. Box 0 is lifted 5 m and sent down at
// 32,767.5 m/s, 0.5 m/s inside fx16's range: the first sub-step's gravity and the solve against
// the ground overflow Q16.16, in the response stage, while the other islands go on.
TEST(SolverIslands, AFaultInAnIslandIsReportedAsInTheSequence) {
  Scenario s = pile();
  s.scalar = ScalarKind::Fx16;
  validateForScalar(s, s.scalar, 0);
  const int64_t kOne = int64_t(1) << 32;
  TickInput hit;
  hit.bodies = {BodyCommand{0, BodyCommandKind::Teleport, {0, 5 * kOne, 0}},
                BodyCommand{0, BodyCommandKind::AddVelocity, {0, -(32767 * kOne + kOne / 2), 0}}};
  std::vector<std::string> reports;
  for (const int threads : {1, 2, 3}) {
    World<Fx16> w(s, threads);
    for (int t = 0; t < 30; ++t) ASSERT_TRUE(w.step(TickInput{}).ok);
    const StepResult r = w.step(hit);
    ASSERT_FALSE(r.ok) << threads << " threads";
    EXPECT_EQ(r.error.stage, Stage::Response) << r.error.message();
    reports.push_back(r.error.message());
  }
  EXPECT_EQ(reports[1], reports[0]);
  EXPECT_EQ(reports[2], reports[0]);
}

}  // namespace
}  // namespace sg
