#include "replay/cli/diff_command.h"

#include <algorithm>
#include <cinttypes>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "replay/cli/cli_common.h"
#include "replay/cli/divergence_report.h"
#include "replay/divergence.h"
#include "replay/lockstep.h"
#include "replay/progress.h"

namespace sg {
namespace {
struct DiffOptions {
  std::string a, b, csv, heatmap, heatmapTick = "last";
  int threads = 1;
  bool json = false;
};

/// One side of the diff: a recording replayed with its own inputs and settings, checked against
/// the hashes it holds.
struct Side {
  std::string file;
  std::unique_ptr<sgr::Recording> rec;
  std::unique_ptr<LockStepReplay> run;
  std::unique_ptr<RecordedHashes> hashes;
  int64_t ticksPerStep = 1;  ///< own ticks per common step
  int64_t hashesChecked = 0, firstMismatchTick = -1;
  int64_t replayedTo = -1;  ///< the last tick replayed (diff stops at the shorter run's end)
  uint64_t expectedHash = 0, actualHash = 0;
  std::optional<SimError> fault;
  Observation obs, heat;

  void check(int64_t tick, uint64_t hash) {
    replayedTo = std::max(replayedTo, tick);
    const std::optional<uint64_t> expected = hashes->at(tick);
    if (!expected) return;
    if (*expected == hash) {
      ++hashesChecked;
    } else if (firstMismatchTick < 0) {
      firstMismatchTick = tick;
      expectedHash = *expected;
      actualHash = hash;
    }
  }
  bool verified() const { return firstMismatchTick < 0 && !fault; }
  std::string settings() const { return VariantSettings::resolvedFrom(run->player().scenario()).describe(); }
  nlohmann::json json() const {
    nlohmann::json j = {{"file", file},
                        {"scenario", run->player().scenario().name},
                        {"variant", settings()},
                        {"lastTick", rec->lastTick()},
                        {"truncated", rec->truncated},
                        {"ticksPerStep", ticksPerStep},
                        {"verified", verified()},
                        {"replayedTo", replayedTo},
                        {"hashesChecked", hashesChecked},
                        {"hashedTicks", rec->hashedTicks()}};
    if (firstMismatchTick >= 0) {
      j["firstMismatchTick"] = firstMismatchTick;
      j["expectedHash"] = hex(expectedHash);
      j["actualHash"] = hex(actualHash);
    }
    if (fault) j["error"] = fault->message();
    return j;
  }
  std::string verifiedText() const {
    if (fault) return "the replay FAULTED: " + fault->message();
    if (firstMismatchTick >= 0)
      return "the replay DIFFERS from the recording from tick " + std::to_string(firstMismatchTick);
    if (hashesChecked == 0) return "no recorded hashes to verify";
    // Replayed only as far as the other run goes: say so, and of how many hashed ticks.
    if (replayedTo < rec->lastTick())
      return "replay verified to tick " + std::to_string(replayedTo) + " (" + std::to_string(hashesChecked) + " of " +
             std::to_string(rec->hashedTicks()) + " hashed ticks match; the rest lies past the other run's end)";
    return "replay verified (" + std::to_string(hashesChecked) + " hashed ticks match)";
  }
};

/// --heatmap-tick: "last", "max" or a common tick (a multiple of `step` up to `last`).
bool parseHeatmapTick(const std::string& text, int64_t step, int64_t last, int64_t* tick, bool* atMax) {
  *atMax = text == "max";
  if (*atMax) return true;
  if (text == "last") {
    *tick = last;
    return true;
  }
  if (text.empty() || text.size() > 15 || text.find_first_not_of("0123456789") != std::string::npos) return false;
  *tick = std::stoll(text);
  return *tick <= last && *tick % step == 0;
}

int diff(const DiffOptions& o) {
  Side a, b;
  a.file = o.a, b.file = o.b;
  if (!canWrite("diff", o.csv, "CSV file") || !canWrite("diff", o.heatmap, "PNG file")) return kExitBadInput;
  if (overwritesInput("diff", "--csv", o.csv, {o.a, o.b}) ||
      overwritesInput("diff", "--heatmap", o.heatmap, {o.a, o.b}) ||
      sameOutputTwice("diff", "--csv", o.csv, "--heatmap", o.heatmap))
    return kExitBadInput;
  a.rec = loadRecordingFor("diff", o.a);
  if (!a.rec) return kExitBadInput;
  b.rec = loadRecordingFor("diff", o.b);
  if (!b.rec) return kExitBadInput;
  try {
    const Rational dtA = recordedTimeStep(*a.rec), dtB = recordedTimeStep(*b.rec);
    const std::optional<TimeRatio> ratio = lineUp(dtA, dtB);
    if (!ratio) {
      std::fprintf(
          stderr,
          "simgrass diff: %s: expected a time step that is a whole multiple or fraction of %s's dt=%s, got dt=%s\n",
          o.b.c_str(), o.a.c_str(), dtA.toString().c_str(), dtB.toString().c_str());
      return kExitBadInput;
    }
    a.ticksPerStep = ratio->aSteps, b.ticksPerStep = ratio->bSteps;
    a.run = std::make_unique<LockStepReplay>(*a.rec, o.threads);
    b.run = std::make_unique<LockStepReplay>(*b.rec, o.threads);
  } catch (const sgr::RecordingError& e) {
    printError("simgrass diff: %s\n", e.what());
    return kExitBadInput;
  }
  a.hashes = std::make_unique<RecordedHashes>(*a.rec);
  b.hashes = std::make_unique<RecordedHashes>(*b.rec);
  const WorldCounts ca = a.run->world().counts(), cb = b.run->world().counts();
  if (ca.patchesX != cb.patchesX || ca.patchesZ != cb.patchesZ || ca.bodies != cb.bodies) {
    printError("simgrass diff: %s: expected a recording of a field like %s's (%" PRId64 " x %" PRId64
               " patches, %" PRId64 " bodies), got %" PRId64 " x %" PRId64 " patches, %" PRId64 " bodies\n",
               o.b.c_str(), o.a.c_str(), ca.patchesX, ca.patchesZ, ca.bodies, cb.patchesX, cb.patchesZ, cb.bodies);
    return kExitBadInput;
  }
  // Hashes say "same state" only between runs that promise the same states (same settings up to
  // broad phases); otherwise the first divergence is the first tick whose observations differ.
  const VariantSettings settingsA = VariantSettings::resolvedFrom(a.run->player().scenario());
  const bool comparable = VariantSettings::resolvedFrom(b.run->player().scenario()).mustBeIdenticalTo(settingsA);
  const int64_t steps = std::min(a.rec->lastTick() / a.ticksPerStep, b.rec->lastTick() / b.ticksPerStep);
  const int64_t lastCommon = steps * a.ticksPerStep;
  int64_t heatTick = -1;
  bool heatAtMax = false;
  if (!o.heatmap.empty() && !parseHeatmapTick(o.heatmapTick, a.ticksPerStep, lastCommon, &heatTick, &heatAtMax)) {
    printError("simgrass diff: --heatmap-tick %s: expected 'last', 'max' or a tick from 0 to %" PRId64 "%s\n",
               echoed(o.heatmapTick).c_str(), lastCommon,
               a.ticksPerStep > 1 ? (" that is a multiple of " + std::to_string(a.ticksPerStep)).c_str() : "");
    return kExitBadInput;
  }

  DivergenceSummary summary;
  std::vector<TickDivergence> series;
  // Grown as the replays go, never reserved from the tick count a recording claims.
  series.reserve(size_t(std::min<int64_t>(steps + 1, 4096)));
  bool heatTaken = false;
  ProgressBar bar("diff", steps, !o.json);
  for (int64_t k = 0; k <= steps; ++k) {
    const int64_t tickA = k * a.ticksPerStep, tickB = k * b.ticksPerStep;
    if (k > 0) {
      StepResult r = a.run->advanceTo(tickA);
      if (!r.ok) a.fault = r.error;
      if (r.ok) r = b.run->advanceTo(tickB);
      if (!r.ok && !a.fault) b.fault = r.error;
      if (!r.ok) break;
    }
    a.run->world().observe(a.obs);
    b.run->world().observe(b.obs);
    bool hashesEqual = false;
    if (comparable || a.hashes->at(tickA) || b.hashes->at(tickB)) {
      const uint64_t ha = a.run->world().stateHash(), hb = b.run->world().stateHash();
      a.check(tickA, ha);
      b.check(tickB, hb);
      hashesEqual = comparable && ha == hb;
    }
    TickDivergence d = measureDivergence(a.obs, b.obs, hashesEqual);
    d.tick = tickA;
    summary.add(d);
    series.push_back(d);
    if (!o.heatmap.empty() && (heatAtMax ? summary.tipMaxTick == tickA : tickA == heatTick)) {
      std::swap(a.obs, a.heat);  // keep this tick's observations; the next observe refills the spare
      std::swap(b.obs, b.heat);
      heatTaken = true;
    }
    bar.update(k);
  }
  bar.finish();

  int code = kExitOk;
  // One line on stderr for the first problem: a fault, then a replay that left its recording.
  for (const Side* s : {&a, &b}) {
    if (code != kExitOk) break;
    if (s->fault) {
      printError("simgrass diff: %s: the replay faulted where the recording did not: %s\n", s->file.c_str(),
                 s->fault->message().c_str());
      code = kExitMismatch;
    } else if (s->firstMismatchTick >= 0) {
      printError("simgrass diff: %s: hash mismatch at tick %" PRId64 ": recorded %s, replayed %s\n", s->file.c_str(),
                 s->firstMismatchTick, hex(s->expectedHash).c_str(), hex(s->actualHash).c_str());
      code = kExitMismatch;
    }
  }
  std::string heatError;
  if (!o.heatmap.empty()) {
    if (!heatTaken) {
      heatError = o.heatmap + ": not written (the replays stopped before tick " + std::to_string(heatTick) + ")";
    } else if (!writeDivergencePng(o.heatmap, a.heat, b.heat, &heatError)) {
      printError("simgrass diff: %s\n", heatError.c_str());
      return kExitBadInput;
    }
  }
  if (!o.csv.empty() && !writeCsv("diff", o.csv, kTickCsvColumns, [&](std::FILE* f) {
        for (const TickDivergence& d : series) writeTickCsvRow(f, d);
      }))
    return kExitBadInput;

  const int64_t firstDivergent = comparable ? summary.firstHashTick : summary.firstObservedTick;
  const char* by = comparable ? "hash" : "observation";
  const int64_t compared = series.empty() ? -1 : series.back().tick;
  if (o.json) {
    nlohmann::json out;
    out["a"] = a.json();
    out["b"] = b.json();
    out["hashesComparable"] = comparable;
    out["statesCompared"] = series.size();
    out["lastTick"] = compared;
    out["identical"] = firstDivergent < 0;
    out["firstDivergentTick"] = firstDivergent;
    out["divergenceBy"] = by;
    summaryJson(summary, out);
    if (!o.heatmap.empty()) {
      if (heatTaken)
        out["heatmap"] = {{"file", o.heatmap}, {"tick", a.heat.tick}};
      else
        out["heatmapError"] = heatError;
    }
    nlohmann::json s = nlohmann::json::array();
    for (const TickDivergence& d : series) s.push_back(tickJson(d));
    out["series"] = std::move(s);
    std::printf("%s\n", out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  } else {
    std::printf("A           %s: %s, %s; %s\n", escapeControl(o.a).c_str(),
                escapeControl(a.run->player().scenario().name).c_str(), a.settings().c_str(), a.verifiedText().c_str());
    std::printf("B           %s: %s, %s; %s\n", escapeControl(o.b).c_str(),
                escapeControl(b.run->player().scenario().name).c_str(), b.settings().c_str(), b.verifiedText().c_str());
    std::string timeBase;
    if (b.ticksPerStep > 1) timeBase = "; B takes " + std::to_string(b.ticksPerStep) + " ticks per tick of A";
    if (a.ticksPerStep > 1) timeBase = "; every " + std::to_string(a.ticksPerStep) + " ticks of A, one of B";
    std::printf("ticks       0 to %" PRId64 " in A's ticks, %zu states compared%s\n", compared, series.size(),
                timeBase.c_str());
    if (firstDivergent < 0)
      std::printf("divergence  none: %s\n",
                  comparable ? "every state hash is equal" : "tips, bodies and contacts agree at every tick");
    else
      std::printf(
          "divergence  from tick %" PRId64 " (%s)\n", firstDivergent,
          comparable ? "the first state hash that differs"
                     : "the first tips, bodies or contacts that differ; the settings differ, so hashes do not compare");
    std::printf("tip error   max %s m (tick %" PRId64 "), rms %s m over all patches and ticks\n",
                shortNumber(summary.tipMax).c_str(), summary.tipMaxTick, shortNumber(summary.tipRms()).c_str());
    std::printf("bodies      position max %s m, angle max %s rad, contacts max |A - B| %" PRId64 "\n",
                shortNumber(summary.bodyPosMax).c_str(), shortNumber(summary.bodyAngleMax).c_str(),
                summary.contactDeltaMax);
    if (!o.heatmap.empty())
      std::printf(
          "heat map    %s\n",
          escapeControl(heatTaken ? o.heatmap + " (tick " + std::to_string(a.heat.tick) + ")" : heatError).c_str());
    if (!o.csv.empty()) std::printf("csv         %s (%zu rows)\n", escapeControl(o.csv).c_str(), series.size());
  }
  if (code == kExitOk && firstDivergent >= 0) code = kExitMismatch;
  // As `replay`: a cut-off recording compared in full is still not a clean agreement.
  if (code == kExitOk && (a.rec->truncated || b.rec->truncated)) code = kExitTruncated;
  return code;
}
}  // namespace

void addDiffCommand(CLI::App& app, int* exitCode) {
  auto o = std::make_shared<DiffOptions>();
  CLI::App* cmd = app.add_subcommand(
      "diff", "Replay two recordings side by side: first divergent tick, tip, body and contact errors per tick");
  cmd->add_option("a", o->a, "First recording (.sgr): the reference, whose ticks are reported")->required();
  cmd->add_option("b", o->b, "Second recording (.sgr) of a field the same size (other settings allowed)")->required();
  cmd->add_option("--csv", o->csv, "Write one row per compared tick to this CSV file");
  CLI::Option* heatmap =
      cmd->add_option("--heatmap", o->heatmap, "Write a PNG heat map of the tip distance over the meadow");
  // Without --heatmap the tick was never read, so `--heatmap-tick abc` passed (an independent pass).
  cmd->add_option("--heatmap-tick", o->heatmapTick,
                  "Tick of the heat map (with --heatmap): a tick, 'last' (default) or 'max' (largest tip error)")
      ->needs(heatmap);
  cmd->add_option("--threads", o->threads, "Worker threads per replay (results are identical for any count)")
      ->check(CLI::Range(1, 256));
  cmd->add_flag("--json", o->json, "Machine-readable output, with the per-tick series");
  cmd->footer(
      "Exit codes (like diff(1)): 0 the runs agree at every tick, 1 they diverge (or a replay faulted or left "
      "its recording), 2 bad input.");
  cmd->callback([o, exitCode] { *exitCode = diff(*o); });
}
}  // namespace sg
