// The mower's persistent cuts and the football-field markings.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/test_support.h"

namespace sg {
namespace {

Scenario mowerField() { return loadScenarioFile(test::sourcePath("scenarios/mower-field.json")); }

std::unique_ptr<World<Fx32>> mowFor(const Scenario& s, int ticks) {
  auto w = std::make_unique<World<Fx32>>(s, 2);
  for (int t = 0; t < ticks; ++t) EXPECT_TRUE(w->step(scriptedInput(s, w->tick())).ok);
  return w;
}

TEST(Mower, CutsExactlyAlongItsPath) {
  const Scenario s = mowerField();
  auto w = mowFor(s, 600);
  const auto& p = w->patches();
  const double mowerX = w->bodies()[0].position.x().toDouble();
  ASSERT_GT(mowerX, -5.0) << "the script drives the mower across the field";
  ASSERT_GT(w->cuts().size(), 100u);
  // Every cut tuft's root lies under the deck's path: |z - 2| <= half depth 0.4 (+ jitter + a
  // spacing of slack for the blade test point) and x between the start and the mower.
  for (const auto& [ij, value] : w->cuts()) {
    const size_t q = size_t(ij.second * 151 + ij.first);
    EXPECT_EQ(p.cut[q], 1);
    EXPECT_LE(std::fabs(p.rootZ[q].toDouble() - 2.0), 0.4 + 0.075 + 0.25) << ij.first << "," << ij.second;
    EXPECT_GE(p.rootX[q].toDouble(), -15.5 - 0.25);
    EXPECT_LE(p.rootX[q].toDouble(), mowerX + 0.5 + 0.25);
  }
  // And the tufts right on the line it drove over, well behind it, are cut.
  int onLine = 0, cutOnLine = 0;
  for (size_t q = 0; q < p.cut.size(); ++q) {
    const double x = p.rootX[q].toDouble(), z = p.rootZ[q].toDouble();
    if (std::fabs(z - 2.0) < 0.2 && x > -13.0 && x < mowerX - 1.0) {
      ++onLine;
      cutOnLine += p.cut[q];
    }
  }
  EXPECT_GT(onLine, 20);
  EXPECT_EQ(cutOnLine, onLine);
  // Cut tufts are short: at most the blade height above their root (thesis scaleYMinus).
  for (const auto& [ij, value] : w->cuts()) {
    const size_t q = size_t(ij.second * 151 + ij.first);
    EXPECT_LE((p.topY[q] - p.rootY[q]).toDouble(), 0.25 + 1e-9);
  }
}

TEST(Mower, CutsArePersistentStateSavedRestoredAndHashed) {
  const Scenario s = mowerField();
  auto a = mowFor(s, 300);
  ASSERT_FALSE(a->cuts().empty());
  const auto saved = a->saveState();
  World<Fx32> b(s, 1);
  const uint64_t freshHash = b.stateHash();
  b.restoreState(saved);
  EXPECT_EQ(b.cuts(), a->cuts());
  EXPECT_EQ(b.stateHash(), a->stateHash());
  EXPECT_NE(b.stateHash(), freshHash);
  for (int t = 0; t < 300; ++t) {
    ASSERT_TRUE(a->step(scriptedInput(s, a->tick())).ok);
    ASSERT_TRUE(b.step(scriptedInput(s, b.tick())).ok);
  }
  EXPECT_EQ(a->stateHash(), b.stateHash());
  EXPECT_EQ(a->cuts(), b.cuts());

  // Damaged edit lists are refused with the byte offset of the bad entry.
  auto bad = saved;
  const size_t editsAt = bad.size() - 16 * World<Fx32>(s, 1).cuts().size() - 16 * mowFor(s, 300)->cuts().size();
  int64_t ij[2] = {151, 0};  // outside the field
  std::memcpy(bad.data() + editsAt, ij, 16);
  World<Fx32> c(s, 1);
  EXPECT_THROW(c.restoreState(bad), StateError);
}

// A mower 14 km from a small fx16 lattice's origin: its lattice index (280,000 at 20 per metre)
// is beyond Q16.16's range. It cuts nothing and must not fault: the index is the exact product's
// floor (floorOfProduct), and a fault raised by the mowing or the grass pushers' set-up is taken
// in the response stage, on the thread that raised it, for any thread count.
TEST(Mower, FarFromAnFx16LatticeCutsNothingAndRaisesNoFault) {
  nlohmann::json j = nlohmann::json::parse(std::ifstream(test::sourcePath("scenarios/mower-field.json")));
  j["scalar"] = "fx16";
  j["field"]["patchesX"] = 20;
  j["field"]["patchesZ"] = 20;
  j["field"]["spacing"] = 0.05;
  j["field"]["center"] = {-7000, 0};
  j.erase("markings");
  j["script"] = nlohmann::json::array();
  j["bodies"]["list"][0]["position"] = {7000, 0.45, 2};
  const Scenario s = parseScenario(j.dump(), "far-mower", {});
  for (int threads : {1, 2}) {
    World<Fx16> w(s, threads);
    for (int t = 0; t < 30; ++t) {
      const StepResult r = w.step(scriptedInput(s, w.tick()));
      ASSERT_TRUE(r.ok) << "threads " << threads << ", tick " << t << ": " << r.error.what;
      EXPECT_EQ(takeFixedFaults(), 0u) << "a fault left pending on the caller's thread";
    }
    EXPECT_TRUE(w.cuts().empty());
  }
}

TEST(Markings, PatchesOnTheLinesShowTheMarkingTuft) {
  const Scenario s = mowerField();
  World<Fx32> w(s, 1);
  const auto& p = w.patches();
  const int marking = s.field.atlasVariants;
  auto variantAt = [&](double x, double z) {
    const int64_t i = std::llround((x - w.lattice().originX.toDouble()) / 0.25);
    const int64_t j = std::llround((z - w.lattice().originZ.toDouble()) / 0.25);
    return p.variant[size_t(j * 151 + i)];
  };
  EXPECT_EQ(variantAt(0, 0), marking) << "halfway line";
  EXPECT_EQ(variantAt(0, 7), marking) << "halfway line";
  EXPECT_EQ(variantAt(15, 3), marking) << "goal line";
  EXPECT_EQ(variantAt(-6, 10), marking) << "touch line";
  EXPECT_EQ(variantAt(3, 0), marking) << "centre circle";
  EXPECT_NE(variantAt(7, 5), marking) << "inside the field, off the lines";
  EXPECT_NE(variantAt(1.5, 1.5), marking) << "inside the centre circle";
  EXPECT_NE(variantAt(17, 0), marking) << "outside the field";
  int marked = 0;
  for (uint8_t v : p.variant) marked += v == marking;
  // Line area: 2 x (30 + 20) x 0.5 + 20 x 0.5 + 2 pi 3 x 0.5 = 69.4 m^2 at 16 tufts per m^2: ~1110,
  // plus the tufts whose centre lies within half a spacing of a line edge.
  EXPECT_GT(marked, 1000);
  EXPECT_LT(marked, 1800);
}

TEST(Markings, AreAPureFunctionOfTheLatticeNotOfTheSeed) {
  Scenario s = mowerField();
  World<Fx32> a(s, 1);
  s.seed = 99;
  World<Fx32> b(s, 1);
  const int marking = s.field.atlasVariants;
  for (size_t q = 0; q < a.patches().variant.size(); ++q)
    ASSERT_EQ(a.patches().variant[q] == marking, b.patches().variant[q] == marking) << q;
  EXPECT_NE(a.patches().rootX[1000], b.patches().rootX[1000]) << "the jitter does depend on the seed";
}

}  // namespace
}  // namespace sg
