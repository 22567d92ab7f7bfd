// Bit-exact promises: golden state hashes (committed, identical for GCC and Clang, Debug and
// Release, any thread count), save -> restore -> continue == uninterrupted, and clear errors
// for states that do not belong to the world.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/state_sections.h"
#include "tests/test_support.h"

namespace sg {
namespace {

struct GoldenCase {
  std::string scenario;
  std::string scalar;
};
void PrintTo(const GoldenCase& c, std::ostream* os) { *os << c.scenario << " " << c.scalar; }

nlohmann::json goldens() {
  std::ifstream in(test::sourcePath("tests/golden/state_hashes.json"));
  return nlohmann::json::parse(in);
}

/// Every committed golden: scenario and scalar (tests/golden/state_hashes.json). float and double
/// too: with -ffp-contract=off, no Eigen SIMD and no libm in the step they are the same IEEE
/// operations in the same order on every build and architecture (docs/determinism.md).
const std::vector<GoldenCase> kGoldenCases = [] {
  std::vector<GoldenCase> cases;
  for (const char* scenario :
       {"thesis-meadow", "hilly-meadow", "thesis-bodies", "mower-field", "lod-crossing", "blade-bodies", "wind-fronts"})
    for (const char* scalar : {"fx32", "fx16", "float", "double"}) cases.push_back({scenario, scalar});
  return cases;
}();

/// A test name from a golden case ("thesis_meadow_fx32").
std::string caseName(const GoldenCase& c) {
  std::string n = c.scenario + "_" + c.scalar;
  for (char& ch : n)
    if (ch == '-') ch = '_';
  return n;
}

std::string hex(uint64_t h) {
  char buf[19];
  std::snprintf(buf, sizeof buf, "%016llx", (unsigned long long)h);
  return buf;
}

std::unique_ptr<SimWorld> build(const GoldenCase& c, int threads) {
  Scenario s = loadScenarioFile(test::sourcePath("scenarios/" + c.scenario + ".json"));
  s.scalar = *parseScalarKind(c.scalar);
  return makeWorld(s, threads);
}

Scenario scenarioOf(const GoldenCase& c) {
  Scenario s = loadScenarioFile(test::sourcePath("scenarios/" + c.scenario + ".json"));
  s.scalar = *parseScalarKind(c.scalar);
  return s;
}

/// Runs with the scenario's scripted inputs (empty for scenarios without a script).
void runTicks(SimWorld& w, int64_t ticks, const Scenario& s = test::thesisMeadow()) {
  for (int64_t t = 0; t < ticks; ++t) ASSERT_TRUE(w.step(scriptedInput(s, w.tick())).ok) << "tick " << w.tick();
}

class GoldenHash : public ::testing::TestWithParam<std::tuple<GoldenCase, int>> {};

TEST_P(GoldenHash, MatchesCommittedHashAfter600Ticks) {
  const auto& [c, threads] = GetParam();
  // The sanitizer build (Clang) checks that its code reaches every golden, on two threads; that
  // the thread count changes no bit is the release build's check (1, 2 and 4 here, and
  // Determinism.*): 24 s of the sanitizer build's test time saved.
  if (test::slowBuild() && threads != 2) GTEST_SKIP() << "the sanitizer build runs the 2-thread goldens";
  const nlohmann::json g = goldens();
  const std::string expected = g.at(c.scenario + "/" + c.scalar);
  auto w = build(c, threads);
  runTicks(*w, g.at("ticks").get<int64_t>(), scenarioOf(c));
  EXPECT_EQ(hex(w->stateHash()), expected)
      << c.scenario << " " << c.scalar << " with " << threads
      << " threads. If the physics was meant to change, run .ci/update-goldens and say why in the commit.";
}

INSTANTIATE_TEST_SUITE_P(ScenariosScalarsThreads, GoldenHash,
                         ::testing::Combine(::testing::ValuesIn(kGoldenCases), ::testing::Values(1, 2, 4)),
                         [](const auto& info) {
                           return caseName(std::get<0>(info.param)) + "_threads" +
                                  std::to_string(std::get<1>(info.param));
                         });

// The scalar reference kernel must reach the same goldens (the default is the AVX2 kernel on
// CPUs that have it; tests/particle_kernel_test.cpp compares the two tick by tick).
class GoldenHashScalarKernel : public ::testing::TestWithParam<GoldenCase> {};

TEST_P(GoldenHashScalarKernel, MatchesCommittedHashAfter600Ticks) {
  const GoldenCase c = GetParam();
  const nlohmann::json g = goldens();
  auto w = build(c, 2);
  w->setParticleKernel(ParticleKernel::Scalar);
  runTicks(*w, g.at("ticks").get<int64_t>(), scenarioOf(c));
  EXPECT_EQ(hex(w->stateHash()), g.at(c.scenario + "/" + c.scalar).get<std::string>()) << c.scenario << " " << c.scalar;
}

INSTANTIATE_TEST_SUITE_P(Goldens, GoldenHashScalarKernel, ::testing::ValuesIn(kGoldenCases),
                         [](const auto& info) { return caseName(info.param); });

class SaveRestore : public ::testing::TestWithParam<GoldenCase> {};

TEST_P(SaveRestore, RestoreAtTick300ContinuesToTheGoldenHash) {
  const GoldenCase c = GetParam();
  const nlohmann::json g = goldens();
  auto first = build(c, 2);
  runTicks(*first, 300, scenarioOf(c));
  const std::vector<uint8_t> saved = first->saveState();
  EXPECT_EQ(test::documentedStateHash(
                saved, first->scalar() == ScalarKind::Fx16 || first->scalar() == ScalarKind::Float ? 4 : 8,
                size_t(first->counts().particlesX)),
            first->stateHash())
      << "the hash is of the saved bytes (state_hash.h)";

  auto fresh = build(c, 1);  // a different thread count on purpose
  fresh->restoreState(saved);
  EXPECT_EQ(fresh->tick(), 300);
  EXPECT_EQ(fresh->stateHash(), first->stateHash());
  runTicks(*fresh, 300, scenarioOf(c));
  EXPECT_EQ(hex(fresh->stateHash()), g.at(c.scenario + "/" + c.scalar).get<std::string>());
}

INSTANTIATE_TEST_SUITE_P(Goldens, SaveRestore, ::testing::ValuesIn(kGoldenCases),
                         [](const auto& info) { return caseName(info.param); });

// float and double promise only same-binary reproducibility, but for any thread count.
TEST(FloatDeterminism, SameHashForOneTwoAndFourThreads) {
  for (const char* scalar : {"float", "double"}) {
    uint64_t reference = 0;
    for (int threads : {1, 2, 4}) {
      auto w = build({"thesis-meadow", scalar}, threads);
      runTicks(*w, 200);
      if (threads == 1) reference = w->stateHash();
      EXPECT_EQ(w->stateHash(), reference) << scalar << " with " << threads << " threads";
    }
  }
}

TEST(Determinism, EveryTickHashIdenticalAcrossRunsAndThreadCounts) {
  auto a = build({"thesis-meadow", "fx32"}, 1);
  auto b = build({"thesis-meadow", "fx32"}, 3);
  const TickInput input;
  for (int t = 0; t < 120; ++t) {
    ASSERT_TRUE(a->step(input).ok);
    ASSERT_TRUE(b->step(input).ok);
    ASSERT_EQ(a->stateHash(), b->stateHash()) << "diverged at tick " << a->tick();
  }
  b->setThreads(2);  // changing the thread count mid-run changes nothing either
  for (int t = 0; t < 30; ++t) {
    ASSERT_TRUE(a->step(input).ok);
    ASSERT_TRUE(b->step(input).ok);
  }
  EXPECT_EQ(a->stateHash(), b->stateHash());
}

TEST(Determinism, HashChangesWhenTheStateChanges) {
  auto a = build({"thesis-meadow", "fx32"}, 1);
  const uint64_t h0 = a->stateHash();
  ASSERT_TRUE(a->step(TickInput{}).ok);
  EXPECT_NE(a->stateHash(), h0) << "the tick counter and the particles are part of the hash";
  auto& w = dynamic_cast<World<Fx32>&>(*a);
  const uint64_t h1 = w.stateHash();
  w.mutableParticles().vz[12345] += Fx32::epsilon();
  EXPECT_NE(w.stateHash(), h1) << "one ulp of one velocity changes the hash";
}

// ---- bad saved states: one clear error with the byte offset ------------------------------------

class BadState : public ::testing::Test {
 protected:
  void SetUp() override {
    world = build({"thesis-meadow", "fx32"}, 1);
    runTicks(*world, 3);
    good = world->saveState();
  }
  void expectError(const std::vector<uint8_t>& bytes, uint64_t offset, const std::string& fragment) {
    auto fresh = build({"thesis-meadow", "fx32"}, 1);
    try {
      fresh->restoreState(bytes);
      FAIL() << "accepted a bad state; expected an error at byte " << offset;
    } catch (const StateError& e) {
      EXPECT_EQ(e.offset(), offset) << e.what();
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  }
  std::unique_ptr<SimWorld> world;
  std::vector<uint8_t> good;
};

// Offsets in a state (sim/state/state_format.h): magic 0..7, HEAD tag 8, length 12, payload 20:
// version 20, scalar 24, k 25, fingerprint 28, tick 36, particle count 44, body count 52.
TEST_F(BadState, TruncatedMagic) { expectError({good.begin(), good.begin() + 5}, 5, "magic"); }
TEST_F(BadState, WrongMagic) {
  auto b = good;
  b[0] = 'X';
  expectError(b, 0, "magic");
}
TEST_F(BadState, AVersionOneStateNamesItsVersion) {
  auto b = good;
  b[7] = '1';
  expectError(b, 7, "version 2");
}
TEST_F(BadState, TruncatedHeadSection) {
  expectError({good.begin(), good.begin() + 30}, 12, "length for section 'HEAD'");
}
TEST_F(BadState, WrongVersion) {
  auto b = good;
  b[20] = 99;
  expectError(b, 20, "version");
}
TEST_F(BadState, WrongScalar) {
  auto b = good;
  b[24] = uint8_t(ScalarKind::Fx16);
  expectError(b, 24, "fx32");
}
TEST_F(BadState, OtherScenario) {
  auto b = good;
  b[28] ^= 1;
  expectError(b, 28, "same scenario");
}
TEST_F(BadState, NegativeTick) {
  auto b = good;
  b[43] = 0x80;
  expectError(b, 36, "non-negative tick");
}
TEST_F(BadState, ParticleCount) {
  auto b = good;
  b[44] ^= 1;
  expectError(b, 44, "particles");
}
TEST_F(BadState, SectionOutOfOrder) {
  auto b = good;
  const test::StateSection part = test::findSection(b, "PART");
  std::memcpy(b.data() + part.tagAt, "BODY", 4);
  expectError(b, part.tagAt, "section 'PART', got 'BODY'");
}
TEST_F(BadState, SectionOfTheWrongSize) {
  auto b = good;
  const test::StateSection part = test::findSection(b, "PART");
  b[part.tagAt + 4] ^= 8;
  expectError(b, part.tagAt + 4, "section 'PART' of");
}
TEST_F(BadState, ExtraBytes) {
  auto b = good;
  b.push_back(0);
  expectError(b, good.size(), "end of the state");
}
TEST_F(BadState, EveryTruncationIsRefusedAtOrBeforeTheCut) {
  auto fresh = build({"thesis-meadow", "fx32"}, 1);
  const uint64_t before = fresh->stateHash();
  for (size_t cut = 0; cut < good.size(); cut += (cut < 200 || good.size() - cut < 200) ? 1 : 997) {
    try {
      fresh->restoreState(std::span<const uint8_t>(good.data(), cut));
      ADD_FAILURE() << "accepted a state cut at byte " << cut;
    } catch (const StateError& e) {
      EXPECT_LE(e.offset(), cut) << e.what();
    }
  }
  EXPECT_EQ(fresh->stateHash(), before) << "a refused state changes nothing";
}
TEST_F(BadState, FieldsAreLittleEndianWhateverTheHost) {
  // The canonical form: tick and particle count read byte by byte, low byte first.
  uint64_t tick = 0, particles = 0;
  for (int i = 7; i >= 0; --i) {
    tick = tick << 8 | good[size_t(36 + i)];
    particles = particles << 8 | good[size_t(44 + i)];
  }
  EXPECT_EQ(int64_t(tick), world->tick());
  EXPECT_EQ(int64_t(particles), world->counts().particles());
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(good.data()), 12), std::string("SGSTATE2HEAD"));
}
// Float and double states: a NaN, an infinity or a 1e45 restored would reach the next step as
// undefined behaviour (a float-to-int64 cell lookup), not as a fault; refused at its byte, with
// the world left as it was. Found by tests/fuzz/state_restore_fuzz (its crashes/ folder).
TEST(BadFloatState, NonFiniteOrHugeValuesAreRefusedAtTheirByte) {
  for (const char* scalar : {"double", "float"}) {
    SCOPED_TRACE(scalar);
    auto world = build({"thesis-bodies", scalar}, 1);
    runTicks(*world, 3);
    const std::vector<uint8_t> good = world->saveState();
    const size_t width = std::string(scalar) == "double" ? 8 : 4;
    auto poke = [&](std::vector<uint8_t>& b, size_t at, double v) {
      if (width == 8) {
        std::memcpy(&b[at], &v, 8);
      } else {
        const float f = float(v);
        std::memcpy(&b[at], &f, 4);
      }
    };
    const struct {
      const char* section;
      size_t value;  ///< which value of the section's payload
      double v;
      const char* fragment;
    } cases[] = {{"PART", 0, std::nan(""), "a finite particle position or velocity within +-2^48"},
                 {"PART", 7, -INFINITY, "a finite particle position or velocity within +-2^48"},
                 {"PART", 3, 3e14, "a finite particle position or velocity within +-2^48"},
                 {"BODY", 0, -2.4e37, "a finite body pose or velocity within +-2^48"},
                 {"BODY", 9, std::nan(""), "a finite body pose or velocity within +-2^48"}};
    for (const auto& c : cases) {
      auto b = good;
      const size_t at = test::findSection(b, c.section).payloadAt + c.value * width;
      poke(b, at, c.v);
      const uint64_t before = world->stateHash();
      try {
        world->restoreState(b);
        ADD_FAILURE() << "accepted " << c.v << " in " << c.section;
      } catch (const StateError& e) {
        EXPECT_EQ(e.offset(), at) << e.what();
        EXPECT_NE(std::string(e.what()).find(c.fragment), std::string::npos) << e.what();
      }
      EXPECT_EQ(world->stateHash(), before);
    }
    // 2^48 itself is allowed (and a plain restore of the saved state still works).
    auto edge = good;
    poke(edge, test::findSection(edge, "PART").payloadAt, 281474976710656.0);
    EXPECT_NO_THROW(world->restoreState(edge));
    EXPECT_NO_THROW(world->restoreState(good));
  }
}

// A body's still-tick count outside 0..ticksToSleep was silently clamped to 0 (a negative one),
// or overflowed the next count (INT32_MAX): refused at its byte. Found by state_restore_fuzz.
TEST(BadBodyState, StillTickCountOutOfRangeIsRefusedAtItsByte) {
  auto world = build({"thesis-bodies", "fx32"}, 1);
  runTicks(*world, 3);
  const std::vector<uint8_t> good = world->saveState();
  const size_t at = test::findSection(good, "BODY").payloadAt + 13 * sizeof(int64_t);  // body 0's count
  for (const int32_t bad : {-1, INT32_MIN, INT32_MAX}) {
    auto b = good;
    std::memcpy(&b[at], &bad, 4);
    try {
      world->restoreState(b);
      ADD_FAILURE() << "accepted a still-tick count of " << bad;
    } catch (const StateError& e) {
      EXPECT_EQ(e.offset(), at) << e.what();
      EXPECT_NE(std::string(e.what()).find("a still-tick count from 0 to "), std::string::npos) << e.what();
    }
  }
}

TEST_F(BadState, FailedRestoreLeavesTheWorldUsable) {
  auto b = good;
  b[0] = 'X';
  const uint64_t before = world->stateHash();
  EXPECT_THROW(world->restoreState(b), StateError);
  EXPECT_EQ(world->stateHash(), before);
  EXPECT_TRUE(world->step(TickInput{}).ok);
}

}  // namespace
}  // namespace sg
