#include "replay/cli/record_command.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "replay/cli/cli_common.h"
#include "replay/cli/option_checks.h"
#include "replay/input_file.h"
#include "replay/physics_devices.h"
#include "replay/progress.h"
#include "replay/recorder.h"
#include "replay/scenario_files.h"
#include "replay/stage_clock.h"

namespace sg {
namespace {
struct RecordOptions {
  std::string scenario, output, inputTrack;
  int64_t ticks = -1;
  std::vector<std::string> variants;
  /// `run`'s flags (--scalar fx16, --lod off, ...): each one a --variant key=value.
  std::vector<std::pair<const char*, std::string>> shorthands;
  int threads = 1;
  int64_t checkEvery = -1, snapshotEvery = 300;
  int zstdLevel = 3;
  bool json = false;
};

/// The most body commands any one tick of `commands` (sorted by tick) holds, and that tick.
std::pair<size_t, int64_t> busiestTick(const std::vector<ScriptedCommand>& commands) {
  std::pair<size_t, int64_t> most{0, 0};
  for (size_t i = 0; i < commands.size();) {
    size_t j = i;
    while (j < commands.size() && commands[j].tick == commands[i].tick) ++j;
    if (j - i > most.first) most = {j - i, commands[i].tick};
    i = j;
  }
  return most;
}

/// The names of the settings both `a` and `b` set (a flag and a --variant of the same key).
std::string sharedKeys(const VariantSettings& a, const VariantSettings& b) {
  std::string keys;
  auto both = [&](bool x, bool y, const char* key) {
    if (x && y) keys += std::string(keys.empty() ? "" : ", ") + key;
  };
  both(a.scalar.has_value(), b.scalar.has_value(), "scalar");
  both(a.interpolation.has_value(), b.interpolation.has_value(), "interp");
  both(a.broadphase.has_value(), b.broadphase.has_value(), "broadphase");
  both(a.bodyBroadphase.has_value(), b.bodyBroadphase.has_value(), "body-broadphase");
  both(a.timeStep.has_value(), b.timeStep.has_value(), "dt");
  both(a.lod.has_value(), b.lod.has_value(), "lod");
  both(a.model.has_value(), b.model.has_value(), "model");
  both(a.physics.has_value(), b.physics.has_value(), "physics");
  return keys;
}

int record(const RecordOptions& o) {
  // The recording must not replace the scenario or the input track it is made from (the
  // heightmap is checked once the scenario names it).
  if (overwritesInput("record", "-o", o.output, {o.scenario, o.inputTrack})) return kExitBadInput;
  Scenario scenario;
  std::vector<sgr::EmbeddedFile> files;
  std::optional<InputTrack> track;
  std::unique_ptr<SimWorld> world;
  try {
    VariantSettings variant;
    for (const std::string& v : o.variants) {
      // Two --variant options naming one key: the last won silently (an independent pass).
      const VariantSettings one = VariantSettings::parse(v);
      if (const std::string keys = sharedKeys(one, variant); !keys.empty())
        throw std::invalid_argument(keys + ": expected each setting once across the --variant options");
      variant = one.over(variant);
    }
    VariantSettings flags;
    for (const auto& [key, value] : o.shorthands) {
      if (value.empty()) continue;  // not given (a given empty value is refused by the parser)
      try {
        flags = VariantSettings::parse(std::string(key) + "=" + value).over(flags);
      } catch (const std::invalid_argument& e) {  // named by the flag the user typed
        printError("simgrass record: --%s: %s\n", key, e.what());
        return kExitBadInput;
      }
    }
    if (const std::string keys = sharedKeys(flags, variant); !keys.empty())
      throw std::invalid_argument(keys + ": expected each setting once, as a flag or as a --variant, got both");
    variant = variant.over(flags);
    scenario = loadScenarioFile(o.scenario, &files);
    variant.applyTo(scenario);
    if (!o.inputTrack.empty()) {
      std::string text, why;
      if (!readInputFile(o.inputTrack, InputLimits::kInputTrackBytes, &text, &why))
        throw ScenarioError(o.inputTrack, "$", why);
      track = parseInputTrack(text, o.inputTrack, scenario);
    }
    world = makeWorldWithinMemory(scenario, o.threads);
    if (variant.physics) {  // named with the scenario: the setting is fine, this scene is not
      // A recording's hashes are a promise about the bits; float on the device makes none.
      const std::string why = *variant.physics != PhysicsPath::Cpu && scenario.scalar == ScalarKind::Float
                                  ? "float on the device is a comparison variant without the CPU's bits, so its "
                                    "recording would not verify: record float on the CPU"
                                  : applyPhysicsPath(*world, *variant.physics);
      if (!why.empty()) {
        printError("simgrass record: %s: physics=%s: %s\n", scenario.sourceName.c_str(),
                   physicsPathName(*variant.physics), why.c_str());
        return kExitBadInput;
      }
    }
  } catch (const std::invalid_argument& e) {
    printError("simgrass record: --variant %s\n", e.what());
    return kExitBadInput;
  } catch (const ScenarioError& e) {
    printError("simgrass record: %s\n", e.what());
    return kExitBadInput;
  }
  const int64_t ticks = o.ticks >= 0 ? o.ticks : (track && track->ticks ? *track->ticks : 600);
  RecordSettings settings;
  settings.checkEvery = uint32_t(o.checkEvery >= 0 ? o.checkEvery : defaultCheckEvery(world->counts().patches()));
  settings.snapshotEvery = uint32_t(o.snapshotEvery);
  settings.zstdLevel = o.zstdLevel;
  // Everything `simgrass replay` would refuse is refused here, before the file is touched.
  // Nor a file the scenario reads: its heightmap, the OBJ meshes its bodies name for looks.
  const std::string scenarioDir = std::filesystem::path(o.scenario).parent_path().string();
  if (overwritesInput("record", "-o", o.output, filesNamedBy(scenario, files, scenarioDir))) return kExitBadInput;
  {
    const uint32_t interval = settings.checkEvery == 0      ? settings.snapshotEvery
                              : settings.snapshotEvery == 0 ? settings.checkEvery
                                                            : std::min(settings.checkEvery, settings.snapshotEvery);
    if ((interval == 0 || interval > sgr::kMaxTickGap) && ticks > sgr::kMaxTickGap) {
      printError("simgrass record: --ticks: expected at most %" PRId64
                 " ticks unless --check-every or --snapshot-every is at most %" PRId64
                 " (a replay refuses a longer stretch without a hash or a snapshot), got %" PRId64,
                 sgr::kMaxTickGap, sgr::kMaxTickGap, ticks);
      return kExitBadInput;
    }
    const auto [most, atTick] = busiestTick(track ? track->commands : scenario.script);
    TickInput busiest;
    busiest.bodies.resize(most);
    if (const std::string why = sgr::inputProblem(busiest); !why.empty()) {
      printError("simgrass record: %s: tick %" PRId64 ": expected %s",
                 track ? o.inputTrack.c_str() : scenario.sourceName.c_str(), atTick, why.c_str());
      return kExitBadInput;
    }
  }
  std::unique_ptr<Recorder> recorder;
  try {
    recorder = std::make_unique<Recorder>(o.output, scenario, files, *world, settings);
  } catch (const std::runtime_error& e) {
    printError("simgrass record: %s\n", e.what());
    return kExitBadInput;
  }
  StageClock clock;
  ProgressBar progress("record", ticks, !o.json);
  const auto start = std::chrono::steady_clock::now();
  StepResult last;
  try {
    for (int64_t t = 0; t < ticks && last.ok; ++t) {
      const int64_t tick = world->tick();
      last = recorder->step(track ? trackInput(*track, tick) : scriptedInput(scenario, tick), &clock);
      progress.update(t + 1);
    }
    recorder->finish(last);
  } catch (const std::runtime_error& e) {
    // The recording cannot be written (a full disk, a file-size limit): exit 2, as for every
    // command's outputs; the file reads up to its last complete chunk.
    progress.finish();
    printError("simgrass record: %s\n", e.what());
    return kExitBadInput;
  }
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const int64_t ran = world->tick();
  const uint64_t finalHash = world->stateHash();
  if (o.json) {
    nlohmann::json j;
    j["output"] = o.output;
    j["scenario"] = scenario.name;
    j["variant"] = VariantSettings::resolvedFrom(scenario).describe();
    j["ticks"] = ran;
    j["finalHash"] = hex(finalHash);
    j["bytes"] = recorder->bytesWritten();
    j["checkEvery"] = settings.checkEvery;
    j["snapshotEvery"] = settings.snapshotEvery;
    j["msPerTick"] = ran > 0 ? seconds * 1e3 / double(ran) : 0.0;
    if (!last.ok) j["error"] = last.error.message();
    std::printf("%s\n", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  } else {
    std::printf("recorded   %" PRId64 " ticks of %s (%s) to %s\n", ran, escapeControl(scenario.name).c_str(),
                VariantSettings::resolvedFrom(scenario).describe().c_str(), escapeControl(o.output).c_str());
    std::printf("file       %.1f KiB; a hash every %u tick%s, a snapshot every %u\n",
                double(recorder->bytesWritten()) / 1024.0, settings.checkEvery, settings.checkEvery == 1 ? "" : "s",
                settings.snapshotEvery);
    std::printf("hash       %s (state after tick %" PRId64 ")\n", hex(finalHash).c_str(), ran);
    std::printf("time       %.3f ms/tick\n", ran > 0 ? seconds * 1e3 / double(ran) : 0.0);
  }
  if (!last.ok) {
    // Name the input behind a body's fault (its file and JSON path), as `run` does.
    const std::string cause = describeInputCause(scenario, track ? &*track : nullptr, last.error.tick, last.error.body);
    printError("simgrass record: %s%s (recorded up to it)\n", last.error.message().c_str(),
               cause.empty() ? "" : ("; " + cause).c_str());
    return kExitMismatch;
  }
  return kExitOk;
}
}  // namespace

void addRecordCommand(CLI::App& app, int* exitCode) {
  auto o = std::make_shared<RecordOptions>();
  CLI::App* cmd =
      app.add_subcommand("record", "Run a scenario and stream a .sgr recording (inputs, hashes, snapshots)");
  cmd->add_option("scenario", o->scenario, "Scenario JSON file (default: the built-in thesis meadow)");
  cmd->add_option("-o,--output", o->output, "Recording to write (.sgr)")->required();
  cmd->add_option("--ticks", o->ticks, "Ticks to record (default: the input track's 'ticks', else 600)")
      ->check(CLI::Range(int64_t(0), kMaxTick));
  cmd->add_option("--input", o->inputTrack,
                  "Input-track JSON (camera keys and body commands) instead of the scenario's script");
  cmd->add_option("--variant", o->variants,
                  "Settings over the scenario: scalar=fx16, interp=2, broadphase=brute, "
                  "body-broadphase=sap, dt=1/120, lod=off, model=blade, physics=gpu (repeatable)")
      ->allow_extra_args(false)  // one value per --variant: a scenario path after it stays the scenario
      ->check(nonEmptyValue("KEY=VALUE", "KEY=VALUE"));
  // The same flags as `simgrass run`, each a shorthand for --variant KEY=VALUE.
  o->shorthands = {{"scalar", ""}, {"interp", ""}, {"broadphase", ""}, {"body-broadphase", ""},
                   {"lod", ""},    {"dt", ""},     {"model", ""},      {"physics", ""}};
  // A flag's value is one word: empty or spaced values would be read as no flag, or split.
  const CLI::Validator oneWord(
      [](std::string& v) {
        return v.empty() || v.find_first_of(" \t\r\n") != std::string::npos
                   ? std::string("expected one word (no spaces), got '") + v.substr(0, 40) + "'"
                   : std::string();
      },
      "WORD");
  cmd->add_option("--scalar", o->shorthands[0].second, "Scalar type (= --variant scalar=...)")
      ->check(CLI::IsMember({"fx32", "fx16", "float", "double"}))
      ->check(oneWord);
  cmd->add_option("--interp", o->shorthands[1].second, "Interpolation k, 1..4 (= --variant interp=...)")
      ->check(oneWord);
  cmd->add_option("--broadphase", o->shorthands[2].second, "Particle-vs-body broad phase (= --variant broadphase=...)")
      ->check(CLI::IsMember({"grid", "brute"}))
      ->check(oneWord);
  cmd->add_option("--body-broadphase", o->shorthands[3].second,
                  "Body-vs-body broad phase (= --variant body-broadphase=...)")
      ->check(CLI::IsMember({"brute", "sap"}))
      ->check(oneWord);
  cmd->add_option("--lod", o->shorthands[4].second, "Level of detail: off or window (= --variant lod=...)")
      ->check(CLI::IsMember({"off", "window"}))
      ->check(oneWord);
  cmd->add_option("--dt", o->shorthands[5].second, "Time step in s, e.g. 1/120 (= --variant dt=...)")->check(oneWord);
  cmd->add_option("--model", o->shorthands[6].second, "Grass model: thesis, pbd or blade (= --variant model=...)")
      ->check(CLI::IsMember({"thesis", "pbd", "blade"}))
      ->check(oneWord);
  cmd->add_option("--physics", o->shorthands[7].second,
                  "Where the grass stages run: cpu, gpu or gpu-readback (= --variant physics=...; the recording is "
                  "identical on every path, docs/gpu-physics.md)")
      ->check(CLI::IsMember({"cpu", "gpu", "gpu-readback"}))
      ->check(oneWord);
  cmd->add_option("--threads", o->threads, "Worker threads (the recording is identical for any count)")
      ->check(CLI::Range(1, 256));
  cmd->add_option("--check-every", o->checkEvery, "Ticks between state hashes (default: 1 up to ~130,000 patches)")
      ->check(CLI::Range(int64_t(0), int64_t(1) << 30));
  cmd->add_option("--snapshot-every", o->snapshotEvery, "Ticks between zstd state snapshots (0: none)")
      ->check(CLI::Range(int64_t(0), int64_t(1) << 30));
  cmd->add_option("--zstd-level", o->zstdLevel, "zstd level for snapshots")->check(CLI::Range(1, 19));
  cmd->add_flag("--json", o->json, "Machine-readable output");
  cmd->callback([o, exitCode] { *exitCode = record(*o); });
}
}  // namespace sg
