// The state hash (sim/state/state_hash.h): its definition, written out here from a saved state's
// bytes; the same value whether the particle pass took the row groups' digests or the world takes them
// afterwards, on any thread count and kernel; and digests that never go stale.
#include <gtest/gtest.h>

#include <climits>
#include <cstdint>
#include <string>
#include <vector>

#include "tests/state_sections.h"
#include "tests/test_support.h"

namespace sg {
namespace {

template <class S>
void expectTheDocumentedHash(const Scenario& s, const std::string& file) {
  for (const int threads : {1, 2, 3}) {
    auto asked = test::makeTyped<S>(s, threads), plain = test::makeTyped<S>(s, threads);
    const size_t width = size_t(asked->particleGrid().countX);
    for (int t = 0; t < 12; ++t) {
      const TickInput input = scriptedInput(s, asked->tick());
      if (t % 3 != 2) asked->requestStateHash();  // some ticks taken by the pass, some afterwards
      ASSERT_TRUE(asked->step(input).ok);
      ASSERT_TRUE(plain->step(input).ok);
      const uint64_t expected = test::documentedStateHash(plain->saveState(), sizeof(S), width);
      ASSERT_EQ(asked->stateHash(), expected) << file << ", " << threads << " threads, tick " << t;
      ASSERT_EQ(plain->stateHash(), expected) << file << ", " << threads << " threads, tick " << t;
    }
  }
}

// The thesis meadow (1.1 MB of particles, 6 groups of 27 rows, the last of 16), a trampling blade
// meadow with bodies (TRMP), a moving level-of-detail window (toroidal rows), gust fronts crossing
// the rows (a row advanced in pieces) at interpolation k = 2, and the one-ball corpus source, in
// each scalar; and rows wider than a group.
TEST(StateHash, IsTheDocumentedHashWhetherThePassTookTheDigestsOrNot) {
  for (const char* file : {"scenarios/thesis-meadow.json", "scenarios/blade-bodies.json", "scenarios/lod-crossing.json",
                           "scenarios/wind-fronts.json", "tests/data/sgr/tiny.json"}) {
    const Scenario s = loadScenarioFile(test::sourcePath(file));
    expectTheDocumentedHash<Fx32>(s, file);
    expectTheDocumentedHash<Fx16>(s, file);
    expectTheDocumentedHash<double>(s, file);
  }
  // Rows of 4096 particles and more: a group is one row.
  Scenario wide = loadScenarioFile(test::sourcePath("tests/data/sgr/tiny.json"));
  wide.field.patchesX = 4300;
  wide.field.patchesZ = 3;
  expectTheDocumentedHash<Fx32>(wide, "4300 x 3 patches");
}

TEST(StateHash, TheScalarKernelTakesTheSameDigests) {
  const Scenario s = loadScenarioFile(test::sourcePath("scenarios/thesis-meadow.json"));
  auto vector = test::makeTyped<Fx32>(s, 2), scalar = test::makeTyped<Fx32>(s, 2);
  scalar->setParticleKernel(ParticleKernel::Scalar);
  for (int t = 0; t < 5; ++t) {
    vector->requestStateHash();
    scalar->requestStateHash();
    ASSERT_TRUE(vector->step(TickInput{}).ok);
    ASSERT_TRUE(scalar->step(TickInput{}).ok);
    EXPECT_EQ(vector->stateHash(), scalar->stateHash()) << "tick " << t;
  }
}

// Digests the pass took describe the particles of that tick only: a change to the particles after
// it (a restore, a test's edit) is hashed afresh, and a request is for the next step alone.
TEST(StateHash, DigestsTakenByThePassNeverGoStale) {
  const Scenario s = loadScenarioFile(test::sourcePath("scenarios/thesis-meadow.json"));
  auto w = test::makeTyped<Fx32>(s, 2);
  const size_t width = size_t(w->particleGrid().countX);
  ASSERT_TRUE(w->step(TickInput{}).ok);
  const std::vector<uint8_t> tick1 = w->saveState();
  const uint64_t hash1 = w->stateHash();

  w->requestStateHash();
  ASSERT_TRUE(w->step(TickInput{}).ok);
  const uint64_t hash2 = w->stateHash();
  EXPECT_NE(hash2, hash1);
  w->restoreState(tick1);
  EXPECT_EQ(w->stateHash(), hash1) << "a restore after a requested step";

  w->requestStateHash();
  ASSERT_TRUE(w->step(TickInput{}).ok);
  EXPECT_EQ(w->stateHash(), hash2);
  w->mutableParticles().vx[width + 3] += Fx32::fromRaw(1);
  EXPECT_EQ(w->stateHash(), test::documentedStateHash(w->saveState(), sizeof(Fx32), width))
      << "an edit after a requested step";
  EXPECT_NE(w->stateHash(), hash2);

  ASSERT_TRUE(w->step(TickInput{}).ok);  // not requested: the pass takes none
  EXPECT_EQ(w->stateHash(), test::documentedStateHash(w->saveState(), sizeof(Fx32), width));
}

// A pass that faults after a request leaves no digests behind: the hash of the failed world is
// still the documented hash of its bytes.
TEST(StateHash, AFaultingPassLeavesNoDigests) {
  const Scenario s = loadScenarioFile(test::sourcePath("tests/data/sgr/tiny.json"));
  auto w = test::makeTyped<Fx16>(s, 2);
  const size_t width = size_t(w->particleGrid().countX);
  ASSERT_TRUE(w->step(TickInput{}).ok);
  w->mutableParticles().vy[width + 2] = Fx16::fromRaw(INT32_MAX - 4);  // overflows Q16.16 when integrated
  w->requestStateHash();
  ASSERT_FALSE(w->step(TickInput{}).ok);
  EXPECT_EQ(w->stateHash(), test::documentedStateHash(w->saveState(), sizeof(Fx16), width));
}

}  // namespace
}  // namespace sg
