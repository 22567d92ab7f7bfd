// One full tick, per scalar, field size, interpolation k and thread count (issue: core).
// Counters: patch_steps/s (patches advanced per second) and ticks/s.
//   build/release/bench/simgrass_bench --benchmark_filter=Tick
#include <benchmark/benchmark.h>
#include <cstdio>
#include "replay/kernel_environment.h"

#include <map>
#include <memory>

#include "bench/bench_support.h"
#include "sim/world/world.h"

namespace {

void BM_Tick(benchmark::State& state, sg::ScalarKind scalar) {
  const int64_t side = state.range(0);
  const int k = int(state.range(1));
  const int threads = int(state.range(2));
  auto world = sg::makeWorld(sg::bench::plainMeadow(side, k, scalar), threads);
  // Warm up past the initial transient so the wind is blowing on part of the field.
  for (int t = 0; t < 30; ++t) world->step(sg::TickInput{});
  for (auto _ : state) {
    if (!world->step(sg::TickInput{}).ok) state.SkipWithError("simulation fault");
  }
  const double patches = double(side * side);
  state.counters["patches"] = patches;
  state.counters["patch_steps/s"] =
      benchmark::Counter(patches * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["ticks/s"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

void sizes(benchmark::internal::Benchmark* b) {
  for (int64_t side : {151, 1000})  // 22,801 (thesis) and 1,000,000 patches
    for (int k : {1, 2})
      for (int threads : {1, 2}) b->Args({side, k, threads});
  b->ArgNames({"side", "k", "threads"})->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK_CAPTURE(BM_Tick, fx32, sg::ScalarKind::Fx32)->Apply(sizes);
BENCHMARK_CAPTURE(BM_Tick, fx16, sg::ScalarKind::Fx16)->Apply(sizes);
BENCHMARK_CAPTURE(BM_Tick, float, sg::ScalarKind::Float)->Apply(sizes);
BENCHMARK_CAPTURE(BM_Tick, double, sg::ScalarKind::Double)->Apply(sizes);

}  // namespace

// BENCHMARK_MAIN with SIMGRASS_KERNEL applied first (the core reads no environment).
int main(int argc, char** argv) {
  if (!sg::applyKernelEnvironment()) {
    std::fprintf(stderr, "simgrass_bench: SIMGRASS_KERNEL: expected scalar, avx2 or auto\n");
    return 2;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
