#include "replay/cli/sweep_command.h"

#include <stdlib.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <sstream>

#include "replay/cli/cli_common.h"
#include "replay/cli/divergence_report.h"
#include "replay/divergence.h"
#include "replay/lockstep.h"
#include "replay/output_file.h"
#include "replay/progress.h"
#include "replay/recorder.h"
#include "replay/report/model_behaviour.h"
#include "replay/report/pareto.h"
#include "replay/report/plot.h"
#include "replay/scenario_files.h"
#include "replay/stage_clock.h"

namespace sg {
namespace {
namespace fs = std::filesystem;

/// The fixed sweep set, relative to the repository root (where the command is meant to run).
constexpr const char* kDefaultScenarios = "scenarios/sweep-bodies.json,scenarios/sweep-mower.json";

struct SweepOptions {
  std::string scenarios = kDefaultScenarios, out = "sweep-results";  // never the committed docs/results by default
  std::string scalars = "fx16,fx32,float,double", ks = "1,2,3,4", dts = "1/30,1/60,1/120,1/240", lods = "off,window";
  std::string broadphases = "grid";
  std::string models;  ///< empty: each scenario's own grass model
  double seconds = 3.0;
  int repeats = 3, threads = 1;
  bool json = false;
};

/// Splits "a,b,c" (empty items are errors later: they match no value).
std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> items;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) items.push_back(item);
  if (!s.empty() && s.back() == ',') items.emplace_back();
  return items;
}

/// The variant axes, parsed from the filter options. Throws std::invalid_argument with
/// "--k: expected 1, 2, 3 or 4, got '5'".
struct SweepAxes {
  std::vector<ScalarKind> scalars;
  std::vector<int> ks;
  std::vector<Rational> dts;
  std::vector<LodMode> lods;
  std::vector<ParticleBroadphase> broadphases;
  std::vector<std::optional<GrassModel>> models;  ///< {nullopt}: each scenario's own
};

template <class T, class Parse>
std::vector<T> parseList(const char* option, const std::string& text, const char* expected, Parse parse) {
  std::vector<T> values;
  for (const std::string& item : splitList(text)) {
    std::optional<T> v = parse(item);
    if (!v) throw std::invalid_argument(std::string(option) + ": expected " + expected + ", got '" + item + "'");
    values.push_back(*v);
  }
  if (values.empty()) throw std::invalid_argument(std::string(option) + ": expected " + expected + ", got nothing");
  return values;
}

SweepAxes parseAxes(const SweepOptions& o) {
  SweepAxes a;
  a.scalars = parseList<ScalarKind>("--scalars", o.scalars, "a comma-separated list of fx16, fx32, float, double",
                                    [](const std::string& s) { return parseScalarKind(s); });
  a.ks = parseList<int>("--k", o.ks, "a comma-separated list of 1, 2, 3, 4", [](const std::string& s) {
    return s.size() == 1 && s[0] >= '1' && s[0] <= '4' ? std::optional<int>(s[0] - '0') : std::nullopt;
  });
  a.dts = parseList<Rational>("--dt", o.dts, "a comma-separated list of time steps from 1e-5 to 1 s, e.g. 1/60",
                              [](const std::string& s) -> std::optional<Rational> {
                                try {
                                  return VariantSettings::parse("dt=" + s).timeStep;
                                } catch (const std::invalid_argument&) {
                                  return std::nullopt;
                                }
                              });
  a.lods = parseList<LodMode>("--lod", o.lods, "a comma-separated list of off, window",
                              [](const std::string& s) -> std::optional<LodMode> {
                                if (s == "off") return LodMode::Off;
                                if (s == "window") return LodMode::Window;
                                return std::nullopt;
                              });
  a.broadphases = parseList<ParticleBroadphase>("--broadphase", o.broadphases, "a comma-separated list of grid, brute",
                                                [](const std::string& s) -> std::optional<ParticleBroadphase> {
                                                  if (s == "grid") return ParticleBroadphase::Grid;
                                                  if (s == "brute") return ParticleBroadphase::Brute;
                                                  return std::nullopt;
                                                });
  a.models = {std::nullopt};
  if (!o.models.empty()) {
    const auto models = parseList<GrassModel>("--models", o.models, "a comma-separated list of thesis, pbd, blade",
                                              [](const std::string& s) -> std::optional<GrassModel> {
                                                try {
                                                  return VariantSettings::parse("model=" + s).model;
                                                } catch (const std::invalid_argument&) {
                                                  return std::nullopt;
                                                }
                                              });
    a.models.assign(models.begin(), models.end());
  }
  return a;
}

/// The reference every variant is measured against: the most accurate setting of each axis.
VariantSettings referenceSettings() {
  VariantSettings r;
  r.scalar = ScalarKind::Double;
  r.interpolation = 1;
  r.timeStep = Rational{1, 240};
  r.lod = LodMode::Off;
  r.broadphase = ParticleBroadphase::Grid;
  return r;
}

/// One scenario of the sweep, with its reference run recorded and observed at the common times.
struct SweepScenario {
  std::string file, name;  ///< name: the scenario's, plus " [model]" when --models chose the model
  GrassModel model = GrassModel::Thesis;
  ModelBehaviour behaviour;  ///< one tuft of the scenario under its model (report/model_behaviour.h)
  /// The model's error against the reference blade (report/reference_blade.h) at each swept dt
  /// (by its text; NaN where the one tuft does not validate at that step).
  std::map<std::string, ModelError> modelError;
  Scenario reference;  ///< the scenario under the reference settings, script in reference ticks
  std::vector<sgr::EmbeddedFile> files;
  int64_t patches = 0, bodies = 0;
  std::unique_ptr<sgr::Recording> recording;  ///< the reference's inputs
  std::vector<Observation> observed;          ///< the reference at ticks 0, M, 2M, ... (M: the common interval)
};

/// One row: a variant of one scenario and what it measured.
struct SweepRow {
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
  std::string label() const {
    return std::string(scalarName(*settings.scalar)) + " k" + std::to_string(*settings.interpolation) + " " +
           settings.timeStep->toString() + (*settings.lod == LodMode::Window ? " win" : "") +
           (*settings.broadphase == ParticleBroadphase::Brute ? " brute" : "");
  }
};

/// Makes the scenario's script and camera track keep their simulated times at the reference
/// step: the reference step must divide the scenario's own step (1/60 = 4 x 1/240).
void rescaleToReferenceTicks(Scenario& s, const Rational& ownDt, const Rational& refDt, const std::string& file) {
  const std::optional<TimeRatio> r = lineUp(ownDt, refDt);
  if (!r || r->aSteps != 1)
    throw ScenarioError(file, "$.timeStep",
                        "a time step that is a whole multiple of the sweep reference's " + refDt.toString() + ", got " +
                            ownDt.toString());
  for (ScriptedCommand& c : s.script) c.tick *= r->bSteps;
  for (CameraKey& k : s.camera) k.tick *= r->bSteps;
}

/// A temporary file name for the reference recording (removed once it is read back).
std::string temporaryRecordingPath() {
  std::string tmpl = (fs::temp_directory_path() / "simgrass-sweep-XXXXXX").string();
  const int fd = mkstemp(tmpl.data());
  if (fd < 0) throw std::runtime_error(tmpl + ": expected a writable temporary folder for the reference recording");
  ::close(fd);
  return tmpl;
}

/// Runs the reference of `sc` for `ticks` reference ticks: records its inputs (the scripted
/// camera and commands) and keeps an observation every `interval` ticks. Throws
/// std::runtime_error (a fault, an I/O error).
void runReference(SweepScenario& sc, int64_t ticks, int64_t interval, int threads) {
  std::unique_ptr<SimWorld> world = makeWorld(sc.reference, threads, physicalMemoryBytes());
  sc.patches = world->counts().patches();
  const std::string path = temporaryRecordingPath();
  RecordSettings settings;
  // The sweep never seeks or verifies: no snapshots, and a hash only as often as the reader
  // requires some tick to be named (sgr::kMaxTickGap), so that hour-long sweeps record too.
  settings.checkEvery = uint32_t(sgr::kMaxTickGap), settings.snapshotEvery = 0;
  // The temporary recording goes whatever happens (a fault, a full disk).
  struct RemoveAtExit {
    std::string path;
    ~RemoveAtExit() {
      std::error_code ec;
      fs::remove(path, ec);
    }
  } removeAtExit{path};
  {
    Recorder recorder(path, sc.reference, sc.files, *world, settings);
    StepResult last;
    for (int64_t t = 0; t <= ticks; ++t) {
      if (t % interval == 0) {
        sc.observed.emplace_back();
        world->observe(sc.observed.back());
      }
      if (t == ticks) break;
      last = recorder.step(scriptedInput(sc.reference, t));
      if (!last.ok) throw std::runtime_error(sc.file + ": the reference run faulted: " + last.error.message());
    }
    recorder.finish(last);
  }
  sc.bodies = int64_t(sc.observed.front().bodyPosition.size() / 3);
  try {
    sc.recording = std::make_unique<sgr::Recording>(sgr::readRecording(path));
  } catch (const sgr::RecordingError& e) {
    throw std::runtime_error(e.what());
  }
}

/// One run of a variant over the reference's inputs, timed (stepping only); when `measure`,
/// compared with the reference at every common time.
void runVariant(const SweepScenario& sc, SweepRow& row, int64_t interval, int threads, bool measure,
                const std::function<void(int64_t)>& progress) {
  std::unique_ptr<LockStepReplay> run;
  try {
    run = std::make_unique<LockStepReplay>(*sc.recording, threads, row.settings);
  } catch (const std::exception& e) {
    row.fault = e.what();
    return;
  }
  SimWorld& w = run->world();
  Observation obs;
  double ms = 0;
  const int64_t startTick = w.tick();
  for (size_t k = 0; k < sc.observed.size(); ++k) {
    const int64_t target = int64_t(k) * interval;
    if (k > 0) {
      const auto t0 = std::chrono::steady_clock::now();
      const StepResult r = run->advanceTo(target);
      ms += msSince(t0);
      if (!r.ok) {
        row.fault = r.error.message();
        return;
      }
      progress(target);
    }
    if (!measure) continue;
    w.observe(obs);
    TickDivergence d = measureDivergence(sc.observed[k], obs, false);
    d.tick = target;
    row.summary.add(d);
  }
  row.steps = w.tick() - startTick;
  row.runMs.push_back(ms);
}

/// The common interval M (reference ticks): every variant's step ends on a multiple of it.
/// Throws std::invalid_argument for a step with no whole ratio to the reference's.
int64_t commonInterval(const std::vector<Rational>& dts, const Rational& refDt) {
  int64_t m = 1;
  for (const Rational& dt : dts) {
    const std::optional<TimeRatio> r = lineUp(refDt, dt);
    if (!r)
      throw std::invalid_argument("--dt " + dt.toString() + ": expected a time step that is a whole multiple or a " +
                                  "whole fraction of the reference's " + refDt.toString());
    m = std::lcm(m, r->aSteps);
  }
  return m;
}

/// Errors of zero cannot sit on a log axis: they are drawn at a floor a decade under the
/// smallest non-zero error (1e-9 m when there is none).
double zeroFloor(const std::vector<double>& errors) {
  double smallest = INFINITY;
  for (double e : errors)
    if (e > 0 && std::isfinite(e)) smallest = std::min(smallest, e);
  return std::isfinite(smallest) ? std::pow(10.0, std::floor(std::log10(smallest)) - 1) : 1e-9;
}

plot::Rgb scalarColour(ScalarKind s) {
  switch (s) {
    case ScalarKind::Fx16:
      return {214, 39, 40};
    case ScalarKind::Fx32:
      return {31, 119, 180};
    case ScalarKind::Float:
      return {44, 160, 44};
    case ScalarKind::Double:
      return {148, 103, 189};
  }
  return {0, 0, 0};
}

plot::Marker kMarker(int k) {
  static constexpr plot::Marker kByK[4] = {plot::Marker::Circle, plot::Marker::Square, plot::Marker::Triangle,
                                           plot::Marker::Diamond};
  return kByK[std::clamp(k, 1, 4) - 1];
}

/// One plot: cost (ms per simulated second) against one error of the rows of one scenario.
plot::ScatterPlot errorPlot(const SweepScenario& sc, const std::vector<const SweepRow*>& rows, const SweepAxes& axes,
                            const std::string& what, const std::string& unit, double (*error)(const SweepRow&),
                            bool SweepRow::*onFront, int repeats, int threads, bool modelError) {
  plot::ScatterPlot p;
  p.title = sc.name + ": cost against " + what;
  p.xLabel = "ms of wall time per simulated second (log)";
  p.yLabel = what + ", " + unit + " (log)";
  std::vector<double> errors;
  for (const SweepRow* r : rows)
    if (r->fault.empty()) errors.push_back(error(*r));
  const double floor = zeroFloor(errors);
  std::vector<std::pair<double, const SweepRow*>> front;
  int faulted = 0;
  for (const SweepRow* r : rows) {
    if (!r->fault.empty()) {
      ++faulted;
      continue;
    }
    const double e = error(*r) > 0 ? error(*r) : floor;
    plot::Point pt{r->msPerSimSecond,
                   e,
                   scalarColour(*r->settings.scalar),
                   kMarker(*r->settings.interpolation),
                   *r->settings.lod == LodMode::Window,
                   r->*onFront,
                   ""};
    if (r->*onFront) {
      pt.label = r->label();
      front.push_back({r->msPerSimSecond, r});
    }
    p.points.push_back(pt);
  }
  std::sort(front.begin(), front.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [cost, r] : front) p.line.push_back({cost, error(*r) > 0 ? error(*r) : floor});
  p.lineColour = {40, 40, 40};
  for (ScalarKind s : axes.scalars) p.legend.push_back({scalarName(s), scalarColour(s), plot::Marker::Circle});
  for (int k : axes.ks) p.legend.push_back({"k = " + std::to_string(k), {90, 90, 90}, kMarker(k)});
  if (std::find(axes.lods.begin(), axes.lods.end(), LodMode::Window) != axes.lods.end()) {
    p.legend.push_back({"LOD off: filled", {90, 90, 90}, plot::Marker::Circle, false});
    p.legend.push_back({"LOD window: hollow", {90, 90, 90}, plot::Marker::Circle, true});
  }
  p.legend.push_back({"Pareto front", {40, 40, 40}, plot::Marker::Circle, false, true});
  char buf[160];
  std::snprintf(buf, sizeof buf, "An error of 0 (identical to the reference) is plotted at %s %s.",
                plot::tickLabel(floor).c_str(), unit.c_str());
  p.notes.push_back(buf);
  p.notes.push_back(modelError
                        ? "Model error: one tuft's tip RMS against the reference blade (8 segments, double; "
                          "docs/grass-models.md), 30 s of wind and a press; it depends on the model and dt only."
                        : "Reference: double, k = 1, dt = 1/240, LOD off. Pareto points are ringed and labelled: "
                          "scalar, k, dt, win = LOD window.");
  std::snprintf(buf, sizeof buf, "Cost: median of %d run%s, %d thread%s; errors over %zu common times.", repeats,
                repeats == 1 ? "" : "s", threads, threads == 1 ? "" : "s", sc.observed.size());
  p.notes.push_back(buf);
  if (faulted > 0) p.notes.push_back(std::to_string(faulted) + " variant(s) faulted and are not shown.");
  return p;
}

/// A file-name-safe version of a scenario name.
std::string slug(const std::string& name) {
  std::string s;
  for (char ch : name) s += std::isalnum(static_cast<unsigned char>(ch)) ? char(std::tolower(ch)) : '-';
  return s.empty() ? "scenario" : s;
}

/// Creates `dir` when missing; false with one line on stderr when it is not a writable folder.
bool prepareOutputFolder(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (fs::is_directory(dir, ec) && ::access(dir.c_str(), W_OK) == 0) return true;
  printError("simgrass sweep: --out %s: expected a writable folder (or one that can be created)\n", dir.c_str());
  return false;
}

nlohmann::json rowJson(const SweepRow& r, const std::string& scenario, GrassModel model, double refDt) {
  const int64_t first = r.summary.firstObservedTick;
  return {{"scenario", scenario},
          {"model", grassModelName(model)},
          {"scalar", scalarName(*r.settings.scalar)},
          {"k", *r.settings.interpolation},
          {"dt", r.settings.timeStep->toString()},
          {"dt_s", r.dtSeconds()},
          {"lod", *r.settings.lod == LodMode::Window ? "window" : "off"},
          {"broadphase", *r.settings.broadphase == ParticleBroadphase::Brute ? "brute" : "grid"},
          {"steps", r.steps},
          {"ms_per_tick", r.msPerTick},
          {"ms_per_simulated_second", r.msPerSimSecond},
          {"tip_rms_m", r.summary.tipRms()},
          {"tip_max_m", r.summary.tipMax},
          {"body_pos_max_m", r.summary.bodyPosMax},
          {"body_angle_max_rad", r.summary.bodyAngleMax},
          {"first_divergent_time", first < 0 ? -1.0 : double(first) * refDt},
          {"states_compared", r.summary.ticks},
          {"status", r.status()},
          {"pareto", r.pareto},
          {"pareto_tip_max", r.paretoTipMax},
          {"pareto_body", r.paretoBody},
          {"model_error_rms_m", r.modelError.tipRms},
          {"model_error_max_m", r.modelError.tipMax},
          {"pareto_model", r.paretoModel}};
}

int sweep(const SweepOptions& o) {
  SweepAxes axes;
  const VariantSettings ref = referenceSettings();
  const Rational refDt = *ref.timeStep;
  int64_t interval = 1;
  try {
    axes = parseAxes(o);
    interval = commonInterval(axes.dts, refDt);
  } catch (const std::invalid_argument& e) {
    printError("simgrass sweep: %s\n", e.what());
    return kExitBadInput;
  }
  const int64_t ticks = int64_t(std::floor(o.seconds / refDt.toDouble() + 1e-9)) / interval * interval;
  if (ticks < interval) {
    printError("simgrass sweep: --seconds: expected at least %g s (one step of the coarsest dt), got %g\n",
               double(interval) * refDt.toDouble(), o.seconds);
    return kExitBadInput;
  }

  // Every scenario loads and takes every variant before anything runs. With --models, each
  // scenario is swept once per model, each against its own reference (the same model at the
  // reference settings): the sweep measures each model's discretisation error, not how far two
  // models differ (that is `simgrass compare --variant model=...`).
  std::vector<SweepScenario> scenarios;
  std::map<std::string, std::vector<std::array<double, 3>>> referenceTipsOf;  ///< by file and dt
  for (const std::string& file : splitList(o.scenarios))
    for (const std::optional<GrassModel>& model : axes.models) {
      SweepScenario sc;
      sc.file = file;
      try {
        if (file.empty()) throw ScenarioError("--scenarios", "$", "a comma-separated list of scenario files");
        if (!fs::is_regular_file(file))
          throw ScenarioError(
              file, "$",
              std::string("a scenario file") +
                  (o.scenarios == kDefaultScenarios ? " (run from the repository root or pass --scenarios)" : ""));
        Scenario s = loadScenarioFile(file, &sc.files);
        if (model) {
          VariantSettings chosen;
          chosen.model = *model;
          chosen.applyTo(s);
        }
        sc.model = s.particles.model;
        const Scenario own = s;
        sc.name = model ? s.name + " [" + grassModelName(*model) + "]" : s.name;
        const Rational ownDt = s.timeStep;
        ref.applyTo(s);
        rescaleToReferenceTicks(s, ownDt, refDt, file);
        for (ScalarKind scalar : axes.scalars) validateForScalar(s, scalar, physicalMemoryBytes());
        // One tuft's behaviour and model error, once the scenario is known to be good (a slow
        // model error used to run before a bad time step was refused). The reference blade's run
        // is the same for every model of a file: computed once per file and dt.
        sc.behaviour = measureModelBehaviour(own);
        for (const Rational& dt : axes.dts) {
          ModelError e{NAN, NAN, 0};
          try {
            const std::string key = file + '\n' + dt.toString();
            auto cached = referenceTipsOf.find(key);
            if (cached == referenceTipsOf.end()) cached = referenceTipsOf.emplace(key, referenceTips(own, dt)).first;
            e = measureModelError(own, dt, &cached->second);
          } catch (const ScenarioError&) {          // the variant at this dt faults too, and says why
          } catch (const std::invalid_argument&) {  // no reference blade has these parameters
          }
          sc.modelError[dt.toString()] = e;
        }
        sc.reference = std::move(s);
      } catch (const ScenarioError& e) {
        printError("simgrass sweep: %s\n", e.what());
        return kExitBadInput;
      }
      scenarios.push_back(std::move(sc));
    }
  if (!prepareOutputFolder(o.out)) return kExitBadInput;
  // No output may replace one of the scenarios it is computed from, nor a file one of them reads
  // (a heightmap, a mesh: `--out o3` once wrote the plot o3/h-body.png over scenario h's heightmap).
  std::vector<std::string> inputs;
  for (const SweepScenario& sc : scenarios) {
    inputs.push_back(sc.file);
    for (const std::string& f : filesNamedBy(sc.reference, sc.files, fs::path(sc.file).parent_path().string()))
      inputs.push_back(f);
  }
  auto overwritesScenario = [&](const std::string& output) {
    return overwritesInput("sweep", "--out", output, inputs);
  };
  for (const char* name : {"sweep.csv", "sweep.json"})
    if (overwritesScenario((fs::path(o.out) / name).string())) return kExitBadInput;
  // The plots' names too, before the run (not after an hour of it): four per scenario, named by
  // its slug (numbered when two scenarios share one).
  static constexpr const char* kPlotSuffixes[] = {"tip-rms", "tip-max", "body", "model-error"};
  std::vector<std::string> plotBase;
  for (size_t s = 0; s < scenarios.size(); ++s) {
    std::string base = slug(scenarios[s].name);
    if (std::find(plotBase.begin(), plotBase.end(), base) != plotBase.end()) base += "-" + std::to_string(s + 1);
    plotBase.push_back(base);
    for (const char* suffix : kPlotSuffixes)
      if (overwritesScenario((fs::path(o.out) / (base + "-" + suffix + ".png")).string())) return kExitBadInput;
  }

  std::vector<SweepRow> rows;
  for (size_t s = 0; s < scenarios.size(); ++s)
    for (ScalarKind scalar : axes.scalars)
      for (int k : axes.ks)
        for (const Rational& dt : axes.dts)
          for (LodMode lod : axes.lods)
            for (ParticleBroadphase bp : axes.broadphases) {
              SweepRow r;
              r.scenario = s;
              r.settings.scalar = scalar, r.settings.interpolation = k, r.settings.timeStep = dt;
              r.settings.lod = lod, r.settings.broadphase = bp;
              r.modelError = scenarios[s].modelError.at(dt.toString());
              rows.push_back(std::move(r));
            }

  // The references, then every variant; repeats are the outer loop so that each variant's
  // timings are spread over the whole sweep (a busy minute does not hit one variant only).
  const int64_t rowTicks = ticks;
  ProgressBar bar("sweep", int64_t(scenarios.size()) * ticks + int64_t(rows.size()) * o.repeats * rowTicks, !o.json);
  int64_t done = 0;
  for (SweepScenario& sc : scenarios) {
    try {
      runReference(sc, ticks, interval, o.threads);
    } catch (const std::exception& e) {
      bar.finish();
      printError("simgrass sweep: %s\n", e.what());
      return kExitMismatch;
    }
    done += ticks;
    bar.update(done);
  }
  for (int rep = 0; rep < o.repeats; ++rep)
    for (SweepRow& r : rows) {
      if (!r.fault.empty()) continue;
      const int64_t base = done;
      runVariant(scenarios[r.scenario], r, interval, o.threads, rep == 0, [&](int64_t t) { bar.update(base + t); });
      done = base + rowTicks;
      bar.update(done);
    }
  bar.finish();

  // Costs, Pareto fronts per scenario (one per error measure).
  for (SweepRow& r : rows) {
    r.msPerTick = r.steps > 0 && !r.runMs.empty() ? medianOf(r.runMs) / double(r.steps) : NAN;
    r.msPerSimSecond = r.msPerTick / r.dtSeconds();
  }
  for (size_t s = 0; s < scenarios.size(); ++s) {
    std::vector<size_t> idx;
    std::vector<double> cost, tipRms, tipMax, body, model;
    std::vector<bool> ok;
    for (size_t i = 0; i < rows.size(); ++i) {
      if (rows[i].scenario != s) continue;
      idx.push_back(i);
      cost.push_back(rows[i].msPerSimSecond);
      tipRms.push_back(rows[i].summary.tipRms());
      tipMax.push_back(rows[i].summary.tipMax);
      body.push_back(rows[i].summary.bodyPosMax);
      model.push_back(rows[i].modelError.tipRms);
      ok.push_back(rows[i].fault.empty());
    }
    const std::vector<bool> a = paretoFront(cost, tipRms, ok), b = paretoFront(cost, tipMax, ok),
                            c = paretoFront(cost, body, ok), d = paretoFront(cost, model, ok);
    for (size_t j = 0; j < idx.size(); ++j)
      rows[idx[j]].pareto = a[j], rows[idx[j]].paretoTipMax = b[j], rows[idx[j]].paretoBody = c[j],
      rows[idx[j]].paretoModel = d[j];
  }

  // sweep.csv and sweep.json.
  const std::string csvPath = (fs::path(o.out) / "sweep.csv").string();
  const std::string csvHeader =
      "scenario,scalar,k,dt,dt_s,lod,broadphase,steps,ms_per_tick,ms_per_simulated_second,tip_rms_m,tip_max_m,"
      "body_pos_max_m,body_angle_max_rad,first_divergent_time,states_compared,status,pareto,pareto_tip_max,pareto_body,"
      "model_error_rms_m,model_error_max_m,pareto_model";
  const double refDtS = refDt.toDouble();
  if (!writeCsv("sweep", csvPath, csvHeader, [&](std::FILE* f) {
        for (const SweepRow& r : rows) {
          const nlohmann::json j = rowJson(r, scenarios[r.scenario].name, scenarios[r.scenario].model, refDtS);
          std::fprintf(
              f, "%s,%s,%d,%s,%s,%s,%s,%" PRId64 ",%s,%s,%s,%s,%s,%s,%s,%" PRId64 ",%s,%d,%d,%d,%s,%s,%d\n",
              csvField(scenarios[r.scenario].name).c_str(), scalarName(*r.settings.scalar), *r.settings.interpolation,
              r.settings.timeStep->toString().c_str(), csvNumber(r.dtSeconds()).c_str(),
              j["lod"].get<std::string>().c_str(), j["broadphase"].get<std::string>().c_str(), r.steps,
              csvNumber(r.msPerTick).c_str(), csvNumber(r.msPerSimSecond).c_str(),
              csvNumber(r.summary.tipRms()).c_str(), csvNumber(r.summary.tipMax).c_str(),
              csvNumber(r.summary.bodyPosMax).c_str(), csvNumber(r.summary.bodyAngleMax).c_str(),
              csvNumber(j["first_divergent_time"].get<double>()).c_str(), r.summary.ticks, csvField(r.status()).c_str(),
              r.pareto ? 1 : 0, r.paretoTipMax ? 1 : 0, r.paretoBody ? 1 : 0, csvNumber(r.modelError.tipRms).c_str(),
              csvNumber(r.modelError.tipMax).c_str(), r.paretoModel ? 1 : 0);
        }
      }))
    return kExitBadInput;

  nlohmann::json doc;
  doc["reference"] = {{"scalar", "double"}, {"k", 1}, {"dt", refDt.toString()}, {"lod", "off"}, {"broadphase", "grid"}};
  doc["seconds"] = double(ticks) * refDtS;
  doc["compareEvery_s"] = double(interval) * refDtS;
  doc["repeats"] = o.repeats;
  doc["threads"] = o.threads;
  nlohmann::json scenarioList = nlohmann::json::array(), rowList = nlohmann::json::array();
  for (const SweepScenario& sc : scenarios)
    scenarioList.push_back({{"file", sc.file},
                            {"name", sc.name},
                            {"model", grassModelName(sc.model)},
                            {"behaviour",
                             {{"sway_at_start_m", sc.behaviour.swayStart},
                              {"sway_after_600_s_m", sc.behaviour.swayLate},
                              {"settle_after_gust_s", sc.behaviour.settleAfterGust},
                              {"settle_after_press_s", sc.behaviour.settleAfterPress},
                              {"down_after_press_s", sc.behaviour.downAfterPress}}},
                            {"patches", sc.patches},
                            {"bodies", sc.bodies},
                            {"referenceTicks", ticks},
                            {"statesCompared", sc.observed.size()}});
  for (const SweepRow& r : rows)
    rowList.push_back(rowJson(r, scenarios[r.scenario].name, scenarios[r.scenario].model, refDtS));
  doc["scenarios"] = std::move(scenarioList);
  doc["rows"] = std::move(rowList);

  // The plots: four per scenario.
  std::vector<std::string> pngs;
  for (size_t s = 0; s < scenarios.size(); ++s) {
    std::vector<const SweepRow*> mine;
    for (const SweepRow& r : rows)
      if (r.scenario == s) mine.push_back(&r);
    const std::string& base = plotBase[s];
    struct Kind {
      const char* suffix;
      const char* what;
      const char* unit;
      double (*error)(const SweepRow&);
      bool SweepRow::*front;
    };
    const Kind kinds[] = {
        {kPlotSuffixes[0], "tip RMS error", "m", [](const SweepRow& r) { return r.summary.tipRms(); },
         &SweepRow::pareto},
        {kPlotSuffixes[1], "tip max error", "m", [](const SweepRow& r) { return r.summary.tipMax; },
         &SweepRow::paretoTipMax},
        {kPlotSuffixes[2], "body position max error", "m", [](const SweepRow& r) { return r.summary.bodyPosMax; },
         &SweepRow::paretoBody},
        {kPlotSuffixes[3], "model error", "m", [](const SweepRow& r) { return r.modelError.tipRms; },
         &SweepRow::paretoModel},
    };
    for (const Kind& k : kinds) {
      const std::string path = (fs::path(o.out) / (base + "-" + k.suffix + ".png")).string();
      std::string error;
      if (!plot::writePng(path,
                          plot::render(errorPlot(scenarios[s], mine, axes, k.what, k.unit, k.error, k.front, o.repeats,
                                                 o.threads, k.front == &SweepRow::paretoModel)),
                          &error)) {
        printError("simgrass sweep: %s\n", error.c_str());
        return kExitBadInput;
      }
      pngs.push_back(path);
    }
  }
  doc["plots"] = pngs;
  const std::string jsonPath = (fs::path(o.out) / "sweep.json").string();
  {
    std::string error;
    if (!writeFileAtomic(jsonPath, doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n", &error)) {
      printError("simgrass sweep: %s", error.c_str());
      return kExitBadInput;
    }
  }

  int faults = 0;
  for (const SweepRow& r : rows) faults += r.fault.empty() ? 0 : 1;
  if (o.json) {
    std::printf("%s\n", doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  } else {
    std::printf(
        "reference  scalar=double interp=1 dt=%s lod=off; %g simulated s, compared every %g s; cost: median "
        "of %d run%s, %d thread%s\n",
        refDt.toString().c_str(), double(ticks) * refDtS, double(interval) * refDtS, o.repeats,
        o.repeats == 1 ? "" : "s", o.threads, o.threads == 1 ? "" : "s");
    for (size_t s = 0; s < scenarios.size(); ++s) {
      const SweepScenario& sc = scenarios[s];
      std::printf("\n%s (%s): %" PRId64 " patches, %" PRId64 " bodies\n", escapeControl(sc.name).c_str(),
                  escapeControl(sc.file).c_str(), sc.patches, sc.bodies);
      const ModelBehaviour& b = sc.behaviour;
      auto seconds = [](double v) { return v < 0 ? std::string("> 190 s") : std::to_string(v).substr(0, 5) + " s"; };
      std::printf(
          "behaviour  %s model, one tuft: its strongest gust sways it %.3f m at 0 s and %.3f m at 600 s; "
          "back within 5 cm %s after it, %s after a press to 70 deg; down %s\n",
          grassModelName(sc.model), b.swayStart, b.swayLate, seconds(b.settleAfterGust).c_str(),
          seconds(b.settleAfterPress).c_str(), seconds(b.downAfterPress).c_str());
      std::printf("%-28s %10s %12s %11s %11s %11s %9s %11s  %s\n", "variant", "ms/tick", "ms/sim s", "tip rms m",
                  "tip max m", "body pos m", "diverges", "model err m", "status");
      for (const SweepRow& r : rows) {
        if (r.scenario != s) continue;
        const int64_t first = r.summary.firstObservedTick;
        char diverges[32];
        if (first < 0)
          std::snprintf(diverges, sizeof diverges, "never");
        else
          std::snprintf(diverges, sizeof diverges, "%.3g s", double(first) * refDtS);
        std::printf("%-28s %10.3f %12.1f %11s %11s %11s %9s %11s  %s%s\n", r.label().c_str(), r.msPerTick,
                    r.msPerSimSecond, shortNumber(r.summary.tipRms()).c_str(), shortNumber(r.summary.tipMax).c_str(),
                    shortNumber(r.summary.bodyPosMax).c_str(), diverges, shortNumber(r.modelError.tipRms).c_str(),
                    r.status().c_str(), r.pareto ? "  * pareto" : "");
      }
    }
    std::printf("\nwrote      %s, %s and %zu plots in %s\n", escapeControl(csvPath).c_str(),
                escapeControl(jsonPath).c_str(), pngs.size(), escapeControl(o.out).c_str());
    std::printf(
        "* pareto: no other variant of the scenario is both cheaper (ms per simulated second) and more "
        "accurate (tip RMS error).\n"
        "model err: one tuft's tip RMS against the reference blade (8 segments, double): 30 s of the scenario's wind "
        "and a press (docs/grass-models.md).\n");
  }
  if (faults > 0) {
    printError("simgrass sweep: %d variant%s faulted (status column in %s)\n", faults, faults == 1 ? "" : "s",
               csvPath.c_str());
    return kExitMismatch;
  }
  return kExitOk;
}
}  // namespace

void addSweepCommand(CLI::App& app, int* exitCode) {
  auto o = std::make_shared<SweepOptions>();
  CLI::App* cmd = app.add_subcommand(
      "sweep",
      "Every variant (scalar x k x dt x LOD) against a double, k=1, dt=1/240 reference: cost per simulated "
      "second against tip and body error; CSV, JSON and PNG plots with the Pareto front");
  cmd->add_option("--scenarios", o->scenarios, "Comma-separated scenario files")->capture_default_str();
  cmd->add_option("--seconds", o->seconds, "Simulated seconds per run")
      ->check(CLI::Range(1e-3, 3600.0))
      ->capture_default_str();
  cmd->add_option("--out", o->out, "Folder for sweep.csv, sweep.json and the plots (created if missing)")
      ->capture_default_str();
  cmd->add_option("--scalars", o->scalars, "Scalars to sweep (subset of fx16,fx32,float,double)")
      ->capture_default_str();
  cmd->add_option("--k", o->ks, "Interpolation factors to sweep (subset of 1,2,3,4)")->capture_default_str();
  cmd->add_option("--dt", o->dts, "Time steps to sweep (whole multiples or fractions of the reference's 1/240)")
      ->capture_default_str();
  cmd->add_option("--lod", o->lods, "Level-of-detail modes to sweep (subset of off,window)")->capture_default_str();
  cmd->add_option("--broadphase", o->broadphases, "Particle broad phases to sweep (grid,brute; results are identical)")
      ->capture_default_str();
  cmd->add_option("--models", o->models,
                  "Grass models to sweep (subset of thesis,pbd,blade), each against its own reference; "
                  "default: each scenario's own model");
  cmd->add_option("--repeats", o->repeats, "Timed runs per variant (the cost is their median)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--threads", o->threads, "Worker threads per run")->check(CLI::Range(1, 256))->capture_default_str();
  cmd->add_flag("--json", o->json, "Print sweep.json on stdout instead of the table");
  cmd->footer("Exit codes: 0 ok, 1 the reference or a variant faulted (the variant's row says so), 2 bad input.");
  cmd->callback([o, exitCode] { *exitCode = sweep(*o); });
}
}  // namespace sg
