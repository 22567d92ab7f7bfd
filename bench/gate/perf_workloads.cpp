// Deterministic workloads for the instruction-count regression gate (.ci/perf-gate).
//
// Each workload builds its world (and whatever else it needs) first, then calls
// simgrass_perf_measured() once: the gate runs this program under
//   valgrind --tool=callgrind --collect-atstart=no --toggle-collect=simgrass_perf_measured
// so only the instructions executed inside that call are counted. Program start, scenario parsing
// and world construction stay out of the count: a regression in a stage is not diluted by them.
// Everything runs on one thread, so the count does not depend on scheduling.
//
//   simgrass_perf_workloads --list [--json]     the workloads, one a line
//   simgrass_perf_workloads NAME [--json]       run one (natively: the gate adds callgrind)
//
// The fixed-point workloads run the world's default particle kernel (AVX2 where the CPU has it,
// as callgrind's virtual CPU does); the "-scalar" ones force the scalar reference, so that both
// implementations are gated. --build-info names the default, and the gate compares only counts
// taken with the same one (docs/performance.md, "Regression gate").
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "replay/format/sgr_reader.h"
#include "replay/kernel_environment.h"
#include "replay/player.h"
#include "replay/recorder.h"
#include "replay/scenario_files.h"
#include "sim/world/world.h"

namespace {

/// What a workload leaves for the report: the state it ended in and how far it went.
struct Outcome {
  int64_t ticks = 0;  ///< ticks stepped inside the measured part (replayed ticks included)
  uint64_t hash = 0;  ///< state hash at the end (informative: other changes may move it)
  std::string note;   ///< e.g. how many rows the level-of-detail window moved
  bool ok = true;
};

struct Workload {
  const char* name;
  const char* what;
  /// Builds everything and returns the measured part (called once, inside the counted function).
  std::function<std::function<Outcome()>(const std::string& scenarioDir)> prepare;
};

std::string tempPath(const char* name) {
  return (std::filesystem::temp_directory_path() /
          (std::string("simgrass-perf-") + std::to_string(getpid()) + "-" + name))
      .string();
}

sg::Scenario builtInMeadow(sg::ScalarKind scalar, int k) {
  sg::Scenario s = sg::parseScenario(sg::defaultScenarioText(), "<built-in>", {});
  s.scalar = scalar;
  s.particles.interpolation = k;
  return s;
}

/// Steps `ticks` scripted ticks; the world is shared with the caller so it is built outside.
std::function<Outcome()> stepping(std::shared_ptr<sg::SimWorld> world, sg::Scenario s, int64_t ticks) {
  return [world, s, ticks] {
    Outcome o;
    const int64_t originJ = world->counts().windowOriginJ, originI = world->counts().windowOriginI;
    for (int64_t t = 0; t < ticks && o.ok; ++t) o.ok = world->step(sg::scriptedInput(s, world->tick())).ok;
    o.ticks = ticks;
    o.hash = world->stateHash();
    const sg::WorldCounts c = world->counts();
    if (c.lodWindow)
      o.note = "window moved " + std::to_string(c.windowOriginI - originI) + " columns, " +
               std::to_string(c.windowOriginJ - originJ) + " rows";
    if (c.bodies > 0)
      o.note += (o.note.empty() ? "" : ", ") + std::to_string(c.contacts) + " contacts in the last tick";
    return o;
  };
}

std::function<Outcome()> run(const sg::Scenario& s, int64_t ticks) {
  return stepping(std::shared_ptr<sg::SimWorld>(sg::makeWorld(s, 1)), s, ticks);
}

/// As run(), with the scalar reference particle kernel whatever the CPU has.
std::function<Outcome()> runScalarKernel(const sg::Scenario& s, int64_t ticks) {
  std::shared_ptr<sg::SimWorld> world(sg::makeWorld(s, 1));
  world->setParticleKernel(sg::ParticleKernel::Scalar);
  return stepping(world, s, ticks);
}

// Tick counts: each workload is 0.1-0.5 s natively, 10-30 s under callgrind on the 2-core VM.
const std::vector<Workload>& workloads() {
  using sg::ScalarKind;
  static const std::vector<Workload> list = {
      {"meadow-fx32-k1",
       "thesis meadow (22,801 patches), fx32, k=1: 20 ticks (wind, integrate, constraints, patch state)",
       [](const std::string&) { return run(builtInMeadow(ScalarKind::Fx32, 1), 20); }},
      {"meadow-fx32-k2", "thesis meadow, fx32, k=2 (interpolated patch state): 40 ticks",
       [](const std::string&) { return run(builtInMeadow(ScalarKind::Fx32, 2), 40); }},
      {"meadow-fx16-k1", "thesis meadow, fx16, k=1: 30 ticks",
       [](const std::string&) { return run(builtInMeadow(ScalarKind::Fx16, 1), 30); }},
      {"meadow-float-k1", "thesis meadow, float, k=1 (the IEEE AVX2 lanes): 30 ticks",
       [](const std::string&) { return run(builtInMeadow(ScalarKind::Float, 1), 30); }},
      {"blade-fx32", "scenarios/blade-bodies.json (the blade model's AVX2 row, trampling, 3 bodies): 12 ticks",
       [](const std::string& dir) { return run(sg::loadScenarioFile(dir + "/blade-bodies.json"), 12); }},
      {"meadow-fx32-k1-scalar", "thesis meadow, fx32, k=1, the scalar reference particle kernel: 20 ticks",
       [](const std::string&) { return runScalarKernel(builtInMeadow(ScalarKind::Fx32, 1), 20); }},
      {"meadow-fx16-k1-scalar", "thesis meadow, fx16, k=1, the scalar reference particle kernel: 30 ticks",
       [](const std::string&) { return runScalarKernel(builtInMeadow(ScalarKind::Fx16, 1), 30); }},
      {"bodies-fx32", "scenarios/thesis-bodies.json (3 bodies: collision, response, grid broad phase): 30 ticks",
       [](const std::string& dir) { return run(sg::loadScenarioFile(dir + "/thesis-bodies.json"), 30); }},
      {"mower-fx32", "scenarios/mower-field.json (compound mower body, cutting): 40 ticks, past its push at tick 30",
       [](const std::string& dir) { return run(sg::loadScenarioFile(dir + "/mower-field.json"), 40); }},
      {"lod-crossing",
       "scenarios/lod-crossing.json (121x121 window following the camera: window shifts, edge ring): 40 ticks",
       [](const std::string& dir) { return run(sg::loadScenarioFile(dir + "/lod-crossing.json"), 40); }},
      {"record-fx32", "record the thesis meadow for 20 ticks to a temp file (CHCK hash every tick, SNAP every 10)",
       [](const std::string&) -> std::function<Outcome()> {
         const sg::Scenario s = builtInMeadow(ScalarKind::Fx32, 1);
         std::shared_ptr<sg::SimWorld> world(sg::makeWorld(s, 1));
         return [s, world] {
           const std::string path = tempPath("record.sgr");
           sg::RecordSettings settings;
           settings.snapshotEvery = 10;
           Outcome o;
           {
             sg::Recorder recorder(path, s, {}, *world, settings);
             for (int t = 0; t < 20 && o.ok; ++t) o.ok = recorder.step(sg::scriptedInput(s, world->tick())).ok;
             recorder.finish();
             o.note = std::to_string(recorder.bytesWritten()) + " bytes written";
           }
           std::filesystem::remove(path);
           o.ticks = 20;
           o.hash = world->stateHash();
           return o;
         };
       }},
      {"replay-verify-seek", "read a 20-tick recording (SNAP every 10), replay --verify it, then seek to tick 15",
       [](const std::string&) -> std::function<Outcome()> {
         const sg::Scenario s = builtInMeadow(ScalarKind::Fx32, 1);
         const std::string path = tempPath("replay.sgr");
         {
           auto world = sg::makeWorld(s, 1);
           sg::RecordSettings settings;
           settings.snapshotEvery = 10;
           sg::Recorder recorder(path, s, {}, *world, settings);
           for (int t = 0; t < 20; ++t) recorder.step(sg::scriptedInput(s, world->tick()));
           recorder.finish();
         }
         return [path] {
           const sg::sgr::Recording rec = sg::sgr::readRecording(path);
           sg::Player player(rec, 1);
           const sg::VerifyReport v = player.verify();
           Outcome o;
           o.ok = v.ok && player.seek(15).ok;
           o.ticks = v.ticks + 5;  // verify, then the snapshot at 10 restored and 5 ticks stepped
           o.hash = player.world().stateHash();
           o.note = std::to_string(v.checksVerified) + " hashes verified";
           std::filesystem::remove(path);
           return o;
         };
       }},
  };
  return list;
}

}  // namespace

// The counted region: callgrind's --toggle-collect names this function (C linkage: one plain
// symbol name, no mangling). noinline keeps it a real call.
extern "C" __attribute__((noinline)) void simgrass_perf_measured(void* part, void* outcome) {
  *static_cast<Outcome*>(outcome) = (*static_cast<std::function<Outcome()>*>(part))();
}

int main(int argc, char** argv) {
  CLI::App app{
      "Deterministic single-threaded workloads for the callgrind instruction-count gate (.ci/perf-gate).\n"
      "Only the call to simgrass_perf_measured() is meant to be counted:\n"
      "  valgrind --tool=callgrind --collect-atstart=no --toggle-collect=simgrass_perf_measured "
      "simgrass_perf_workloads NAME"};
  std::string name;
  std::string scenarioDir = SIMGRASS_SCENARIO_DIR;
  bool list = false, json = false, info = false;
  app.add_option("workload", name, "Workload to run (see --list)");
  app.add_option("--scenarios", scenarioDir, "Directory holding the scenario files")->check(CLI::ExistingDirectory);
  app.add_flag("--list", list, "List the workloads");
  app.add_flag("--build-info", info, "Print the compiler and build type this binary was built with");
  app.add_flag("--json", json, "Machine-readable output");
  CLI11_PARSE(app, argc, argv);
  if (!sg::applyKernelEnvironment()) {
    std::fprintf(stderr, "simgrass_perf_workloads: SIMGRASS_KERNEL: expected scalar, avx2 or auto\n");
    return 2;
  }

  if (info) {
    const char* kernel = sg::particleKernelName(sg::defaultParticleKernel());
    if (json)
      std::printf("%s\n",
                  nlohmann::json{{"buildId", sg::buildId()}, {"compiler", __VERSION__}, {"particleKernel", kernel}}
                      .dump()
                      .c_str());
    else
      std::printf("%s (compiler %s, %s particle kernel)\n", sg::buildId().c_str(), __VERSION__, kernel);
    return 0;
  }
  if (list) {
    nlohmann::json all = nlohmann::json::array();
    for (const Workload& w : workloads()) {
      if (json)
        all.push_back({{"name", w.name}, {"what", w.what}});
      else
        std::printf("%-20s %s\n", w.name, w.what);
    }
    if (json) std::printf("%s\n", all.dump().c_str());
    return 0;
  }
  const Workload* chosen = nullptr;
  for (const Workload& w : workloads())
    if (name == w.name) chosen = &w;
  if (!chosen) {
    std::fprintf(stderr, "simgrass_perf_workloads: workload '%s': expected one of the names --list prints\n",
                 name.c_str());
    return 2;
  }
  Outcome outcome;
  try {
    std::function<Outcome()> part = chosen->prepare(scenarioDir);
    const auto start = std::chrono::steady_clock::now();
    simgrass_perf_measured(&part, &outcome);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    char hash[19];
    std::snprintf(hash, sizeof hash, "%016" PRIx64, outcome.hash);
    if (json)
      std::printf("%s\n", nlohmann::json{{"workload", chosen->name},
                                         {"ok", outcome.ok},
                                         {"ticks", outcome.ticks},
                                         {"hash", hash},
                                         {"note", outcome.note},
                                         {"seconds", seconds}}
                              .dump()
                              .c_str());
    else
      std::printf("%s: %" PRId64 " ticks, hash %s, %.3f s measured%s%s%s\n", chosen->name, outcome.ticks, hash, seconds,
                  outcome.note.empty() ? "" : " (", outcome.note.c_str(), outcome.note.empty() ? "" : ")");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "simgrass_perf_workloads: %s: %s\n", chosen->name, e.what());
    return 1;
  }
  if (!outcome.ok) {
    std::fprintf(stderr, "simgrass_perf_workloads: %s: the simulation faulted\n", chosen->name);
    return 1;
  }
  return 0;
}
