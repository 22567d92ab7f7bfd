#include "replay/cli/replay_command.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "replay/cli/cli_common.h"
#include "replay/cli/divergence_report.h"
#include "replay/output_file.h"
#include "replay/physics_devices.h"
#include "replay/player.h"
#include "replay/progress.h"
#include "replay/state_export.h"

namespace sg {
namespace {
struct ReplayOptions {
  std::string file, exportState;
  bool verify = false, info = false, json = false;
  int64_t to = -1;
  int threads = 1;
  std::string physics = "cpu";
};

/// The hash the recording holds for `tick`, if any.
std::optional<uint64_t> recordedHash(const sgr::Recording& r, int64_t tick) {
  if (tick == r.header.startTick) return r.header.initialStateHash;
  for (const sgr::Check& c : r.checks)
    if (c.tick == tick) return c.hash;
  for (const sgr::SnapshotInfo& s : r.snapshots)
    if (s.tick == tick) return s.hash;
  if (r.end && !r.end->faulted && r.end->tick == tick) return r.end->hash;
  return std::nullopt;
}

nlohmann::json headerJson(const sgr::Recording& r) {
  return {{"file", r.file},
          {"scenario", r.header.scenarioSource},
          {"variant", r.header.variant},
          {"build", r.header.buildId},
          {"checkEvery", r.header.checkEvery},
          {"snapshotEvery", r.header.snapshotEvery},
          {"lastTick", r.lastTick()},
          {"complete", r.end.has_value()},
          {"inputs", r.inputs.size()},
          {"checks", r.checks.size()},
          {"snapshots", r.snapshots.size()},
          {"hashedTicks", r.hashedTicks()}};
}

int replay(const ReplayOptions& o) {
  if (overwritesInput("replay", "--export-state", o.exportState, {o.file})) return kExitBadInput;
  if (!canWrite("replay", o.exportState, "state file")) return kExitBadInput;  // before a long replay
  std::unique_ptr<sgr::Recording> rec;
  try {
    rec = std::make_unique<sgr::Recording>(sgr::readRecording(o.file));
  } catch (const sgr::RecordingError& e) {
    printError("simgrass replay: %s\n", e.what());
    return kExitBadInput;
  }
  // Said once the command will run: an error in the options or the recording is then the one line
  // (a cut recording with a bad --to printed the warning and the error).
  const auto warnIfCut = [&] {
    if (rec->truncated)
      printError("simgrass replay: warning: %s: byte %" PRIu64 ": expected %s; replaying the %" PRId64
                 " ticks before it\n",
                 o.file.c_str(), rec->truncatedAt, rec->truncatedExpected.c_str(), rec->lastTick());
  };
  nlohmann::json out = headerJson(*rec);
  if (o.info) {
    warnIfCut();
    if (o.json) {
      std::printf("%s\n", out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
    } else {
      std::printf("recording  %s (%s)\n", escapeControl(o.file).c_str(), rec->end ? "complete" : "cut off before END");
      std::printf("scenario   %s, %s\n", escapeControl(rec->header.scenarioSource).c_str(),
                  escapeControl(rec->header.variant).c_str());
      std::printf("built by   %s\n", escapeControl(rec->header.buildId).c_str());
      std::printf("ticks      %" PRId64 " to %" PRId64 "; %zu input chunk%s, %zu check%s, %zu snapshot%s\n",
                  rec->header.startTick, rec->lastTick(), rec->inputs.size(), rec->inputs.size() == 1 ? "" : "s",
                  rec->checks.size(), rec->checks.size() == 1 ? "" : "s", rec->snapshots.size(),
                  rec->snapshots.size() == 1 ? "" : "s");
      std::printf("hashed     %" PRId64 " ticks (the start, checks, snapshots and the end, each tick once)\n",
                  rec->hashedTicks());
    }
    return rec->truncated ? kExitTruncated : kExitOk;
  }
  std::unique_ptr<Player> player;
  VariantSettings onPath;  // --physics: the same bits, so every recorded hash still applies
  onPath.physics = parsePhysicsPath(o.physics);
  try {
    player = std::make_unique<Player>(*rec, o.threads, onPath);
  } catch (const sgr::RecordingError& e) {
    printError("simgrass replay: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    printError("simgrass replay: %s: %s\n", o.file.c_str(), e.what());
    return kExitBadInput;
  }
  if (onPath.physics.value_or(PhysicsPath::Cpu) != PhysicsPath::Cpu && player->world().scalar() == ScalarKind::Float) {
    printError(
        "simgrass replay: %s: physics=%s: float on the device is a comparison variant without the CPU's "
        "bits, so the recorded hashes do not apply: use compare --variant physics=%s\n",
        o.file.c_str(), o.physics.c_str(), o.physics.c_str());
    return kExitBadInput;
  }
  const int64_t last = rec->lastTick();
  if (o.to > last) {
    printError("simgrass replay: --to: expected a tick from %" PRId64 " to %" PRId64
               " (the recording's last), got %" PRId64 "\n",
               rec->header.startTick, last, o.to);
    return kExitBadInput;
  }
  warnIfCut();
  int code = kExitOk;
  // Verifying a recording that stopped on a fault replays the faulting step too: the world is left
  // in that step's state, which no recorded hash describes.
  bool inFaultedStep = false;
  // A replay that faulted never reached the tick asked for: no state file is written for it (the
  // state it stopped in is not the one --export-state promises).
  bool faulted = false;
  const std::string noStateWritten =
      o.exportState.empty() ? std::string() : "; no state written to " + echoed(o.exportState);
  const auto start = std::chrono::steady_clock::now();
  try {
    if (o.verify) {
      ProgressBar bar("verify", last - rec->header.startTick, !o.json);
      const VerifyReport v = player->verify([&bar](int64_t done) { bar.update(done); });
      bar.finish();
      out["verified"] = v.ok;
      out["ticks"] = v.ticks;
      out["hashesChecked"] = v.checksVerified;
      if (!v.ok) {
        out["firstMismatchTick"] = v.firstMismatchTick;
        if (v.fault) {
          faulted = true;
          out["error"] = v.fault->message();
          printError("simgrass replay: %s: the replay faulted where the recording did not: %s%s\n", o.file.c_str(),
                     v.fault->message().c_str(), noStateWritten.c_str());
        } else if (v.recordedFaultMissing) {
          // No hash to show: the recording holds none for the tick after its last. A forged or
          // damaged END fault flag gave "hash mismatch at tick 25: recorded 0000000000000000,
          // replayed 0000000000000000" here (an independent pass).
          const std::string what = describeRecordedFaultMissing(*rec->end);
          out["error"] = what;
          printError("simgrass replay: %s: %s\n", o.file.c_str(), what.c_str());
        } else {
          out["expectedHash"] = hex(v.expectedHash);
          out["actualHash"] = hex(v.actualHash);
          printError("simgrass replay: %s: hash mismatch at tick %" PRId64 ": recorded %s, replayed %s\n",
                     o.file.c_str(), v.firstMismatchTick, hex(v.expectedHash).c_str(), hex(v.actualHash).c_str());
        }
        code = kExitMismatch;
      } else if (!o.json) {
        std::printf("verified %" PRId64 " ticks (%" PRId64 " of %" PRId64 " hashed ticks match, the start included)\n",
                    v.ticks, v.checksVerified, rec->hashedTicks());
      }
      inFaultedStep = v.ok && rec->end && rec->end->faulted;
    }
    if (code == kExitOk && (o.to >= 0 || !o.verify)) {
      if (inFaultedStep) {  // seek from a fresh world, not from inside the faulted step
        player = std::make_unique<Player>(*rec, o.threads, onPath);
        inFaultedStep = false;
      }
      const int64_t target = o.to >= 0 ? o.to : last;
      ProgressBar bar("seek", target, !o.json);
      const StepResult r = player->seek(target, [&bar](int64_t done) { bar.update(done); });
      bar.finish();
      if (!r.ok) {
        faulted = true;
        printError("simgrass replay: %s: %s%s\n", o.file.c_str(), r.error.message().c_str(), noStateWritten.c_str());
        out["error"] = r.error.message();
        code = kExitMismatch;
      }
    }
  } catch (const sgr::RecordingError& e) {
    printError("simgrass replay: %s\n", e.what());
    return kExitBadInput;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const int64_t tick = player->tick();
  const uint64_t hash = player->world().stateHash();
  std::optional<uint64_t> expected;
  if (!inFaultedStep) expected = recordedHash(*rec, tick);
  if (inFaultedStep) out["recordedFault"] = rec->end->message;
  out["tick"] = tick;
  out["hash"] = hex(hash);
  out["seconds"] = seconds;
  if (expected) out["matchesRecording"] = *expected == hash;
  if (code == kExitOk && expected && *expected != hash) {
    printError("simgrass replay: %s: hash at tick %" PRId64 " is %s, the recording has %s\n", o.file.c_str(), tick,
               hex(hash).c_str(), hex(*expected).c_str());
    code = kExitMismatch;
  }
  if (!o.exportState.empty() && !faulted && o.to >= 0 && tick != o.to) {
    // A --verify that stopped on a hash mismatch before --to: the state is not the one asked for.
    printError("simgrass replay: %s: stopped at tick %" PRId64 ", not at --to %" PRId64 "%s\n", o.file.c_str(), tick,
               o.to, noStateWritten.c_str());
    faulted = true;
  }
  if (!o.exportState.empty() && !faulted) {
    // .json: the documented plain-number form; anything else: the binary state (SGSTATE2).
    const bool asJson = std::filesystem::path(o.exportState).extension() == ".json";
    std::string error;
    bool written;
    if (asJson) {
      StateExport state;
      player->world().exportState(state);
      written = writeFileAtomic(o.exportState, stateExportJson(state).dump() + "\n", &error);
    } else {
      written = writeFileAtomic(o.exportState, player->world().saveState(), &error);
    }
    if (!written) {
      printError("simgrass replay: %s\n", error.c_str());
      return kExitBadInput;
    }
    out["exportedState"] = o.exportState;
  }
  if (o.json) {
    std::printf("%s\n", out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  } else {
    std::printf("tick %" PRId64 " hash %s%s\n", tick, hex(hash).c_str(),
                inFaultedStep ? " (in the step that faulted, as recorded)"
                : expected    ? (*expected == hash ? " (matches the recording)" : " (DIFFERS from the recording)")
                              : "");
    if (!o.exportState.empty() && !faulted) std::printf("state written to %s\n", escapeControl(o.exportState).c_str());
  }
  if (code == kExitOk && rec->truncated) code = kExitTruncated;
  return code;
}
}  // namespace

void addReplayCommand(CLI::App& app, int* exitCode) {
  auto o = std::make_shared<ReplayOptions>();
  CLI::App* cmd = app.add_subcommand("replay", "Play a .sgr recording back: verify its hashes, seek, export a state");
  cmd->add_option("recording", o->file, "Recording (.sgr)")->required();
  cmd->add_flag("--verify", o->verify, "Recompute every recorded hash; report the first tick that differs (exit 1)");
  CLI::Option* verify = cmd->get_option("--verify");
  CLI::Option* to = cmd->add_option("--to", o->to, "Seek to this tick through the nearest snapshot")
                        ->check(CLI::Range(int64_t(0), kMaxTick));
  CLI::Option* exportState = cmd->add_option(
      "--export-state", o->exportState,
      "Write the state reached to this file: NAME.json the documented JSON form, any other name the binary "
      "state (docs/state-format.md)");
  cmd->add_option("--threads", o->threads, "Worker threads (the result is identical for any count)")
      ->check(CLI::Range(1, 256));
  cmd->add_option("--physics", o->physics,
                  "Where the grass stages run: cpu, gpu or gpu-readback (the state is identical, so the recorded "
                  "hashes verify on any path; docs/gpu-physics.md)")
      ->check(CLI::IsMember({"cpu", "gpu", "gpu-readback"}));
  // --info simulates nothing: with a seek, a verification or an export it ignored them, exit 0 (an
  // independent pass, 2026-11-29).
  cmd->add_flag("--info", o->info,
                "Print what the recording holds without simulating (alone: no --to, --verify or --export-state)")
      ->excludes(verify)
      ->excludes(to)
      ->excludes(exportState);
  cmd->add_flag("--json", o->json, "Machine-readable output");
  cmd->footer(
      "Exit codes: 0 ok, 1 hash mismatch or simulation fault, 2 bad input, 3 recording cut off before END "
      "(everything up to the cut checked out).");
  cmd->callback([o, exitCode] { *exitCode = replay(*o); });
}
}  // namespace sg
