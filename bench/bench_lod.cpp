// Level of detail (issue: LOD). The thesis copied the whole field on every row shift and its
// frame rate collapsed while the camera moved; here a shift writes only what enters.
//   BM_WindowTick/shift:0   a still tick, 1,000,000 window patches (1000 x 1000 particles, k = 1)
//   BM_WindowTick/shift:1   a tick during which the window moves one row (target: <= 1.5x still)
//   BM_EdgeRingShift/rows:R one edge-ring shift by one ring row, R rows deep: one ring row is
//                           written (cost ~ ring row length), never the R rows already there
//   build/release/bench/simgrass_bench --benchmark_filter='Window|EdgeRing'
#include <benchmark/benchmark.h>

#include <string>

#include "sim/lod/edge_ring.h"
#include "sim/world/tick_input.h"
#include "sim/world/world.h"

namespace {

constexpr int64_t kWindow = 1000;  // particles (k = 1): 1,000,000 window patches

sg::Scenario windowMeadow() {
  sg::Scenario s = sg::parseScenario(sg::defaultScenarioText(), "<built-in>", {});
  s.field.patchesX = kWindow;
  s.field.patchesZ = 4 * kWindow;  // room for thousands of one-row shifts along z
  s.field.spacing = sg::Rational{1, 10};
  s.lod.mode = sg::LodMode::Window;
  s.lod.windowX = s.lod.windowZ = kWindow;
  s.lod.centerGiven = true;
  s.lod.centerX = sg::Rational{0, 1};
  s.lod.centerZ = sg::Rational{-150, 1};  // 50 m from the field's -z end (the field is 400 m long)
  s.lod.edgeRows = 30;
  return s;
}

void BM_WindowTick(benchmark::State& state) {
  const bool shift = state.range(0) != 0;
  const sg::Scenario s = windowMeadow();
  auto world = sg::makeWorld(s, int(state.range(1)));
  sg::TickInput in;
  in.hasCamera = true;
  // The camera sits at the window centre; moving it one particle spacing (0.1 m) per tick past
  // the dead zone moves the window one row per tick.
  int64_t cameraRow = 0;
  // On particle rows (the field's rows sit at -199.95 + 0.1 j), never on a border between two.
  auto place = [&] {
    in.camera = sg::InputVec3{
        0, 0, sg::toInputRaw(*sg::add(*sg::Rational::make(-2999, 20), *sg::Rational::make(cameraRow, 10)))};
  };
  place();
  for (int t = 0; t < 5; ++t) world->step(in);
  cameraRow = 2;  // past the dead zone: from here each further spacing is one row
  place();
  world->step(in);
  const int64_t origin = world->counts().windowOriginJ;
  for (auto _ : state) {
    if (shift) {
      ++cameraRow;
      place();
    }
    if (!world->step(in).ok) state.SkipWithError("simulation fault");
  }
  const int64_t moved = world->counts().windowOriginJ - origin;
  if (shift && moved != int64_t(state.iterations()))
    state.SkipWithError(
        ("the window moved " + std::to_string(moved) + " rows in " + std::to_string(state.iterations()) + " ticks")
            .c_str());
  state.counters["rows_shifted"] = double(moved);
  state.counters["window_patches"] = double(world->counts().simulatedPatches());
}
BENCHMARK(BM_WindowTick)
    ->ArgsProduct({{0, 1}, {1, 2}})
    ->ArgNames({"shift", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_EdgeRingShift(benchmark::State& state) {
  using S = sg::Fx32;
  sg::GrassLattice<S> grass;
  grass.patchesX = grass.patchesZ = 1 << 20;
  grass.spacing = S(1) / S(4);
  grass.jitterAmplitude = S(1) / S(16);
  grass.seed = 1;
  sg::EdgeRing<S> ring;
  ring.configure(grass, 4, state.range(0));
  sg::Terrain<S> flat;
  sg::FieldMarkings<S> none;
  auto notCut = [](int64_t, int64_t) { return false; };
  sg::LatticeWindow window{4000, 4000, 301, 301, grass.patchesX, grass.patchesZ};
  ring.follow(window, flat, none, notCut, true);
  int64_t written = ring.cellsWritten;
  for (auto _ : state) {
    window.originJ += 4;  // one ring row
    ring.follow(window, flat, none, notCut, false);
  }
  state.counters["cells_per_shift"] = double(ring.cellsWritten - written) / double(state.iterations());
  state.counters["cells_held"] = double(ring.cells.size());
}
BENCHMARK(BM_EdgeRingShift)->Arg(10)->Arg(30)->Arg(100)->Arg(300)->ArgName("rows")->Unit(benchmark::kMicrosecond);

}  // namespace
