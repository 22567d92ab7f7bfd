// Recording and seeking (issue: record/replay). On the default scenario (the thesis meadow,
// 22,801 tufts) with a CHCK every tick and a SNAP every 300:
//   BM_RecordTick/record:0  one tick, not recording (the baseline)
//   BM_RecordTick/record:1  one tick recorded: INPT delta, XXH3 state hash, amortised zstd snapshot,
//                           one write(2) to the kernel. Target: at most 5% over the baseline.
//   BM_Seek                 seek to the tick just before the next snapshot (the worst case: one
//                           snapshot restore + snapshotEvery - 1 ticks)
//   BM_Snapshot             one zstd snapshot; counters give raw and compressed bytes per
//                           1,000,000 patches
//   BM_StateDigest          XXH3-64 (the package's dispatching entry point, as the state hash
//                           calls it) over 32 KB (one array of a row group, in L1), 196 KB (a
//                           group's six arrays, in L2) and 1.1 MB (the thesis meadow's particle
//                           state): the hash's own speed, which bounds what a CHCK every tick costs
//   build/release/bench/simgrass_bench --benchmark_filter='Record|Seek|Snapshot|StateDigest'
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <memory>

#include "replay/format/sgr_reader.h"
#include "replay/format/sgr_writer.h"
#include "replay/player.h"
#include "replay/recorder.h"
#include "sim/state/state_hash.h"

namespace {

std::string scratchFile(const char* name) {
  return (std::filesystem::temp_directory_path() /
          (std::string("simgrass-bench-") + std::to_string(getpid()) + "-" + name))
      .string();
}

void BM_RecordTick(benchmark::State& state) {
  const bool recording = state.range(0) != 0;
  const int threads = int(state.range(1));
  const sg::Scenario s = sg::parseScenario(sg::defaultScenarioText(), "<built-in>", {});
  auto world = sg::makeWorld(s, threads);
  const std::string path = scratchFile("record.sgr");
  std::unique_ptr<sg::Recorder> recorder;
  if (recording)
    recorder =
        std::make_unique<sg::Recorder>(path, s, std::vector<sg::sgr::EmbeddedFile>{}, *world, sg::RecordSettings{});
  for (auto _ : state) {
    const sg::TickInput input = sg::scriptedInput(s, world->tick());
    const sg::StepResult r = recording ? recorder->step(input) : world->step(input);
    if (!r.ok) state.SkipWithError("simulation fault");
  }
  if (recorder) {
    recorder->finish();
    state.counters["bytes/tick"] = double(recorder->bytesWritten()) / double(state.iterations());
  }
  std::filesystem::remove(path);
}
BENCHMARK(BM_RecordTick)
    ->ArgsProduct({{0, 1}, {1, 2}})
    ->ArgNames({"record", "threads"})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime()
    ->MinTime(2.0);

void BM_Seek(benchmark::State& state) {
  const sg::Scenario s = sg::parseScenario(sg::defaultScenarioText(), "<built-in>", {});
  const std::string path = scratchFile("seek.sgr");
  sg::RecordSettings settings;
  const int64_t ticks = 2 * settings.snapshotEvery;
  {
    auto world = sg::makeWorld(s, 1);
    sg::Recorder recorder(path, s, {}, *world, settings);
    for (int64_t t = 0; t < ticks; ++t) recorder.step(sg::scriptedInput(s, world->tick()));
    recorder.finish();
  }
  const sg::sgr::Recording rec = sg::sgr::readRecording(path);
  sg::Player player(rec);
  const int64_t target = 2 * settings.snapshotEvery - 1;
  for (auto _ : state) {
    player.seek(0);  // away from the target, so each seek restores the snapshot at 300
    if (!player.seek(target).ok) state.SkipWithError("seek failed");
  }
  state.counters["ticks_stepped"] = double(target - settings.snapshotEvery);
  std::filesystem::remove(path);
}
BENCHMARK(BM_Seek)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Snapshot(benchmark::State& state) {
  sg::Scenario s = sg::parseScenario(sg::defaultScenarioText(), "<built-in>", {});
  s.field.patchesX = s.field.patchesZ = state.range(0);
  s.field.spacing = sg::Rational{1, 10};
  auto world = sg::makeWorld(s, 2);
  for (int t = 0; t < 120; ++t) world->step(sg::TickInput{});  // the wind is moving the grass
  const std::vector<uint8_t> raw = world->saveState();
  size_t compressed = 0;
  for (auto _ : state) compressed = sg::sgr::encodeSnapshot(world->tick(), 0, raw, 3).size();
  const double perMillion = 1e6 / double(s.field.patchesX * s.field.patchesZ);
  state.counters["raw_MB_per_1M_patches"] = double(raw.size()) * perMillion / 1e6;
  state.counters["zstd_MB_per_1M_patches"] = double(compressed) * perMillion / 1e6;
}
BENCHMARK(BM_Snapshot)->Arg(151)->Arg(1000)->ArgName("side")->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_StateDigest(benchmark::State& state) {
  std::vector<uint64_t> values(size_t(state.range(0)) / sizeof(uint64_t));
  for (size_t i = 0; i < values.size(); ++i) values[i] = i * 0x9E3779B97F4A7C15ull;  // not all alike
  uint64_t sink = 0;
  for (auto _ : state) {
    sink += sg::rowDigest(values.data(), values.size());
    benchmark::DoNotOptimize(sink);
  }
  state.SetBytesProcessed(int64_t(state.iterations()) * state.range(0));
}
// 6 x 22,801 x 8 bytes = 1,094,448: the thesis meadow's px..vz in fx32.
BENCHMARK(BM_StateDigest)->Arg(32 << 10)->Arg(196 << 10)->Arg(1094448)->ArgName("bytes");

}  // namespace
