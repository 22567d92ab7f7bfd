#include "replay/cli/compare_command.h"

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "replay/cli/cli_common.h"
#include "replay/cli/divergence_report.h"
#include "replay/cli/option_checks.h"
#include "replay/divergence.h"
#include "replay/lockstep.h"
#include "replay/progress.h"
#include "replay/scenario_files.h"
#include "replay/stage_clock.h"

namespace sg {
namespace {
struct CompareOptions {
  std::string file, csv, series;
  std::vector<std::string> variants;
  int64_t ticks = -1;
  int threads = 1;
  bool json = false;
};

/// One --variant: what it changes and what it measured.
struct Row {
  std::string name;  ///< the settings it changes ("scalar=fx16 interp=2")
  VariantSettings settings;
  std::string resolved;  ///< every setting of the run
  bool mustBeIdentical = false;
  int64_t recordedTicksPerStep = 1, substeps = 1;
  DivergenceSummary summary;
  std::vector<double> msPerTick;  ///< per common step, per recorded tick of simulated time
  std::vector<TickDivergence> series;
  std::optional<SimError> fault;

  int64_t firstDivergentTick() const { return mustBeIdentical ? summary.firstHashTick : summary.firstObservedTick; }
  bool failed() const { return fault || (mustBeIdentical && summary.firstHashTick >= 0); }
  std::string status() const {
    if (fault) return "FAULT: " + fault->message();
    if (mustBeIdentical) return summary.firstHashTick < 0 ? "identical" : "FAILED: not identical";
    return summary.firstObservedTick < 0 ? "same observations" : "differs";
  }
};

/// The reference (the recording under its own settings) verified against the recorded hashes.
struct Reference {
  std::vector<double> msPerTick;
  int64_t verifiedTo = -1;  ///< last tick checked against the recording (-1: none yet)
  int64_t hashesChecked = 0, firstMismatchTick = -1;
  uint64_t expectedHash = 0, actualHash = 0;
};

int compare(const CompareOptions& o) {
  if (overwritesInput("compare", "--csv", o.csv, {o.file}) ||
      overwritesInput("compare", "--series", o.series, {o.file}) ||
      sameOutputTwice("compare", "--csv", o.csv, "--series", o.series))
    return kExitBadInput;
  const std::unique_ptr<sgr::Recording> rec = loadRecordingFor("compare", o.file);
  if (!rec) return kExitBadInput;
  const int64_t last = rec->lastTick();
  if (last < 1) {
    printError("simgrass compare: %s: expected a recording of at least one tick, it holds none\n", o.file.c_str());
    return kExitBadInput;
  }
  if (o.ticks > last) {
    printError("simgrass compare: --ticks: expected 1 to %" PRId64 " (the recording's last tick), got %" PRId64 "\n",
               last, o.ticks);
    return kExitBadInput;
  }
  const int64_t ticks = o.ticks > 0 ? o.ticks : last;
  if (!canWrite("compare", o.csv, "CSV file") || !canWrite("compare", o.series, "CSV file")) return kExitBadInput;

  // Every variant is checked before anything runs: a typo is one line, not a half-done table.
  std::vector<Row> rows;
  VariantSettings recorded;
  try {
    recorded = VariantSettings::resolvedFrom(recordedScenario(*rec));
  } catch (const sgr::RecordingError& e) {
    printError("simgrass compare: %s\n", e.what());
    return kExitBadInput;
  }
  for (const std::string& text : o.variants) {
    Row row;
    try {
      row.settings = VariantSettings::parse(text);
      const Scenario s = recordedScenario(*rec, row.settings);
      validateForScalar(s, s.scalar, physicalMemoryBytes());
      const TimeRatio ratio = lockStepRatio(*recorded.timeStep, s.timeStep);
      if (ratio.aSteps > ticks)
        throw std::invalid_argument("dt=" + s.timeStep.toString() + ": expected at least " +
                                    std::to_string(ratio.aSteps) + " recorded ticks to compare (one step of it), got " +
                                    std::to_string(ticks));
      row.recordedTicksPerStep = ratio.aSteps;
      row.substeps = ratio.bSteps;
      row.resolved = VariantSettings::resolvedFrom(s).describe();
      row.mustBeIdentical = row.settings.mustBeIdenticalTo(recorded);
    } catch (const std::invalid_argument& e) {
      printError("simgrass compare: --variant %s\n", e.what());
      return kExitBadInput;
    } catch (const ScenarioError& e) {
      printError("simgrass compare: --variant %s: %s\n", echoed(text).c_str(), e.what());
      return kExitBadInput;
    } catch (const sgr::RecordingError& e) {
      printError("simgrass compare: --variant %s: %s\n", echoed(text).c_str(), e.what());
      return kExitBadInput;
    }
    row.name = row.settings.describe();
    if (row.name.empty()) row.name = "(recorded settings)";
    if (row.settings.threads) row.resolved += " threads=" + std::to_string(*row.settings.threads);
    rows.push_back(std::move(row));
  }

  // Each variant runs next to a fresh reference, the two advancing in lock-step; the reference
  // is checked against the recorded hashes (each tick on the first pass that reaches it).
  const RecordedHashes recordedHashes(*rec);
  Reference ref;
  ProgressBar bar("compare", int64_t(rows.size()) * ticks, !o.json);
  Observation refObs, varObs;
  for (size_t v = 0; v < rows.size(); ++v) {
    Row& row = rows[v];
    std::unique_ptr<LockStepReplay> refRun, varRun;
    try {
      refRun = std::make_unique<LockStepReplay>(*rec, o.threads);
      varRun = std::make_unique<LockStepReplay>(*rec, o.threads, row.settings);
    } catch (const sgr::RecordingError& e) {
      printError("simgrass compare: %s\n", e.what());
      return kExitBadInput;
    } catch (const std::invalid_argument& e) {
      printError("simgrass compare: --variant %s\n", e.what());
      return kExitBadInput;
    }
    SimWorld& rw = refRun->world();
    SimWorld& vw = varRun->world();
    if (v == 0 && ref.verifiedTo < 0) {  // the start state counts as a hashed tick, as in replay and diff
      ref.verifiedTo = rw.tick();
      if (const std::optional<uint64_t> expected = recordedHashes.at(rw.tick())) {
        if (rw.stateHash() == *expected)
          ++ref.hashesChecked;
        else
          ref.firstMismatchTick = rw.tick(), ref.expectedHash = *expected, ref.actualHash = rw.stateHash();
      }
    }
    const int64_t m = row.recordedTicksPerStep;
    for (int64_t k = 0; k * m <= ticks; ++k) {
      const int64_t target = k * m;
      if (k > 0) {
        // The reference one recorded tick at a time (timed and verified tick by tick).
        for (int64_t t = refRun->recordedTick() + 1; t <= target; ++t) {
          const auto t0 = std::chrono::steady_clock::now();
          const StepResult r = refRun->advanceTo(t);
          ref.msPerTick.push_back(msSince(t0));
          if (!r.ok) {
            bar.finish();
            printError("simgrass compare: %s: the replay faulted where the recording did not: %s\n", o.file.c_str(),
                       r.error.message().c_str());
            return kExitMismatch;
          }
          if (t > ref.verifiedTo) {  // each tick once, whichever pass gets there first
            ref.verifiedTo = t;
            if (const std::optional<uint64_t> expected = recordedHashes.at(t)) {
              const uint64_t h = rw.stateHash();
              if (h == *expected) {
                ++ref.hashesChecked;
              } else if (ref.firstMismatchTick < 0) {
                ref.firstMismatchTick = t, ref.expectedHash = *expected, ref.actualHash = h;
              }
            }
          }
        }
        const auto t0 = std::chrono::steady_clock::now();
        const StepResult r = varRun->advanceTo(target);
        row.msPerTick.push_back(msSince(t0) / double(m));
        if (!r.ok) {
          row.fault = r.error;
          break;
        }
      }
      rw.observe(refObs);
      vw.observe(varObs);
      const bool hashesEqual = row.mustBeIdentical && rw.stateHash() == vw.stateHash();
      TickDivergence d = measureDivergence(refObs, varObs, hashesEqual);
      d.tick = target;
      row.summary.add(d);
      if (!o.series.empty()) row.series.push_back(d);
      bar.update(int64_t(v) * ticks + target);
    }
  }
  bar.finish();

  int code = kExitOk;
  if (ref.firstMismatchTick >= 0) {
    printError("simgrass compare: %s: hash mismatch at tick %" PRId64 ": recorded %s, replayed %s\n", o.file.c_str(),
               ref.firstMismatchTick, hex(ref.expectedHash).c_str(), hex(ref.actualHash).c_str());
    code = kExitMismatch;
  }
  for (const Row& row : rows) {
    if (code != kExitOk || !row.failed()) continue;
    printError("simgrass compare: --variant %s: %s\n", row.name.c_str(), row.status().c_str());
    code = kExitMismatch;
  }
  // As `replay`: a cut-off recording compared in full is still not a clean agreement.
  if (code == kExitOk && rec->truncated) code = kExitTruncated;
  const double refMs = medianOf(ref.msPerTick);
  const std::string refVerified =
      ref.firstMismatchTick >= 0 ? "DIFFERS from the recording from tick " + std::to_string(ref.firstMismatchTick)
      : ref.hashesChecked > 0    ? "verified (" + std::to_string(ref.hashesChecked) + " hashed ticks match)"
                                 : "not verified (no recorded hashes in range)";

  const std::string csvHeader =
      "variant,settings,must_be_identical,status,ms_per_tick,tip_max_m,tip_rms_m,body_pos_max_m,body_angle_max_rad,"
      "contact_delta_max,first_divergent_tick,divergence_by,states_compared";
  if (!o.csv.empty() && !writeCsv("compare", o.csv, csvHeader, [&](std::FILE* f) {
        std::fprintf(f, "reference,%s,1,%s,%s,0,0,0,0,0,-1,hash,%" PRId64 "\n", csvField(recorded.describe()).c_str(),
                     ref.firstMismatchTick >= 0 ? "not-verified" : "verified", csvNumber(refMs).c_str(), ticks + 1);
        for (const Row& r : rows)
          std::fprintf(f, "%s,%s,%d,%s,%s,%s,%s,%s,%s,%" PRId64 ",%" PRId64 ",%s,%" PRId64 "\n",
                       csvField(r.name).c_str(), csvField(r.resolved).c_str(), r.mustBeIdentical ? 1 : 0,
                       csvField(r.status()).c_str(), csvNumber(medianOf(r.msPerTick)).c_str(),
                       csvNumber(r.summary.tipMax).c_str(), csvNumber(r.summary.tipRms()).c_str(),
                       csvNumber(r.summary.bodyPosMax).c_str(), csvNumber(r.summary.bodyAngleMax).c_str(),
                       r.summary.contactDeltaMax, r.firstDivergentTick(), r.mustBeIdentical ? "hash" : "observation",
                       r.summary.ticks);
      }))
    return kExitBadInput;
  if (!o.series.empty() && !writeCsv("compare", o.series, std::string("variant,") + kTickCsvColumns, [&](std::FILE* f) {
        for (const Row& r : rows)
          for (const TickDivergence& d : r.series) {
            std::fprintf(f, "%s,", csvField(r.name).c_str());
            writeTickCsvRow(f, d);
          }
      }))
    return kExitBadInput;

  if (o.json) {
    nlohmann::json out;
    out["recording"] = o.file;
    out["truncated"] = rec->truncated;
    out["scenario"] = rec->header.scenarioSource;
    out["ticks"] = ticks;
    out["reference"] = {{"settings", recorded.describe()},
                        {"msPerTick", refMs},
                        {"verified", ref.firstMismatchTick < 0 && ref.hashesChecked > 0},
                        {"hashesChecked", ref.hashesChecked}};
    if (ref.firstMismatchTick >= 0) {
      out["reference"]["firstMismatchTick"] = ref.firstMismatchTick;
      out["reference"]["expectedHash"] = hex(ref.expectedHash);
      out["reference"]["actualHash"] = hex(ref.actualHash);
    }
    nlohmann::json list = nlohmann::json::array();
    for (const Row& r : rows) {
      nlohmann::json j = {{"variant", r.name},
                          {"settings", r.resolved},
                          {"mustBeIdentical", r.mustBeIdentical},
                          {"status", r.status()},
                          {"failed", r.failed()},
                          {"msPerTick", medianOf(r.msPerTick)},
                          {"substepsPerTick", r.substeps},
                          {"ticksPerStep", r.recordedTicksPerStep},
                          {"statesCompared", r.summary.ticks},
                          {"firstDivergentTick", r.firstDivergentTick()},
                          {"divergenceBy", r.mustBeIdentical ? "hash" : "observation"}};
      summaryJson(r.summary, j);
      if (r.fault) j["error"] = r.fault->message();
      list.push_back(std::move(j));
    }
    out["variants"] = std::move(list);
    out["ok"] = code == kExitOk;
    std::printf("%s\n", out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  } else {
    std::printf("recording  %s: %s, ticks 0 to %" PRId64 "\n", escapeControl(o.file).c_str(),
                escapeControl(rec->header.scenarioSource).c_str(), ticks);
    std::printf("reference  %s: %.3f ms/tick, %s\n\n", recorded.describe().c_str(), refMs, refVerified.c_str());
    size_t w = 7;
    for (const Row& r : rows) w = std::max(w, r.name.size());
    std::printf("%-*s  %8s  %11s  %11s  %11s  %11s  %8s  %9s  %s\n", int(w), "variant", "ms/tick", "tip max m",
                "tip rms m", "body pos m", "body rad", "contacts", "diverges", "status");
    for (const Row& r : rows) {
      const int64_t first = r.firstDivergentTick();
      const std::string diverges = first < 0 ? "never" : std::to_string(first) + (r.mustBeIdentical ? " (h)" : " (o)");
      std::printf("%-*s  %8.3f  %11s  %11s  %11s  %11s  %8" PRId64 "  %9s  %s\n", int(w), r.name.c_str(),
                  medianOf(r.msPerTick), shortNumber(r.summary.tipMax).c_str(), shortNumber(r.summary.tipRms()).c_str(),
                  shortNumber(r.summary.bodyPosMax).c_str(), shortNumber(r.summary.bodyAngleMax).c_str(),
                  r.summary.contactDeltaMax, diverges.c_str(), r.status().c_str());
    }
    std::printf(
        "\nms/tick: median wall time to advance one recorded tick (%s); errors: largest over the ticks "
        "compared, rms over all patches and ticks; contacts: largest |reference - variant|; diverges: first "
        "tick whose state hash (h) or whose tips, bodies or contacts (o) differ.\n",
        o.threads == 1 ? "1 thread" : (std::to_string(o.threads) + " threads").c_str());
  }
  return code;
}
}  // namespace

void addCompareCommand(CLI::App& app, int* exitCode) {
  auto o = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "Replay a recording's inputs under variant settings: ms/tick, tip and body error, first divergent tick");
  cmd->add_option("recording", o->file, "Recording (.sgr): its own settings are the reference")->required();
  cmd->add_option("--variant", o->variants,
                  "One variant row: scalar=fx16, interp=2, broadphase=brute, body-broadphase=sap, dt=1/120, lod=off, "
                  "model=blade (or thesis, pbd), threads=2, physics=gpu (or gpu-readback, cpu); "
                  "combine with commas (scalar=fx16,interp=2). Repeatable")
      ->required()
      ->allow_extra_args(false)  // one value per --variant: `--variant interp=2 run.sgr` keeps run.sgr
      ->check(nonEmptyValue("KEY=VALUE", "KEY=VALUE"));
  cmd->add_option("--ticks", o->ticks, "Compare the first N ticks (default: the whole recording)")
      ->check(CLI::Range(int64_t(1), kMaxTick));
  cmd->add_option("--threads", o->threads, "Worker threads of the reference and of variants without threads=")
      ->check(CLI::Range(1, 256));
  cmd->add_option("--csv", o->csv, "Write one row per variant (the reference first) to this CSV file");
  cmd->add_option("--series", o->series, "Write one row per variant and compared tick to this CSV file");
  cmd->add_flag("--json", o->json, "Machine-readable output");
  cmd->footer(
      "Variants that cannot change the state (broad phases, threads) must be bit-identical to the reference. "
      "Exit codes: 0 ok, 1 such a variant was not identical, a run faulted or the reference left the "
      "recording, 2 bad input.");
  cmd->callback([o, exitCode] { *exitCode = compare(*o); });
}
}  // namespace sg
