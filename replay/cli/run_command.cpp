#include "replay/cli/run_command.h"

#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "replay/cli/cli_common.h"
#include "replay/physics_devices.h"
#include "replay/progress.h"
#include "replay/scenario_files.h"
#include "replay/stage_clock.h"
#include "sim/world/world.h"

namespace sg {
namespace {
struct RunOptions {
  std::string scenario;
  int64_t ticks = 600;
  std::string scalar;
  int interp = 0;
  int threads = 1;
  int64_t hashEvery = 0;
  std::string broadphase;       // particles vs bodies: grid | brute
  std::string bodyBroadphase;   // bodies vs bodies: brute | sap
  std::string lod;              // off | window
  std::string kernel;           // particle pass: auto | scalar | avx2
  std::string physics = "cpu";  // where the grass stages run: cpu | gpu | gpu-readback
  bool json = false;
};

std::string hex(uint64_t h) {
  char buf[19];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return buf;
}

int runScenario(const RunOptions& o) {
  Scenario scenario;
  std::unique_ptr<SimWorld> world;
  try {
    scenario = loadScenarioFile(o.scenario);
    if (!o.scalar.empty()) scenario.scalar = *parseScalarKind(o.scalar);
    if (o.interp > 0) scenario.particles.interpolation = o.interp;
    if (!o.broadphase.empty())
      scenario.bodies.particleBroadphase =
          o.broadphase == "brute" ? ParticleBroadphase::Brute : ParticleBroadphase::Grid;
    if (!o.bodyBroadphase.empty())
      scenario.bodies.bodyBroadphase =
          o.bodyBroadphase == "sap" ? BodyBroadphase::SweepAndPrune : BodyBroadphase::Brute;
    if (!o.lod.empty()) scenario.lod.mode = o.lod == "window" ? LodMode::Window : LodMode::Off;
    world = makeWorld(scenario, o.threads, physicalMemoryBytes());
    if (o.kernel == "scalar" || o.kernel == "avx2")
      world->setParticleKernel(o.kernel == "avx2" ? ParticleKernel::Avx2 : ParticleKernel::Scalar);
    if (const std::string why = applyPhysicsPath(*world, *parsePhysicsPath(o.physics)); !why.empty()) {
      printError("simgrass run: %s: --physics %s: %s\n", o.scenario.empty() ? "<built-in>" : o.scenario.c_str(),
                 o.physics.c_str(), why.c_str());
      return 2;
    }
  } catch (const ScenarioError& e) {
    printError("simgrass run: %s\n", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    printError("simgrass run: %s: $.field: expected a field that fits in memory (allocation failed)\n",
               o.scenario.empty() ? "<built-in>" : o.scenario.c_str());
    return 2;
  }
  const WorldCounts counts = world->counts();
  StageClock clock;
  nlohmann::json hashes = nlohmann::json::array();
  ProgressBar progress("run", o.ticks, !o.json);
  const auto start = std::chrono::steady_clock::now();
  StepResult failure;
  for (int64_t t = 0; t < o.ticks; ++t) {
    // A tick whose hash is printed, and the last (the final hash): the particle pass takes the
    // digests on its threads (sim/state/state_hash.h).
    if (t + 1 == o.ticks || (o.hashEvery > 0 && (world->tick() + 1) % o.hashEvery == 0)) world->requestStateHash();
    StepResult r = world->step(scriptedInput(scenario, world->tick()), &clock);
    if (!r.ok) {
      failure = r;
      break;
    }
    if (o.hashEvery > 0 && world->tick() % o.hashEvery == 0) {
      const std::string h = hex(world->stateHash());
      if (o.json) {
        hashes.push_back({{"tick", world->tick()}, {"hash", h}});
      } else {
        progress.finish();
        std::printf("tick %-8" PRId64 " hash %s\n", world->tick(), h.c_str());
      }
    }
    progress.update(t + 1);
  }
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const int64_t ran = world->tick();
  const uint64_t finalHash = world->stateHash();
  // Contacts and the window's place are the last tick's: read after the loop, not with `counts`.
  const WorldCounts last = world->counts();
  const double msPerTick = ran > 0 ? seconds * 1e3 / double(ran) : 0.0;
  const double patchSteps = ran > 0 ? double(counts.patches()) * double(ran) / seconds : 0.0;

  // What ran where the world chose AVX2 (docs/performance.md, "Vector kernels"): the particle
  // pass has AVX2 lanes in every scalar except the blade model's row in float and double; the
  // patch stage's writes in every scalar (float and double interpolate k > 1 with scalar loops).
  const bool fixed = scenario.scalar == ScalarKind::Fx32 || scenario.scalar == ScalarKind::Fx16;
  const bool blade = scenario.particles.model == GrassModel::Blade;
  const char* patchKernel = particleKernelName(world->particleKernel());
  const char* particleKernel = blade && !fixed ? "scalar" : patchKernel;

  if (o.json) {
    nlohmann::json j;
    j["scenario"] = scenario.name;
    j["source"] = scenario.sourceName;
    j["scalar"] = scalarName(scenario.scalar);
    j["interpolation"] = counts.interpolation;
    j["threads"] = counts.threads;
    j["model"] = grassModelName(scenario.particles.model);
    j["kernel"] = particleKernel;
    j["patchKernel"] = patchKernel;
    j["physics"] = describePhysics(*world);
    j["deviceBytesToHost"] = world->deviceTraffic().toHost;  // 0 on the CPU (docs/gpu-physics.md)
    j["deviceBytesToDevice"] = world->deviceTraffic().toDevice;
    j["counts"] = {{"patchesX", counts.patchesX},     {"patchesZ", counts.patchesZ},
                   {"patches", counts.patches()},     {"particlesX", counts.particlesX},
                   {"particlesZ", counts.particlesZ}, {"particles", counts.particles()},
                   {"bodies", counts.bodies},         {"contacts", last.contacts}};
    if (counts.lodWindow)
      j["lod"] = {{"windowPatchesX", last.windowPatchesX},
                  {"windowPatchesZ", last.windowPatchesZ},
                  {"originI", last.windowOriginI},
                  {"originJ", last.windowOriginJ}};
    j["ticks"] = ran;
    j["finalHash"] = hex(finalHash);
    if (o.hashEvery > 0) j["hashes"] = hashes;
    nlohmann::json stages = nlohmann::json::object();
    for (size_t s = 0; s < size_t(Stage::Count); ++s)
      if (stageIsTimed(Stage(s)))
        stages[timedStageName(Stage(s))] = ran > 0 ? double(clock.nanos[s]) / 1e6 / double(ran) : 0.0;
    j["timing"] = {{"seconds", seconds},
                   {"msPerTick", msPerTick},
                   {"patchStepsPerSecond", patchSteps},
                   {"stageMsPerTick", stages}};
    if (!failure.ok) j["error"] = failure.error.message();
    std::printf("%s\n", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  } else {
    std::printf("scenario   %s (%s)\n", escapeControl(scenario.name).c_str(),
                escapeControl(scenario.sourceName).c_str());
    const std::string kernelText = std::string(particleKernel) + (blade ? " blade kernel, " : " particle kernel, ") +
                                   patchKernel + " patch kernel";
    std::printf("scalar     %s, interpolation k=%d, %d thread%s, %s\n", scalarName(scenario.scalar),
                counts.interpolation, counts.threads, counts.threads == 1 ? "" : "s", kernelText.c_str());
    if (world->physicsPath() != PhysicsPath::Cpu)
      std::printf("physics    %s; copied %" PRId64 " bytes back, %" PRId64 " up\n", describePhysics(*world).c_str(),
                  world->deviceTraffic().toHost, world->deviceTraffic().toDevice);
    std::printf(
        "patches    %" PRId64 " (%" PRId64 " x %" PRId64 "), particles %" PRId64 " (%" PRId64 " x %" PRId64 ")\n",
        counts.patches(), counts.patchesX, counts.patchesZ, counts.particles(), counts.particlesX, counts.particlesZ);
    if (counts.lodWindow) {
      const WorldCounts& now = last;
      std::printf("lod        window of %" PRId64 " x %" PRId64 " patches, at patch (%" PRId64 ", %" PRId64
                  ") after the last tick\n",
                  now.windowPatchesX, now.windowPatchesZ, now.windowOriginI, now.windowOriginJ);
    }
    if (counts.bodies > 0)
      std::printf("bodies     %" PRId64 ", %" PRId64 " contacts in the last tick\n", counts.bodies, last.contacts);
    std::printf("ticks      %" PRId64 " (%.3f s simulated at dt = %s s)\n", ran,
                double(ran) * scenario.timeStep.toDouble(), scenario.timeStep.toString().c_str());
    std::printf("hash       %s (state after tick %" PRId64 ")\n", hex(finalHash).c_str(), ran);
    std::printf("time       %.1f ms total, %.3f ms/tick, %.1f M patch-steps/s\n", seconds * 1e3, msPerTick,
                patchSteps / 1e6);
    std::printf("stages     ");
    for (size_t s = 0; s < size_t(Stage::Count); ++s)
      if (stageIsTimed(Stage(s)))
        std::printf("%s %.3f  ", timedStageName(Stage(s)), ran > 0 ? double(clock.nanos[s]) / 1e6 / double(ran) : 0.0);
    std::printf("(ms/tick)\n");
  }
  if (!failure.ok) {
    // Name the input behind a body's fault (its file and JSON path), not only the tick.
    const std::string cause = describeInputCause(scenario, nullptr, failure.error.tick, failure.error.body);
    printError("simgrass run: %s%s\n", failure.error.message().c_str(), cause.empty() ? "" : ("; " + cause).c_str());
    return 1;
  }
  return 0;
}
}  // namespace

void addRunCommand(CLI::App& app, int* exitCode) {
  auto opts = std::make_shared<RunOptions>();
  CLI::App* run =
      app.add_subcommand("run", "Run a scenario headless and print the final state hash, timings and counts");
  run->add_option("scenario", opts->scenario, "Scenario JSON file (default: the built-in thesis meadow)");
  run->add_option("--ticks", opts->ticks, "Number of fixed ticks to run")->check(CLI::Range(int64_t(0), kMaxTick));
  run->add_option("--scalar", opts->scalar, "Scalar type, overriding the scenario")
      ->check(CLI::IsMember({"fx32", "fx16", "float", "double"}));
  run->add_option("--interp", opts->interp, "Interpolation k (1 = one particle per patch, 2 = per 2x2, ...)")
      ->check(CLI::Range(1, 4));
  run->add_option("--threads", opts->threads, "Worker threads (the result is identical for any count)")
      ->check(CLI::Range(1, 256));
  run->add_option("--hash-every", opts->hashEvery, "Also print the state hash every N ticks")
      ->check(CLI::Range(int64_t(0), kMaxTick));
  run->add_option("--broadphase", opts->broadphase, "Particle-vs-body broad phase (the state is identical)")
      ->check(CLI::IsMember({"grid", "brute"}));
  run->add_option("--body-broadphase", opts->bodyBroadphase, "Body-vs-body broad phase (the state is identical)")
      ->check(CLI::IsMember({"brute", "sap"}));
  run->add_option("--lod", opts->lod, "Level of detail: off (the whole field) or window (around the camera)")
      ->check(CLI::IsMember({"off", "window"}));
  run->add_option("--kernel", opts->kernel,
                  "Particle pass and patch stage: auto (AVX2 where the CPU has it), scalar (the reference) or avx2 "
                  "(the state is identical; --json's kernel and patchKernel say what ran)")
      ->check(CLI::IsMember({"auto", "scalar", "avx2"}));
  run->add_option("--physics", opts->physics,
                  "Where the grass stages run: cpu, gpu (compute shaders; the particles are read back only to "
                  "hash, save or draw) or gpu-readback (the thesis' design: read back every tick). The state is "
                  "identical (docs/gpu-physics.md)")
      ->check(CLI::IsMember({"cpu", "gpu", "gpu-readback"}));
  run->add_flag("--json", opts->json, "Machine-readable output");
  run->callback([opts, exitCode] { *exitCode = runScenario(*opts); });
}
}  // namespace sg
