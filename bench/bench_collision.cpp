// Body-grass collision: brute force vs the thesis' lattice grid, on the thesis case (151 x 151
// particles, 3 bodies: thesis measured 2.89 ms brute vs 0.08 ms grid) and on 1,000,000 patches.
// Counters: collision_ms (collision + response stages per tick) and collision_share (of the tick).
#include <benchmark/benchmark.h>

#include <chrono>
#include <string>

#include "bench/bench_support.h"

namespace {

void BM_BodyGrass(benchmark::State& state) {
  const int64_t side = state.range(0);
  const bool brute = state.range(1) == 1;
  sg::Scenario s = sg::parseScenario(sg::defaultScenarioText(), "<built-in>", {});
  s.field.patchesX = s.field.patchesZ = side;
  s.particles.interpolation = side > 500 ? 2 : 1;
  s.particles.constraintLength = sg::Rational{1, 2};
  s.bodies.particleBroadphase = brute ? sg::ParticleBroadphase::Brute : sg::ParticleBroadphase::Grid;
  s.bodies.list = sg::bench::threeRollingBodies();
  auto world = sg::makeWorld(s, int(state.range(2)));
  for (int t = 0; t < 10; ++t) world->step(sg::TickInput{});
  sg::bench::StageTimer timer;
  for (auto _ : state) world->step(sg::TickInput{}, &timer);
  const double collisionNs = timer.nanos[size_t(sg::Stage::Collision)] + timer.nanos[size_t(sg::Stage::Response)];
  state.counters["collision_ms"] = benchmark::Counter(collisionNs / 1e6 / double(state.iterations()));
  state.counters["particles"] = double(world->counts().particles());
}

void arguments(benchmark::internal::Benchmark* b) {
  for (int64_t side : {151, 1000})
    for (int brute : {0, 1}) b->Args({side, brute, 2});
  b->ArgNames({"side", "brute", "threads"})->Unit(benchmark::kMillisecond)->UseRealTime();
}
BENCHMARK(BM_BodyGrass)->Apply(arguments);

}  // namespace

namespace {

// 1,000 bodies on the thesis meadow (issue 15): 1,000 spheres (box 1: cubes of that half-size) of radius_cm (20: under
// the tuft tips, which stand 1 m up; 50: pressing the grass down) on a 32 x 32 grid 1.1 m apart (all over the grass:
// the meadow is 37.75 m across), body-body broad phase "sap"; `rolling` 1: rolling at (2, 0, 1) m/s (all awake, the
// contact solver runs for each), 0: at rest (asleep after half a second of warm-up; they still push the grass under
// them). The grass stage visits only the parts over each row (O(candidate particles), not O(rows x bodies)). Counters:
// meadow_ms (the same meadow without bodies, timed in the same run, interleaved tick by tick) and ratio_to_meadow.
void BM_ThousandBodies(benchmark::State& state) {
  const bool rolling = state.range(1) == 1;
  sg::Scenario s = sg::parseScenario(sg::defaultScenarioText(), "<built-in>", {});
  sg::Scenario bare = s;
  s.bodies.bodyBroadphase = sg::BodyBroadphase::SweepAndPrune;
  for (int k = 0; k < 1000; ++k) {
    const std::string name = "ball" + std::to_string(k);
    sg::BodySpec b = sg::bench::rollingSphere("ball", state.range(2), 0, 0);
    b.name = name;
    if (state.range(3) == 1) {  // a cube of the same half-size instead
      b.parts[0].type = sg::ShapeType::Box;
      const sg::Rational half{state.range(2), 100};
      b.parts[0].halfExtents = {half, half, half};
    }
    b.position[0] = sg::Rational{110 * (k % 32) - 1705, 100};  // m: -17.05 .. 17.05
    b.position[2] = sg::Rational{110 * (k / 32) - 1705, 100};
    if (!rolling) b.velocity = {sg::Rational{0, 1}, sg::Rational{0, 1}, sg::Rational{0, 1}};
    s.bodies.list.push_back(b);
  }
  const int threads = int(state.range(0));
  auto world = sg::makeWorld(s, threads);
  auto meadow = sg::makeWorld(bare, threads);
  for (int t = 0; t < 60; ++t)
    if (!world->step(sg::TickInput{}).ok || !meadow->step(sg::TickInput{}).ok)
      return state.SkipWithError("step failed");
  double bodiesNs = 0, meadowNs = 0;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    const bool ok = world->step(sg::TickInput{}).ok;
    auto t1 = std::chrono::steady_clock::now();
    state.PauseTiming();
    if (!ok || !meadow->step(sg::TickInput{}).ok) {
      state.ResumeTiming();
      state.SkipWithError("step failed");
      break;
    }
    auto t2 = std::chrono::steady_clock::now();
    state.ResumeTiming();
    bodiesNs += std::chrono::duration<double, std::nano>(t1 - t0).count();
    meadowNs += std::chrono::duration<double, std::nano>(t2 - t1).count();
  }
  state.counters["meadow_ms"] = meadowNs / 1e6 / double(state.iterations());
  state.counters["ratio_to_meadow"] = bodiesNs / meadowNs;
  state.counters["bodies"] = double(world->counts().bodies);
}
BENCHMARK(BM_ThousandBodies)
    ->Args({1, 0, 20, 0})
    ->Args({2, 0, 20, 0})
    ->Args({1, 1, 20, 0})
    ->Args({2, 1, 20, 0})
    ->Args({1, 0, 50, 0})
    ->Args({2, 0, 50, 0})
    ->Args({1, 1, 50, 0})
    ->Args({2, 1, 50, 0})
    ->Args({1, 0, 20, 1})
    ->Args({2, 0, 20, 1})
    ->Args({1, 0, 50, 1})
    ->Args({2, 0, 50, 1})
    ->ArgNames({"threads", "rolling", "radius_cm", "box"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
