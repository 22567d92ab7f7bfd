// Level of detail: the simulation window follows the camera deterministically, holds exactly
// what a fresh window at its position would hold (plus the persistent mown state), keeps
// markings and cuts on any path, saves and restores mid-path, and its edge-grass ring is
// rebuilt one ring row per shift.
#include <gtest/gtest.h>

#include <cstring>
#include <set>

#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {

/// x (or z) of the centre of a 41-wide window starting at lattice column `origin` (201 patches
/// centred on 0, 0.25 m apart: column 0 at -25 m).
Rational windowCentre(int64_t origin) { return *add(Rational{-25, 1}, *Rational::make(origin + 20, 4)); }

/// A small meadow with a 41 x 41 window, a football field and a mower, and a camera track that
/// goes out diagonally and comes back.
Scenario windowedMeadow() {
  Scenario s = loadScenarioFile(test::sourcePath("scenarios/lod-crossing.json"));
  s.field.patchesX = s.field.patchesZ = 201;  // 50 m
  s.lod.windowX = s.lod.windowZ = 41;         // 10 m
  s.lod.edgeRows = 6;
  s.lod.centerGiven = true;
  s.lod.centerX = s.lod.centerZ = Rational{-18, 1};
  s.markings.length = Rational{20, 1};
  s.markings.width = Rational{12, 1};
  s.bodies.list[0].position = {Rational{-20, 1}, *Rational::make(45, 100),
                               Rational{-19, 1}};  // the mower, near the window
  s.bodies.list[1].position = {Rational{-18, 1}, *Rational::make(4, 10), Rational{-18, 1}};
  s.camera.clear();
  for (int t = 0; t <= 240; t += 2) {  // out to (+18, +18) by tick 120, back by tick 240
    const int64_t c = t <= 120 ? -18 + 36 * t / 120 : 18 - 36 * (t - 120) / 120;
    s.camera.push_back(CameraKey{t, test::r3(c, 2, c)});
  }
  return s;
}

/// The same meadow with nothing moving: the tests drive the camera themselves.
Scenario stillMeadow() {
  Scenario s = windowedMeadow();
  s.bodies.list.clear();
  s.script.clear();
  s.camera.clear();
  return s;
}

uint64_t runHash(const Scenario& s, int threads, int64_t ticks) {
  std::unique_ptr<SimWorld> w = makeWorld(s, threads);
  for (int64_t t = 0; t < ticks; ++t) EXPECT_TRUE(w->step(scriptedInput(s, w->tick())).ok);
  return w->stateHash();
}

TEST(LevelOfDetail, DiagonalCrossingGivesTheSameHashForEveryRunAndThreadCount) {
  const Scenario s = loadScenarioFile(test::sourcePath("scenarios/lod-crossing.json"));
  const int64_t ticks = test::slowBuild() ? 120 : 900;
  const uint64_t one = runHash(s, 1, ticks);
  EXPECT_EQ(runHash(s, 1, ticks), one);
  EXPECT_EQ(runHash(s, 2, ticks), one);
  EXPECT_EQ(runHash(s, 4, ticks), one);
  // The window did move, and the hash is not that of the whole field.
  std::unique_ptr<SimWorld> w = makeWorld(s, 1);
  const WorldCounts start = w->counts();
  for (int64_t t = 0; t < ticks; ++t) w->step(scriptedInput(s, w->tick()));
  EXPECT_GT(w->counts().windowOriginI, start.windowOriginI + 10);
  EXPECT_EQ(w->counts().windowOriginI - start.windowOriginI, w->counts().windowOriginJ - start.windowOriginJ);
  Scenario off = s;
  off.lod.mode = LodMode::Off;
  EXPECT_NE(runHash(off, 2, test::slowBuild() ? 12 : 60), runHash(s, 2, test::slowBuild() ? 12 : 60));
}

TEST(LevelOfDetail, TheWindowFollowsTheCameraWithADeadZoneOfOneSpacing) {
  const Scenario s = stillMeadow();
  auto w = test::makeTyped<Fx32>(s);
  const int64_t i0 = w->patchWindow().originI, centre = i0 + 20;  // 41 wide: centre column i0 + 20
  auto at = [&](Rational x) {
    TickInput in;
    in.hasCamera = true;
    in.camera = InputVec3{toInputRaw(x), toInputRaw(Rational{2, 1}), toInputRaw(Rational{-18, 1})};
    EXPECT_TRUE(w->step(in).ok);
    return w->patchWindow().originI;
  };
  const Rational spacing = s.field.spacing;
  auto column = [&](int64_t c, int64_t num = 0, int64_t den = 1) {  // x of lattice column c (+ num/den spacing)
    return *add(*add(Rational{-25, 1}, *mul(spacing, Rational{c, 1})), *mul(spacing, Rational{num, den}));
  };
  // 201 patches centred on 0: column 0 sits at x = -25. Within one spacing of the centre: still.
  EXPECT_EQ(at(column(centre + 1, 4, 10)), i0);
  EXPECT_EQ(at(column(centre - 1, -4, 10)), i0);
  // Two columns right: the window moves one (the camera is then one column right of centre).
  EXPECT_EQ(at(column(centre + 2)), i0 + 1);
  // Back by one column: inside the dead zone, nothing moves (no jitter at cell borders).
  EXPECT_EQ(at(column(centre + 1)), i0 + 1);
  // A jump of 11 columns moves the window 10 at once; past the field's edge it stops at the edge.
  EXPECT_EQ(at(column(centre + 12)), i0 + 11);
  EXPECT_EQ(at(Rational{1000, 1}), 201 - 41);
  EXPECT_EQ(at(Rational{-1000, 1}), 0);
}

/// Static data of a window patch: what a freshly generated window must hold too.
template <class S>
void expectSameStaticWindow(const World<S>& a, const World<S>& b) {
  ASSERT_EQ(a.patchWindow().originI, b.patchWindow().originI);
  ASSERT_EQ(a.patchWindow().originJ, b.patchWindow().originJ);
  EXPECT_EQ(a.patches().rootX, b.patches().rootX);
  EXPECT_EQ(a.patches().rootY, b.patches().rootY);
  EXPECT_EQ(a.patches().rootZ, b.patches().rootZ);
  EXPECT_EQ(a.patches().rotation, b.patches().rotation);
  EXPECT_EQ(a.patches().variant, b.patches().variant);
  EXPECT_EQ(a.particles().anchorX, b.particles().anchorX);
  EXPECT_EQ(a.particles().anchorY, b.particles().anchorY);
  EXPECT_EQ(a.particles().anchorZ, b.particles().anchorZ);
}

TEST(LevelOfDetail, AfterARoundTripTheWindowHoldsWhatAFreshWindowThereHolds) {
  const Scenario s = windowedMeadow();
  auto w = test::makeTyped<Fx32>(s);
  const int64_t startI = w->patchWindow().originI;
  int64_t farthest = startI;
  for (int t = 0; t < 260; ++t) {
    ASSERT_TRUE(w->step(scriptedInput(s, w->tick())).ok);
    farthest = std::max(farthest, w->patchWindow().originI);
  }
  EXPECT_GT(farthest, startI + 100) << "the camera took the window across the field";
  // A fresh world whose window starts where the round trip ended.
  Scenario fresh = s;
  fresh.lod.centerX = windowCentre(w->patchWindow().originI);
  fresh.lod.centerZ = windowCentre(w->patchWindow().originJ);
  auto f = test::makeTyped<Fx32>(fresh);
  expectSameStaticWindow(*w, *f);
  // The cut flags are the persistent state: exactly the mown patches the window holds.
  const LatticeWindow& pw = w->patchWindow();
  int64_t mownInWindow = 0;
  for (int64_t j = pw.originJ; j < pw.endJ(); ++j)
    for (int64_t i = pw.originI; i < pw.endI(); ++i) {
      const bool mown = w->cuts().count({i, j}) > 0;
      mownInWindow += mown;
      ASSERT_EQ(w->patches().cut[pw.storageIndex(i, j)], mown ? 1 : 0) << i << ", " << j;
    }
  EXPECT_GT(w->cuts().size(), 0u) << "the mower cut something";
  EXPECT_GT(mownInWindow, 0) << "the mown lane is back in the window";
}

TEST(LevelOfDetail, MarkingsAndCutsMatchTheWholeFieldOnAnyPath) {
  // Bodies do not feel the grass (grass drag off), so the mower mows the same tufts whether the
  // grass around it is simulated or not: the window and the whole field must agree on every cut,
  // and every held patch must carry the whole field's static data (markings included).
  const Scenario s = windowedMeadow();
  Scenario off = s;
  off.lod.mode = LodMode::Off;
  auto w = test::makeTyped<Fx32>(s);
  auto full = test::makeTyped<Fx32>(off);
  const int ticks = test::slowBuild() ? 80 : 240;
  int64_t mostMarkings = 0;
  for (int t = 0; t < ticks; ++t) {
    ASSERT_TRUE(w->step(scriptedInput(s, w->tick())).ok);
    ASSERT_TRUE(full->step(scriptedInput(off, full->tick())).ok);
    if (t % 20 != 19) continue;
    EXPECT_EQ(w->cuts(), full->cuts()) << "tick " << t;
    const LatticeWindow& pw = w->patchWindow();
    int64_t markings = 0;
    for (int64_t j = pw.originJ; j < pw.endJ(); ++j)
      for (int64_t i = pw.originI; i < pw.endI(); ++i) {
        const size_t a = pw.storageIndex(i, j), b = size_t(j * s.field.patchesX + i);
        ASSERT_EQ(w->patches().variant[a], full->patches().variant[b]) << i << ", " << j << " at tick " << t;
        ASSERT_EQ(w->patches().rootX[a], full->patches().rootX[b]);
        ASSERT_EQ(w->patches().cut[a], full->patches().cut[b]);
        markings += w->patches().variant[a] == 4;
      }
    mostMarkings = std::max(mostMarkings, markings);
  }
  EXPECT_GT(mostMarkings, 100) << "the window crossed the football field";
  EXPECT_GT(w->cuts().size(), 10u);
}

TEST(LevelOfDetail, SaveAndRestoreMidPathContinueBitExactly) {
  const Scenario s = windowedMeadow();
  auto a = makeWorld(s, 1);
  for (int t = 0; t < 90; ++t) ASSERT_TRUE(a->step(scriptedInput(s, a->tick())).ok);
  const std::vector<uint8_t> saved = a->saveState();
  auto b = makeWorld(s, 2);  // a fresh world, its window elsewhere
  b->restoreState(saved);
  EXPECT_EQ(b->stateHash(), a->stateHash());
  EXPECT_EQ(b->counts().windowOriginI, a->counts().windowOriginI);
  for (int t = 0; t < 90; ++t) {
    ASSERT_TRUE(a->step(scriptedInput(s, a->tick())).ok);
    ASSERT_TRUE(b->step(scriptedInput(s, b->tick())).ok);
    ASSERT_EQ(a->stateHash(), b->stateHash()) << "tick " << a->tick();
  }
  // A window origin outside the field is a bad state, not a crash.
  std::vector<uint8_t> bad = saved;
  const int64_t far = 100000;
  std::memcpy(bad.data() + bad.size() - 16, &far, 8);
  EXPECT_THROW(b->restoreState(bad), StateError);
}

TEST(LevelOfDetail, TheEdgeRingSurroundsTheWindowAndIsRebuiltOneRowPerShift) {
  const Scenario s = stillMeadow();
  auto w = test::makeTyped<Fx32>(s);
  const EdgeRing<Fx32>& ring = w->edgeRing();
  const LatticeWindow pw = w->patchWindow();
  const int64_t m = s.lod.edgeSpacing, R = s.lod.edgeRows;
  // Every visible cell lies outside the window and within R cells of its footprint; every cell
  // of the field within R - 1 cells of the footprint and outside the window is visible.
  const std::vector<size_t> visible = ring.visibleCells();
  std::set<size_t> shown(visible.begin(), visible.end());
  EXPECT_EQ(shown.size(), visible.size());
  int64_t expected = 0;
  for (int64_t b = pw.originJ / m - R + 1; b <= (pw.endJ() - 1) / m + R - 1; ++b)
    for (int64_t a = pw.originI / m - R + 1; a <= (pw.endI() - 1) / m + R - 1; ++a) {
      const bool inField = a >= 0 && b >= 0 && a * m + m / 2 < s.field.patchesX && b * m + m / 2 < s.field.patchesZ;
      const bool inHole = pw.contains(a * m + m / 2, b * m + m / 2);
      if (!inField || inHole) continue;
      ++expected;
      EXPECT_TRUE(shown.count(ring.cells.storageIndex(a, b))) << a << ", " << b;
    }
  EXPECT_GT(expected, 100);
  for (size_t q : visible) {
    const int64_t a = ring.cells.latticeColumn(int64_t(q) % ring.cells.sizeI);
    const int64_t b = ring.cells.latticeRow(int64_t(q) / ring.cells.sizeI);
    EXPECT_FALSE(pw.contains(a * m + m / 2, b * m + m / 2));
  }
  // Move the camera m patches along +z at a time: each ring shift writes one ring row, however
  // deep the ring is.
  int64_t shifts = 0, written = ring.cellsWritten;
  for (int step = 1; step <= 12; ++step) {
    TickInput in;
    in.hasCamera = true;
    in.camera = InputVec3{toInputRaw(Rational{-18, 1}), 0, toInputRaw(*add(Rational{-18, 1}, Rational{step, 1}))};
    const int64_t before = ring.cells.originJ;
    ASSERT_TRUE(w->step(in).ok);
    if (ring.cells.originJ == before) continue;
    ASSERT_EQ(ring.cells.originJ, before + 1);
    ++shifts;
    EXPECT_EQ(ring.cellsWritten - written, ring.cells.sizeI) << "one ring row";
    written = ring.cellsWritten;
  }
  EXPECT_GE(shifts, 2);
  // And what it holds equals a ring generated from scratch at the new place.
  Scenario fresh = s;
  fresh.lod.centerX = windowCentre(w->patchWindow().originI);
  fresh.lod.centerZ = windowCentre(w->patchWindow().originJ);
  auto f = test::makeTyped<Fx32>(fresh);
  ASSERT_EQ(f->edgeRing().cells.originJ, ring.cells.originJ);
  for (size_t q : ring.visibleCells()) {
    EXPECT_EQ(ring.x[q], f->edgeRing().x[q]);
    EXPECT_EQ(ring.z[q], f->edgeRing().z[q]);
    EXPECT_EQ(ring.rotation[q], f->edgeRing().rotation[q]);
    EXPECT_EQ(ring.variant[q], f->edgeRing().variant[q]);
  }
}

TEST(LevelOfDetail, OffIsTheWholeFieldAndTheWindowCanBeAsLargeAsTheField) {
  Scenario s = test::thesisMeadow();
  s.lod.mode = LodMode::Window;
  s.lod.windowX = s.lod.windowZ = 1000;  // larger than the field: clamped to it
  auto w = makeWorld(s, 1);
  EXPECT_EQ(w->counts().windowPatchesX, 151);
  EXPECT_EQ(w->counts().particlesX, 151);
  // The state hash differs from lod off only by the window's origin and the fingerprint; the
  // particles evolve identically.
  Scenario off = test::thesisMeadow();
  auto a = test::makeTyped<Fx32>(s), b = test::makeTyped<Fx32>(off);
  for (int t = 0; t < 30; ++t) {
    a->step(scriptedInput(s, t));
    b->step(scriptedInput(off, t));
  }
  EXPECT_EQ(a->particles().px, b->particles().px);
  EXPECT_EQ(a->particles().vy, b->particles().vy);
}

TEST(LevelOfDetail, CompareReportsTheWindowsErrorAndSpeedUp) {
  // The whole field recorded, replayed under lod=window: the grass the window leaves out is the
  // error (nonzero), the window is the speed-up; lod=off must be bit-identical to the recording.
  TempDir dir;
  const std::string run = dir.file("off.sgr");
  const int ticks = test::slowBuild() ? 6 : 40;
  const CliResult rec = runCli("record --variant lod=off " + quote(test::sourcePath("scenarios/lod-crossing.json")) +
                               " -o " + quote(run) + " --ticks " + std::to_string(ticks));
  ASSERT_EQ(rec.exitCode, 0) << rec.describe();
  const CliResult cmp = runCli("compare " + quote(run) + " --variant lod=window --variant lod=off,threads=2 --json");
  ASSERT_EQ(cmp.exitCode, 0) << cmp.describe();
  const json j = parseJson(cmp);
  ASSERT_EQ(j["variants"].size(), 2u);
  const json& window = j["variants"][0];
  EXPECT_EQ(window["status"], "differs");
  EXPECT_GT(window["tipMax"].get<double>(), 0.01);
  EXPECT_EQ(window["firstDivergentTick"], 1);
  EXPECT_EQ(window["bodyPositionMax"].get<double>(), 0.0) << "bodies do not feel the grass";
  EXPECT_EQ(j["variants"][1]["status"], "identical");
  // The speed-up is reported (msPerTick per row), not asserted: speed targets live in bench/.
  EXPECT_GT(window["msPerTick"].get<double>(), 0.0);
}

}  // namespace
}  // namespace sg
