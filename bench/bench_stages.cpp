// Per-stage benchmarks (issue 7): where a tick's time goes, per scalar, interpolation k, broad
// phase, thread count and size (22,801 = the thesis, 250,000, 1,000,000 and 4,000,000 patches),
// the target workload, and integrate + constraints against the memory-bandwidth bound.
//
//   BM_Stages/<scalar>/side:S/k:K/threads:T/brute:B
//        full ticks of the meadow with 3 bodies; counters <stage>_ms (wall clock per tick from a
//        StageObserver), patch_steps/s and bytes/patch (saveState().size() / patches)
//   BM_TargetTick     the target: fx32, k = 2, 1,000,000 patches, 3 bodies, 2 threads
//                     (>= 120 ticks/s); counter vs_target = ticks/s / 120
//   BM_BroadPhase/<scalar>/side:S/brute:B   particle-vs-body broad phase + push, all rows, 1 thread
//   BM_NarrowPhase/<scalar>                 body-body and body-terrain contacts of 3 bodies
//   BM_StateHash, BM_SaveState, BM_RestoreState /<scalar>/side:S   stateHash(), saveState(),
//                     restoreState(); counters bytes/patch and state bytes/s
//   BM_CopyBandwidth/threads:T   memcpy over 2 x 256 MiB (>> the 32 MiB L3): bytes/s counts read + write
//   BM_IntegrateConstraints/<scalar>/threads:T/avx2:V   the integrate and constraints stages at
//                     1,000,000 particles (side 1000, k = 1) with the scalar reference (V = 0) or
//                     the AVX2 kernel (V = 1; the label says which ran); bytes_per_tick = particle
//                     state those stages read and write (15 scalars per particle), bound_ms =
//                     bytes_per_tick / copy bandwidth measured in the same run, ratio_to_bound =
//                     achieved / bound (the issue asks for <= 2 for fx32); fx16 vs fx32:
//                     particle_steps/s
// Every other benchmark runs the world's default kernel (AVX2 where the CPU has it; the
// environment variable SIMGRASS_KERNEL=scalar selects the reference) and names it in its label.
// The window shift is in bench_lod.cpp (BM_WindowTick, BM_EdgeRingShift).
// Filters (docs/performance.md, "Benchmark suites"):
//   simgrass_bench --benchmark_filter='BM_Stages/fx32/side:151/'       thesis size, all variants
//   simgrass_bench --benchmark_filter='BM_TargetTick|BM_IntegrateConstraints|BM_CopyBandwidth'
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_support.h"
#include "sim/collision/body_pairs.h"
#include "sim/collision/body_particles.h"
#include "sim/world/world.h"

namespace {

using sg::ScalarKind;

using sg::bench::StageTimer;

/// The thesis meadow (0.1 m apart) at side x side patches; with three bodies rolling through it
/// (two spheres and a box, as in bench_collision.cpp) when `bodies`.
sg::Scenario meadow(int64_t side, int k, ScalarKind scalar, bool bodies, bool brute = false) {
  sg::Scenario s = sg::parseScenario(sg::defaultScenarioText(), "<built-in>", {});
  s.field.patchesX = s.field.patchesZ = side;
  s.field.spacing = sg::Rational{1, 10};
  s.particles.interpolation = k;
  s.scalar = scalar;
  if (bodies) {
    s.particles.constraintLength = sg::Rational{1, 2};
    s.bodies.particleBroadphase = brute ? sg::ParticleBroadphase::Brute : sg::ParticleBroadphase::Grid;
    s.bodies.list = sg::bench::threeRollingBodies();
  }
  return s;
}

void patchCounters(benchmark::State& state, const sg::SimWorld& world) {
  const double patches = double(world.counts().patches());
  state.counters["patches"] = patches;
  state.counters["patch_steps/s"] =
      benchmark::Counter(patches * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["bytes/patch"] = double(world.saveState().size()) / patches;
}

void stageCounters(benchmark::State& state, const StageTimer& timer) {
  for (size_t s = 0; s < size_t(sg::Stage::Count); ++s)
    if (sg::stageIsTimed(sg::Stage(s)))
      state.counters[std::string(sg::timedStageName(sg::Stage(s))) + "_ms"] =
          timer.nanos[s] / 1e6 / double(state.iterations());
}

// ---- whole ticks, split by stage -------------------------------------------------------------

void BM_Stages(benchmark::State& state, ScalarKind scalar) {
  const sg::Scenario s = meadow(state.range(0), int(state.range(1)), scalar, true, state.range(3) != 0);
  auto world = sg::makeWorld(s, int(state.range(2)));
  for (int t = 0; t < 10; ++t) world->step(sg::TickInput{});  // the bodies are rolling, the wind blowing
  StageTimer timer;
  for (auto _ : state)
    if (!world->step(sg::TickInput{}, &timer).ok) state.SkipWithError("simulation fault");
  stageCounters(state, timer);
  patchCounters(state, *world);
  state.SetLabel(sg::particleKernelName(world->particleKernel()));
}

void stageArgs(benchmark::internal::Benchmark* b) {
  // 22,801 (the thesis), 250,000, 1,000,000 and 4,000,000 patches.
  for (int64_t side : {151, 500, 1000, 2000})
    for (int k : {1, 2})
      for (int threads : {1, 2})
        for (int brute : {0, 1}) b->Args({side, k, threads, brute});
  b->ArgNames({"side", "k", "threads", "brute"})->Unit(benchmark::kMillisecond)->UseRealTime();
}
BENCHMARK_CAPTURE(BM_Stages, fx32, ScalarKind::Fx32)->Apply(stageArgs);
BENCHMARK_CAPTURE(BM_Stages, fx16, ScalarKind::Fx16)->Apply(stageArgs);
BENCHMARK_CAPTURE(BM_Stages, float, ScalarKind::Float)->Apply(stageArgs);
BENCHMARK_CAPTURE(BM_Stages, double, ScalarKind::Double)->Apply(stageArgs);

/// The target workload: "Fx32, k = 2, 1,000,000 patches, 3 bodies, 2 threads: >= 120 ticks/s".
void BM_TargetTick(benchmark::State& state) {
  constexpr double kTargetTicksPerSecond = 120;
  auto world = sg::makeWorld(meadow(1000, 2, ScalarKind::Fx32, true), 2);
  for (int t = 0; t < 10; ++t) world->step(sg::TickInput{});
  StageTimer timer;
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state)
    if (!world->step(sg::TickInput{}, &timer).ok) state.SkipWithError("simulation fault");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stageCounters(state, timer);
  patchCounters(state, *world);
  const double ticksPerSecond = double(state.iterations()) / seconds;
  state.counters["ticks/s"] = ticksPerSecond;
  state.counters["vs_target"] = ticksPerSecond / kTargetTicksPerSecond;  // >= 1: the target is met
  state.SetLabel(sg::particleKernelName(world->particleKernel()));
}
BENCHMARK(BM_TargetTick)->Unit(benchmark::kMillisecond)->UseRealTime();

// ---- stage pieces called directly ------------------------------------------------------------

template <class S>
sg::World<S>& typed(sg::SimWorld& w) {
  return dynamic_cast<sg::World<S>&>(w);
}

/// Particle-vs-body broad phase (grid: the thesis' lattice cells under each body; brute: every
/// particle) and the push out of the bodies, over all particle rows on one thread.
template <class S>
void BM_BroadPhase(benchmark::State& state) {
  const bool brute = state.range(1) != 0;
  const sg::Scenario s = meadow(state.range(0), 1, sg::ScalarTraits<S>::kind, true, brute);
  auto owned = sg::makeWorld(s, 1);
  for (int t = 0; t < 10; ++t) owned->step(sg::TickInput{});
  sg::World<S>& world = typed<S>(*owned);
  // The world's settings (World's constructor), rebuilt here: the push only reads them.
  sg::BodyParticleSettings<S> settings;
  settings.broadphase = brute ? sg::ParticleBroadphase::Brute : sg::ParticleBroadphase::Grid;
  settings.particleInvMass = S(1);
  S largest(0);
  for (const auto& b : world.bodies()) largest = b.boundingRadius > largest ? b.boundingRadius : largest;
  settings.margin = world.particleConstants().rodLength + world.lattice().jitterAmplitude + largest;
  settings.pushAllowance = largest;
  settings.anchorOriginX = world.lattice().originX;
  settings.anchorOriginZ = world.lattice().originZ;
  settings.invParticleSpacing = S(1) / world.lattice().spacing;
  sg::ParticleArrays<S> particles = world.particles();  // a copy: the world stays as it was
  const sg::ParticleGrid& grid = world.particleGrid();
  int64_t candidates = 0;
  for (auto _ : state) {
    const sg::GrassPushers<S> pushers = sg::prepareGrassPushers(world.bodies(), grid, settings);
    benchmark::DoNotOptimize(sg::pushParticlesOutOfBodies(particles, grid, pushers, settings, 0, grid.countZ, nullptr,
                                                          sg::defaultParticleKernel()));
    candidates = 0;
    for (const sg::GrassPusher<S>& p : pushers.parts)
      candidates += (p.range.a1 - p.range.a0 + 1) * (p.range.b1 - p.range.b0 + 1);
  }
  state.counters["particles"] = double(grid.size());
  state.counters["candidate_cells"] = double(candidates);
}
BENCHMARK_TEMPLATE(BM_BroadPhase, sg::Fx32)
    ->ArgsProduct({{151, 1000}, {0, 1}})
    ->ArgNames({"side", "brute"})
    ->Unit(benchmark::kMicrosecond)
    ->Name("BM_BroadPhase/fx32");
BENCHMARK_TEMPLATE(BM_BroadPhase, sg::Fx16)
    ->ArgsProduct({{151, 1000}, {0, 1}})
    ->ArgNames({"side", "brute"})
    ->Unit(benchmark::kMicrosecond)
    ->Name("BM_BroadPhase/fx16");

/// Narrow phase: contacts of every body pair and of every body with the terrain.
template <class S>
void BM_NarrowPhase(benchmark::State& state) {
  auto owned = sg::makeWorld(meadow(151, 1, sg::ScalarTraits<S>::kind, true), 1);
  for (int t = 0; t < 10; ++t) owned->step(sg::TickInput{});
  sg::World<S>& world = typed<S>(*owned);
  const auto& bodies = world.bodies();
  std::vector<sg::Contact<S>> contacts;
  for (auto _ : state) {
    contacts.clear();
    for (const auto& [i, j] : sg::bodyPairs(bodies, sg::BodyBroadphase::Brute))
      sg::collideBodies(i, bodies[size_t(i)], j, bodies[size_t(j)], contacts);
    for (size_t i = 0; i < bodies.size(); ++i) sg::collideBodyTerrain(int32_t(i), bodies[i], world.terrain(), contacts);
    benchmark::DoNotOptimize(contacts.data());
  }
  state.counters["contacts"] = double(contacts.size());
}
BENCHMARK_TEMPLATE(BM_NarrowPhase, sg::Fx32)->Unit(benchmark::kNanosecond)->Name("BM_NarrowPhase/fx32");
BENCHMARK_TEMPLATE(BM_NarrowPhase, sg::Fx16)->Unit(benchmark::kNanosecond)->Name("BM_NarrowPhase/fx16");

enum class StateOp { Hash, Save, Restore };

/// stateHash() (XXH3 over the serialised state), saveState(), restoreState().
void BM_State(benchmark::State& state, ScalarKind scalar, StateOp op) {
  auto world = sg::makeWorld(meadow(state.range(0), 1, scalar, false), 1);
  for (int t = 0; t < 10; ++t) world->step(sg::TickInput{});
  const std::vector<uint8_t> saved = world->saveState();
  for (auto _ : state) {
    switch (op) {
      case StateOp::Hash:
        benchmark::DoNotOptimize(world->stateHash());
        break;
      case StateOp::Save:
        benchmark::DoNotOptimize(world->saveState().data());
        break;
      case StateOp::Restore:
        world->restoreState(saved);
        break;
    }
  }
  state.SetBytesProcessed(int64_t(saved.size()) * int64_t(state.iterations()));
  patchCounters(state, *world);
  state.counters.erase("patch_steps/s");  // no ticks here
}
void stateSizes(benchmark::internal::Benchmark* b) {
  b->Arg(151)->Arg(500)->Arg(1000)->Arg(2000)->ArgName("side")->Unit(benchmark::kMillisecond)->UseRealTime();
}
BENCHMARK_CAPTURE(BM_State, hash / fx32, ScalarKind::Fx32, StateOp::Hash)->Apply(stateSizes)->Name("BM_StateHash/fx32");
BENCHMARK_CAPTURE(BM_State, hash / fx16, ScalarKind::Fx16, StateOp::Hash)->Apply(stateSizes)->Name("BM_StateHash/fx16");
BENCHMARK_CAPTURE(BM_State, save / fx32, ScalarKind::Fx32, StateOp::Save)->Apply(stateSizes)->Name("BM_SaveState/fx32");
BENCHMARK_CAPTURE(BM_State, restore / fx32, ScalarKind::Fx32, StateOp::Restore)
    ->Apply(stateSizes)
    ->Name("BM_RestoreState/fx32");

// ---- memory bandwidth and the particle stages against it -------------------------------------

constexpr size_t kCopyBytes = size_t(256) << 20;  // per buffer: >> the 32 MiB L3

/// Copies src to dst on `threads` threads (each its own contiguous slice).
void parallelCopy(std::vector<char>& dst, const std::vector<char>& src, int threads) {
  const size_t slice = src.size() / size_t(threads);
  std::vector<std::thread> workers;
  for (int t = 1; t < threads; ++t)
    workers.emplace_back(
        [&, t] { std::memcpy(dst.data() + slice * size_t(t), src.data() + slice * size_t(t), slice); });
  std::memcpy(dst.data(), src.data(), slice);
  for (std::thread& w : workers) w.join();
}

/// Bytes per second moved by a copy (read + write counted), the best of `repeats` copies.
double copyBandwidth(int threads, int repeats) {
  std::vector<char> src(kCopyBytes, 1), dst(kCopyBytes, 0);
  double best = 0;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    parallelCopy(dst, src, threads);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    benchmark::DoNotOptimize(dst.data());
    best = std::max(best, 2.0 * double(kCopyBytes) / s);
  }
  return best;
}

void BM_CopyBandwidth(benchmark::State& state) {
  const int threads = int(state.range(0));
  std::vector<char> src(kCopyBytes, 1), dst(kCopyBytes, 0);
  for (auto _ : state) {
    parallelCopy(dst, src, threads);
    benchmark::DoNotOptimize(dst.data());
  }
  state.SetBytesProcessed(int64_t(2 * kCopyBytes) * int64_t(state.iterations()));  // read + write
}
BENCHMARK(BM_CopyBandwidth)->Arg(1)->Arg(2)->ArgName("threads")->Unit(benchmark::kMillisecond)->UseRealTime();

/// Integrate + constraints at 1,000,000 particles. The particle state they touch, per particle and
/// tick (sim/particles/particles.h, integrate.h, rod_constraint.h): position and velocity read and
/// written (3 + 3 scalars each way), the anchor read (3) = 15 scalars, each array counted once:
/// the traffic of one ideal pass, whether the stages run as separate passes over the arrays or
/// fused row by row (sim/particles/particle_row.h; the fused pass also writes the tip
/// displacement for the patch stage, not counted here). The timer sums both stages' time (the
/// fused pass reports under Stage::Integrate).
template <class S>
void BM_IntegrateConstraints(benchmark::State& state) {
  const int threads = int(state.range(0));
  const sg::Scenario s = meadow(1000, 1, sg::ScalarTraits<S>::kind, false);
  auto world = sg::makeWorld(s, threads);
  world->setParticleKernel(state.range(1) ? sg::ParticleKernel::Avx2 : sg::ParticleKernel::Scalar);
  state.SetLabel(sg::particleKernelName(world->particleKernel()));
  for (int t = 0; t < 10; ++t) world->step(sg::TickInput{});
  const double bandwidth = copyBandwidth(threads, 3);  // same run, same thread count
  StageTimer timer;
  for (auto _ : state)
    if (!world->step(sg::TickInput{}, &timer).ok) state.SkipWithError("simulation fault");
  const double particles = double(world->counts().particles());
  const double bytesPerTick = 15.0 * double(sizeof(S)) * particles;
  const double ticks = double(state.iterations());
  const double achievedMs =
      (timer.nanos[size_t(sg::Stage::Integrate)] + timer.nanos[size_t(sg::Stage::Constraints)]) / 1e6 / ticks;
  const double boundMs = bytesPerTick / bandwidth * 1e3;
  state.counters["integrate_constraints_ms"] = achievedMs;
  state.counters["bytes_per_tick"] = bytesPerTick;
  state.counters["copy_GB/s"] = bandwidth / 1e9;
  state.counters["bound_ms"] = boundMs;
  state.counters["ratio_to_bound"] = achievedMs / boundMs;
  // Particle steps per second of these two stages alone (fx16 vs fx32: the issue asks for 1.5x).
  state.counters["particle_steps/s"] = particles / (achievedMs / 1e3);
}
void kernelArgs(benchmark::internal::Benchmark* b) {
  for (int threads : {1, 2})
    for (int avx2 : {0, 1}) b->Args({threads, avx2});
  b->ArgNames({"threads", "avx2"})->Unit(benchmark::kMillisecond)->UseRealTime();
}
BENCHMARK_TEMPLATE(BM_IntegrateConstraints, sg::Fx32)->Apply(kernelArgs)->Name("BM_IntegrateConstraints/fx32");
BENCHMARK_TEMPLATE(BM_IntegrateConstraints, sg::Fx16)->Apply(kernelArgs)->Name("BM_IntegrateConstraints/fx16");
BENCHMARK_TEMPLATE(BM_IntegrateConstraints, float)
    ->Args({1, 0})
    ->Args({2, 0})
    ->ArgNames({"threads", "avx2"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Name("BM_IntegrateConstraints/float");
BENCHMARK_TEMPLATE(BM_IntegrateConstraints, double)
    ->Args({1, 0})
    ->Args({2, 0})
    ->ArgNames({"threads", "avx2"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Name("BM_IntegrateConstraints/double");

}  // namespace
