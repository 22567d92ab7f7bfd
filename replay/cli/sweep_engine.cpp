#include "replay/cli/sweep_engine.h"

#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "replay/cli/divergence_report.h"
#include "replay/lockstep.h"
#include "replay/physics_devices.h"
#include "replay/recorder.h"
#include "replay/report/pareto.h"
#include "replay/scenario_files.h"
#include "replay/stage_clock.h"

namespace sg::sweep {
namespace {
namespace fs = std::filesystem;

template <class T, class Parse>
std::vector<T> parseList(const char* option, const std::string& text, const char* expected, Parse parse) {
  std::vector<T> values;
  for (const std::string& item : splitList(text)) {
    std::optional<T> v = parse(item);
    if (!v) throw std::invalid_argument(std::string(option) + ": expected " + expected + ", got '" + item + "'");
    // `--k 1,1` swept the same variant twice (and fed both to the Pareto plots): each value once,
    // compared as values (1/60 and 2/120 are one time step).
    if (std::find(values.begin(), values.end(), *v) != values.end())
      throw std::invalid_argument(std::string(option) + ": expected each value once, got '" + item + "' twice");
    values.push_back(*v);
  }
  if (values.empty()) throw std::invalid_argument(std::string(option) + ": expected " + expected + ", got nothing");
  return values;
}

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

}  // namespace

/// Splits "a,b,c" (empty items are errors later: they match no value).
std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> items;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) items.push_back(item);
  if (!s.empty() && s.back() == ',') items.emplace_back();
  return items;
}

Axes parseAxes(const Options& o) {
  Axes a;
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
  a.physics = parseList<PhysicsPath>("--physics", o.physics, "a comma-separated list of cpu, gpu, gpu-readback",
                                     [](const std::string& s) { return parsePhysicsPath(s); });
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

VariantSettings referenceSettings() {
  VariantSettings r;
  r.scalar = ScalarKind::Double;
  r.interpolation = 1;
  r.timeStep = Rational{1, 240};
  r.lod = LodMode::Off;
  r.broadphase = ParticleBroadphase::Grid;
  return r;
}

PhysicsPath Row::physics() const { return settings.physics.value_or(PhysicsPath::Cpu); }

std::string Row::label() const {
  return std::string(scalarName(*settings.scalar)) + " k" + std::to_string(*settings.interpolation) + " " +
         settings.timeStep->toString() + (*settings.lod == LodMode::Window ? " win" : "") +
         (*settings.broadphase == ParticleBroadphase::Brute ? " brute" : "") +
         (physics() == PhysicsPath::Cpu ? "" : std::string(" ") + physicsPathName(physics()));
}

std::string Row::settingsText() const {
  return std::string("scalar=") + scalarName(*settings.scalar) + " interp=" + std::to_string(*settings.interpolation) +
         " dt=" + settings.timeStep->toString() + " lod=" + (*settings.lod == LodMode::Window ? "window" : "off") +
         " broadphase=" + (*settings.broadphase == ParticleBroadphase::Brute ? "brute" : "grid") +
         (physics() == PhysicsPath::Cpu ? "" : std::string(" physics=") + physicsPathName(physics()));
}

namespace {
/// The axes, the reference's step, the common interval and the run length of `o`.
Plan planTimes(const Options& o) {
  Plan plan;
  plan.options = o;
  plan.axes = parseAxes(o);
  const VariantSettings ref = referenceSettings();
  plan.refDt = *ref.timeStep;
  plan.interval = commonInterval(plan.axes.dts, plan.refDt);
  plan.ticks = int64_t(std::floor(o.seconds / plan.refDt.toDouble() + 1e-9)) / plan.interval * plan.interval;
  if (plan.ticks < plan.interval) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "--seconds: expected at least %g s (one step of the coarsest dt), got %g",
                  double(plan.interval) * plan.refDt.toDouble(), o.seconds);
    throw std::invalid_argument(buf);
  }
  return plan;
}

/// One row per variant of every scenario (each scenario's model errors, when known).
void listRows(Plan& plan) {
  plan.rows.clear();
  for (size_t s = 0; s < plan.scenarios.size(); ++s)
    for (ScalarKind scalar : plan.axes.scalars)
      for (int k : plan.axes.ks)
        for (const Rational& dt : plan.axes.dts)
          for (LodMode lod : plan.axes.lods)
            for (ParticleBroadphase bp : plan.axes.broadphases)
              for (PhysicsPath physics : plan.axes.physics) {
                // double has no device path (docs/gpu-physics.md): its rows stay on the CPU only.
                if (physics != PhysicsPath::Cpu && scalar == ScalarKind::Double) continue;
                Row r;
                r.scenario = s;
                r.settings.scalar = scalar, r.settings.interpolation = k, r.settings.timeStep = dt;
                r.settings.lod = lod, r.settings.broadphase = bp;
                if (physics != PhysicsPath::Cpu) r.settings.physics = physics;
                const auto e = plan.scenarios[s].modelError.find(dt.toString());  // measured, if asked
                if (e != plan.scenarios[s].modelError.end()) r.modelError = e->second;
                plan.rows.push_back(std::move(r));
              }
}
}  // namespace

Plan makePlan(const Options& o, bool measureTufts, const char* missingFileHint) {
  // An empty list would sweep nothing and write an empty table (and a plan that --merge refuses).
  if (splitList(o.scenarios).empty())
    throw ScenarioError("--scenarios", "$", "a comma-separated list of scenario files (got an empty one)");
  Plan plan = planTimes(o);
  // A device path needs a device, and a scalar that has one (double has none).
  for (PhysicsPath physics : plan.axes.physics) {
    if (physics == PhysicsPath::Cpu) continue;
    std::string error;
    if (!gpuPhysicsProvider(&error))
      throw std::invalid_argument(std::string("--physics ") + physicsPathName(physics) + ": " + error);
    if (std::all_of(plan.axes.scalars.begin(), plan.axes.scalars.end(),
                    [](ScalarKind s) { return s == ScalarKind::Double; }) &&
        std::find(plan.axes.physics.begin(), plan.axes.physics.end(), PhysicsPath::Cpu) == plan.axes.physics.end())
      throw std::invalid_argument(std::string("--physics ") + physicsPathName(physics) +
                                  ": expected --scalars with fx32, fx16 or float (double has no device path)");
  }
  const VariantSettings ref = referenceSettings();
  // Every scenario loads and takes every variant before anything runs. With --models, each
  // scenario is swept once per model, each against its own reference (the same model at the
  // reference settings): the sweep measures each model's discretisation error, not how far two
  // models differ (that is `simgrass compare --variant model=...`).
  std::map<std::string, std::vector<std::array<double, 3>>> tipsCache;  ///< by file and dt
  const std::vector<std::string> files = splitList(o.scenarios);
  for (size_t i = 0; i < files.size(); ++i)
    if (!files[i].empty() &&
        std::find(files.begin(), files.begin() + ptrdiff_t(i), files[i]) != files.begin() + ptrdiff_t(i))
      throw ScenarioError("--scenarios", "$", "each scenario file once, got '" + files[i] + "' twice");
  for (const std::string& file : files)
    for (const std::optional<GrassModel>& model : plan.axes.models) {
      ScenarioRun sc;
      sc.file = file;
      if (file.empty()) throw ScenarioError("--scenarios", "$", "a comma-separated list of scenario files");
      if (!fs::is_regular_file(file)) {
        const char* hint = missingFileHint                    ? missingFileHint
                           : o.scenarios == kDefaultScenarios ? " (run from the repository root or pass --scenarios)"
                                                              : " (not found)";
        throw ScenarioError(file, "$", std::string("a scenario file") + hint);
      }
      Scenario s = loadScenarioFile(file, &sc.files);
      if (model) {
        VariantSettings chosen;
        chosen.model = *model;
        chosen.applyTo(s);
      }
      sc.model = s.particles.model;
      sc.own = s;
      sc.name = model ? s.name + " [" + grassModelName(*model) + "]" : s.name;
      const Rational ownDt = s.timeStep;
      ref.applyTo(s);
      rescaleToReferenceTicks(s, ownDt, plan.refDt, file);
      for (ScalarKind scalar : plan.axes.scalars) validateForScalar(s, scalar, physicalMemoryBytes());
      sc.inputs = {file};
      for (const std::string& f : filesNamedBy(s, sc.files, fs::path(file).parent_path().string()))
        sc.inputs.push_back(f);
      sc.reference = std::move(s);
      plan.scenarios.push_back(std::move(sc));
      // One tuft's behaviour and model error, once the scenario is known to be good (a slow
      // model error used to run before a bad time step was refused).
      if (measureTufts) measureTuft(plan, plan.scenarios.size() - 1, &tipsCache);
    }
  listRows(plan);
  return plan;
}

Plan planSkeleton(const Options& o, std::vector<ScenarioRun> scenarios) {
  Plan plan = planTimes(o);
  plan.scenarios = std::move(scenarios);
  listRows(plan);
  return plan;
}

void measureTuft(Plan& plan, size_t s, std::map<std::string, std::vector<std::array<double, 3>>>* cache) {
  ScenarioRun& sc = plan.scenarios[s];
  sc.behaviour = measureModelBehaviour(sc.own);
  for (const Rational& dt : plan.axes.dts) {
    ModelError e{NAN, NAN, 0, NAN, NAN, {NAN, NAN}, {}};
    try {
      const std::string key = sc.file + '\n' + dt.toString();
      auto cached = cache->find(key);
      if (cached == cache->end()) cached = cache->emplace(key, referenceTips(sc.own, dt)).first;
      e = measureModelError(sc.own, dt, &cached->second);
      if (!e.bodyError.empty())
        std::fprintf(stderr, "sweep: %s: the model error at dt %s leaves out the passing balls: %s\n", sc.file.c_str(),
                     dt.toString().c_str(), e.bodyError.c_str());
    } catch (const ScenarioError&) {          // the tuft itself does not validate at this dt: its variants fault too
    } catch (const std::invalid_argument&) {  // no reference blade has these parameters
    }
    sc.modelError[dt.toString()] = e;
  }
  for (Row& r : plan.rows)
    if (r.scenario == s) r.modelError = sc.modelError.at(r.settings.timeStep->toString());
}

void runReference(Plan& plan, size_t s) {
  ScenarioRun& sc = plan.scenarios[s];
  const int64_t ticks = plan.ticks, interval = plan.interval;
  const int threads = plan.options.threads;
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
  sc.statesCompared = int64_t(sc.observed.size());
  try {
    sc.recording = std::make_unique<sgr::Recording>(sgr::readRecording(path));
  } catch (const sgr::RecordingError& e) {
    throw std::runtime_error(e.what());
  }
}

void runVariant(const Plan& plan, Row& row, bool measure, const std::function<void(int64_t)>& progress) {
  const ScenarioRun& sc = plan.scenarios[row.scenario];
  const int64_t interval = plan.interval;
  const int threads = plan.options.threads;
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

void finishRows(Plan& plan) {
  std::vector<Row>& rows = plan.rows;
  for (Row& r : rows) {
    r.msPerTick = r.steps > 0 && !r.runMs.empty() ? medianOf(r.runMs) / double(r.steps) : NAN;
    r.msPerSimSecond = r.msPerTick / r.dtSeconds();
  }
  for (size_t s = 0; s < plan.scenarios.size(); ++s) {
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
}

}  // namespace sg::sweep
