// The contact solver's islands (sim/collision/solver_islands.h): the partition itself, and the
// promise that solving islands apart, on any number of threads, gives the bits of one sequence.
#include <gtest/gtest.h>
#include <xxhash.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

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

// Steps `s` (scalar S, its script included) on one thread and on each of `threads`, comparing every
// tick's hash; at each checkpoint (tick, hash; ascending) the one-thread state must be the pinned
// one. First pinned as the state the solver gave before it had islands (one sweep over all rows,
// built at ec60f04; the piles ask for 3 sweeps, so the island's 6 left them alone); re-pinned where
// the physics changed on purpose, from the one-thread run whose thread-count checks passed:
// 2026-11-28, a slipping contact's friction turned opposite the slip and a body rolling on one
// point kept awake; then a sphere's speculative rows kept only where its path reaches the other
// part. XXH3-64 of the saved bytes. Stops after the last checkpoint.
template <class S>
void expectThreadsGiveTheSequencesBits(Scenario s, std::vector<int> threads,
                                       std::vector<std::pair<int, uint64_t>> checkpoints, const char* what) {
  s.scalar = ScalarTraits<S>::kind;
  validateForScalar(s, s.scalar, 0);
  World<S> one(s, 1);
  std::vector<std::unique_ptr<World<S>>> others;
  for (const int t : threads) others.push_back(std::make_unique<World<S>>(s, t));
  for (const auto& [tick, pinned] : checkpoints) {
    while (one.tick() < tick) {
      const int64_t t = one.tick();
      ASSERT_TRUE(one.step(scriptedInput(s, t)).ok) << what << " tick " << t;
      for (size_t k = 0; k < others.size(); ++k) {
        ASSERT_TRUE(others[k]->step(scriptedInput(s, t)).ok);
        ASSERT_EQ(others[k]->stateHash(), one.stateHash()) << what << " tick " << t << ", " << threads[k] << " threads";
      }
    }
    if (pinned != 0) {
      // Pinned as format 1 hashed a state, one XXH3 stream over its saved bytes (the bytes are
      // unchanged; stateHash() now hashes rows, sim/state/state_hash.h).
      const std::vector<uint8_t> saved = one.saveState();
      EXPECT_EQ(XXH3_64bits(saved.data(), saved.size()), pinned) << what << " at tick " << tick;
    }
  }
}

// tests/data/solver_pile.json on 1, 2 and 3 threads (2 and 3 solve its islands on the pool).
TEST(SolverIslands, ThreadsGiveTheSequencesBitsFx32) {
  expectThreadsGiveTheSequencesBits<Fx32>(pile(), {2, 3}, {{160, 0x9e413119af9ade4eull}}, "fx32");
}
TEST(SolverIslands, ThreadsGiveTheSequencesBitsFx16) {
  expectThreadsGiveTheSequencesBits<Fx16>(pile(), {2, 3}, {{160, 0xcdc7045ea92d15edull}}, "fx16");
}
// float and double: the same bits on every thread count (no golden: their bits are the machine's).
TEST(SolverIslands, ThreadsGiveTheSequencesBitsFloat) {
  expectThreadsGiveTheSequencesBits<float>(pile(), {2, 3}, {{160, 0}}, "float");
}
TEST(SolverIslands, ThreadsGiveTheSequencesBitsDouble) {
  expectThreadsGiveTheSequencesBits<double>(pile(), {2, 3}, {{160, 0}}, "double");
}

// tests/data/solver_pile_large.json: 200 bodies, over 500 rows, pairs of several points and sliding
// pairs, and its script's commands. The small pile is too small for the pool to prepare its rows,
// or find its terrain contacts, in more than one range (a range needs 32 rows or awake bodies): a
// range that cut a body pair in two passed every other test (an independent review's mutant). The
// sanitizer build stops at tick 60.
Scenario largePile() { return loadScenarioFile(test::sourcePath("tests/data/solver_pile_large.json")); }
TEST(SolverIslands, ALargePileIsPreparedInRangesWithTheSequencesBitsFx32) {
  std::vector<std::pair<int, uint64_t>> at = {{60, 0xd66b051a3162de2eull}, {120, 0x84b13ce1ebf0fef4ull}};
  if (test::slowBuild()) at.pop_back();
  expectThreadsGiveTheSequencesBits<Fx32>(largePile(), {2}, at, "fx32");
}
TEST(SolverIslands, ALargePileIsPreparedInRangesWithTheSequencesBitsFx16) {
  std::vector<std::pair<int, uint64_t>> at = {{60, 0xdd16d93ec8e0d68aull}, {120, 0xc682f07f2f3a0ceull}};
  if (test::slowBuild()) at.pop_back();
  expectThreadsGiveTheSequencesBits<Fx16>(largePile(), {2}, at, "fx16");
}

// A fixed-point fault inside one island's sub-steps, raised on whichever thread solved that
// island, is reported as the sequence reports it. Box 0 is put 0.2 m into the ground and sent
// down at 32,767.5 m/s, 0.5 m/s inside fx16's range: the soft push-out's bias (-3 m/s) added to
// that approach overflows Q16.16 in the solve, in the response stage, while the other islands go
// on. (Lifted 5 m instead, the solve used to overflow in the box's spin between rows; fx16 now
// holds a solve's spin within 8,191 rad/s, contact_solver.cpp turnBy, and that run goes on.)
TEST(SolverIslands, AFaultInAnIslandIsReportedAsInTheSequence) {
  Scenario s = pile();
  s.scalar = ScalarKind::Fx16;
  validateForScalar(s, s.scalar, 0);
  const int64_t kOne = int64_t(1) << 32;
  TickInput hit;
  hit.bodies = {BodyCommand{0, BodyCommandKind::Teleport, {0, 0, 0}},
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

// The same for the terrain contacts, found per range of bodies on the pool: a body of the large
// pile teleported 32,767 m down overflows Q16.16 in its terrain contact (its depth under the
// ground), inside a range that a worker may run, while 200 bodies keep the ranges several.
TEST(SolverIslands, AFaultInATerrainContactIsReportedAsInTheSequence) {
  Scenario s = largePile();
  s.scalar = ScalarKind::Fx16;
  validateForScalar(s, s.scalar, 0);
  const int64_t kOne = int64_t(1) << 32;
  std::vector<std::string> reports;
  for (const int threads : {1, 2}) {
    World<Fx16> w(s, threads);
    for (int t = 0; t < 10; ++t) ASSERT_TRUE(w.step(scriptedInput(s, w.tick())).ok);
    TickInput drop = scriptedInput(s, w.tick());
    drop.bodies.push_back(BodyCommand{150, BodyCommandKind::Teleport, {0, -32767 * kOne, 0}});
    const StepResult r = w.step(drop);
    ASSERT_FALSE(r.ok) << threads << " threads";
    EXPECT_EQ(r.error.stage, Stage::Collision) << r.error.message();
    reports.push_back(r.error.message());
  }
  EXPECT_EQ(reports[1], reports[0]);
}

}  // namespace
}  // namespace sg
