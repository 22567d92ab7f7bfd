// The sweep's engine (docs/diff-and-compare.md, docs/scale-out.md): the variant axes, the plan (every
// scenario loaded and validated, one row per variant), one scenario's reference run, one variant's
// runs, and the costs and Pareto fronts. `simgrass sweep` runs it in one process; the sharded
// mode (sweep_shards.h) runs the same functions as independent jobs and merges their results, so
// a merged report holds the same numbers a single run computes.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "replay/divergence.h"
#include "replay/format/sgr_reader.h"
#include "replay/report/model_behaviour.h"
#include "replay/variant.h"

namespace sg::sweep {

/// The fixed sweep set, relative to the repository root (where the command is meant to run).
inline constexpr const char* kDefaultScenarios = "scenarios/sweep-bodies.json,scenarios/sweep-mower.json";

/// What a sweep runs: the command line's settings that change results (not --out or --json).
struct Options {
  std::string scenarios = kDefaultScenarios;
  std::string scalars = "fx16,fx32,float,double", ks = "1,2,3,4", dts = "1/30,1/60,1/120,1/240", lods = "off,window";
  std::string broadphases = "grid";
  std::string models;           ///< empty: each scenario's own grass model
  std::string physics = "cpu";  ///< where the grass stages run (docs/gpu-physics.md)
  double seconds = 3.0;
  int repeats = 3, threads = 1;
};

/// The variant axes, parsed from the filter options.
struct Axes {
  std::vector<ScalarKind> scalars;
  std::vector<int> ks;
  std::vector<Rational> dts;
  std::vector<LodMode> lods;
  std::vector<ParticleBroadphase> broadphases;
  std::vector<std::optional<GrassModel>> models;  ///< {nullopt}: each scenario's own
  std::vector<PhysicsPath> physics;               ///< a device path takes the scalars that have one (not double)
};

/// Throws std::invalid_argument with "--k: expected 1, 2, 3 or 4, got '5'".
Axes parseAxes(const Options& o);

/// Splits "a,b,c" (empty items are errors later: they match no value).
std::vector<std::string> splitList(const std::string& s);

/// The reference every variant is measured against: the most accurate setting of each axis.
VariantSettings referenceSettings();

/// One scenario of the sweep, with its reference run recorded and observed at the common times.
struct ScenarioRun {
  std::string file, name;  ///< name: the scenario's, plus " [model]" when --models chose the model
  GrassModel model = GrassModel::Thesis;
  Scenario own;              ///< as loaded (its own settings, under the chosen model)
  ModelBehaviour behaviour;  ///< one tuft of the scenario under its model (report/model_behaviour.h)
  /// The model's error against the reference blade (report/reference_blade.h) at each swept dt
  /// (by its text; NaN where the one tuft does not validate at that step).
  std::map<std::string, ModelError> modelError;
  Scenario reference;  ///< the scenario under the reference settings, script in reference ticks
  std::vector<sgr::EmbeddedFile> files;
  std::vector<std::string> inputs;  ///< the scenario file and every file it reads (never an output)
  int64_t patches = 0, bodies = 0;
  std::unique_ptr<sgr::Recording> recording;  ///< the reference's inputs
  std::vector<Observation> observed;          ///< the reference at ticks 0, M, 2M, ... (M: the common interval)
  int64_t statesCompared = 0;                 ///< observed.size() (kept when a merge has no observations)
};

/// One row: a variant of one scenario and what it measured.
struct Row {
  size_t scenario = 0;
  VariantSettings settings;
  int64_t steps = 0;          ///< own ticks per run
  std::vector<double> runMs;  ///< stepping time of each repeat, ms
  DivergenceSummary summary;
  ModelError modelError;  ///< the scenario's model at this row's dt against the reference blade
  std::string fault;      ///< empty: ran to the end
  double msPerTick = 0, msPerSimSecond = 0;
  bool pareto = false, paretoTipMax = false, paretoBody = false, paretoModel = false;

  double dtSeconds() const { return settings.timeStep->toDouble(); }
  std::string status() const { return fault.empty() ? "ok" : "fault: " + fault; }
  /// "fx32 k2 1/60 win brute": the plots' labels and the text table's first column.
  std::string label() const;
  /// "scalar=fx32 interp=2 dt=1/60 lod=window broadphase=grid": the row's settings in full.
  std::string settingsText() const;
  /// Where the row's grass stages run (cpu unless the physics axis chose a device).
  PhysicsPath physics() const;
};

/// The whole sweep before it runs.
struct Plan {
  Options options;
  Axes axes;
  Rational refDt{1, 240};
  int64_t interval = 1;  ///< the common interval M, in reference ticks
  int64_t ticks = 0;     ///< reference ticks per run (a multiple of M)
  std::vector<ScenarioRun> scenarios;
  std::vector<Row> rows;  ///< scenario by scenario, then scalar, k, dt, LOD, broad phase
};

/// Parses the axes, loads and validates every scenario (under each model of --models) and lists
/// the rows. With `measureTufts`, also each scenario's one-tuft behaviour and model errors (the
/// single-process sweep does it here, before anything long runs; a sharded sweep does it in each
/// scenario's reference job). Throws std::invalid_argument (an option: "--k: expected ...") or
/// ScenarioError (a scenario file). `missingFileHint` follows "expected a scenario file" when one
/// is not there (a job: "... relative to the folder the plan was written in").
Plan makePlan(const Options& o, bool measureTufts, const char* missingFileHint = nullptr);

/// The same plan without its scenario files: the axes, times and rows of `o` over `scenarios`
/// (their file, name, model and inputs only, from a plan file). What a merge needs: it reads
/// results, it runs nothing. Throws std::invalid_argument for bad options.
Plan planSkeleton(const Options& o, std::vector<ScenarioRun> scenarios);

/// Scenario s's one-tuft behaviour and model error at every swept dt. The reference blade's run
/// is the same for every model of a file: `cache` (by file and dt) keeps it between scenarios.
void measureTuft(Plan& plan, size_t s, std::map<std::string, std::vector<std::array<double, 3>>>* cache);

/// Runs scenario s's reference for plan.ticks reference ticks: records its inputs (the scripted
/// camera and commands) and keeps an observation every plan.interval ticks. Throws
/// std::runtime_error (a fault, an I/O error).
void runReference(Plan& plan, size_t s);

/// One run of row r over its scenario's reference inputs, timed (stepping only); with `measure`,
/// compared with the reference at every common time. A fault goes into the row.
void runVariant(const Plan& plan, Row& row, bool measure, const std::function<void(int64_t)>& progress);

/// Costs (the median of the runs) and each scenario's Pareto fronts (one per error measure).
void finishRows(Plan& plan);

}  // namespace sg::sweep
