#include "replay/cli/sweep_report.h"

#include <unistd.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "replay/cli/cli_common.h"
#include "replay/cli/divergence_report.h"
#include "replay/output_file.h"
#include "replay/report/plot.h"
#include "replay/scenario_files.h"

namespace sg::sweep {
namespace {
namespace fs = std::filesystem;

struct SweepOut {
  std::string out;
};

static constexpr const char* kPlotSuffixes[] = {"tip-rms", "tip-max", "body", "model-error"};

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
plot::ScatterPlot errorPlot(const ScenarioRun& sc, const std::vector<const Row*>& rows, const Axes& axes,
                            const std::string& what, const std::string& unit, double (*error)(const Row&),
                            bool Row::*onFront, int repeats, int threads, bool modelError) {
  plot::ScatterPlot p;
  p.title = sc.name + ": cost against " + what;
  p.xLabel = "ms of wall time per simulated second (log)";
  p.yLabel = what + ", " + unit + " (log)";
  std::vector<double> errors;
  for (const Row* r : rows)
    if (r->fault.empty()) errors.push_back(error(*r));
  const double floor = zeroFloor(errors);
  std::vector<std::pair<double, const Row*>> front;
  int faulted = 0;
  for (const Row* r : rows) {
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
                          "docs/grass-models.md): 30 s of wind, a press, two balls passing; it depends on the "
                          "model, dt and tipContact only."
                        : "Reference: double, k = 1, dt = 1/240, LOD off. Pareto points are ringed and labelled: "
                          "scalar, k, dt, win = LOD window.");
  std::snprintf(buf, sizeof buf, "Cost: median of %d run%s, %d thread%s; errors over %zu common times.", repeats,
                repeats == 1 ? "" : "s", threads, threads == 1 ? "" : "s", size_t(sc.statesCompared));
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

nlohmann::json rowJson(const Row& r, const std::string& scenario, GrassModel model, double refDt) {
  const int64_t first = r.summary.firstObservedTick;
  return {{"scenario", scenario},
          {"model", grassModelName(model)},
          {"scalar", scalarName(*r.settings.scalar)},
          {"k", *r.settings.interpolation},
          {"dt", r.settings.timeStep->toString()},
          {"dt_s", r.dtSeconds()},
          {"lod", *r.settings.lod == LodMode::Window ? "window" : "off"},
          {"broadphase", *r.settings.broadphase == ParticleBroadphase::Brute ? "brute" : "grid"},
          {"physics", physicsPathName(r.physics())},
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
          {"pareto_model", r.paretoModel},
          {"model_error_body_rms_m", r.modelError.bodyRms},
          {"model_error_body_max_m", r.modelError.bodyMax}};
}

/// The plots' base names: the scenario's slug, numbered when two scenarios share one.
std::vector<std::string> plotBases(const Plan& plan) {
  std::vector<std::string> plotBase;
  for (size_t s = 0; s < plan.scenarios.size(); ++s) {
    std::string base = slug(plan.scenarios[s].name);
    // Appended (GCC 12's -Wrestrict misfires on `base += "-" + ...`, bug 105329).
    if (std::find(plotBase.begin(), plotBase.end(), base) != plotBase.end())
      base.append("-").append(std::to_string(s + 1));
    plotBase.push_back(base);
  }
  return plotBase;
}
}  // namespace

bool checkOutputs(const Plan& plan, const std::string& out) {
  const std::vector<ScenarioRun>& scenarios = plan.scenarios;
  const SweepOut o{out};
  if (!prepareOutputFolder(o.out)) return false;
  // No output may replace one of the scenarios it is computed from, nor a file one of them reads
  // (a heightmap, a mesh: `--out o3` once wrote the plot o3/h-body.png over scenario h's heightmap).
  std::vector<std::string> inputs;
  for (const ScenarioRun& sc : scenarios) inputs.insert(inputs.end(), sc.inputs.begin(), sc.inputs.end());
  auto overwritesScenario = [&](const std::string& output) {
    return overwritesInput("sweep", "--out", output, inputs);
  };
  for (const char* name : {"sweep.csv", "sweep.json"})
    if (overwritesScenario((fs::path(o.out) / name).string())) return false;
  // The plots' names too, before the run (not after an hour of it): four per scenario, named by
  // its slug (numbered when two scenarios share one).
  for (const std::string& base : plotBases(plan))
    for (const char* suffix : kPlotSuffixes)
      if (overwritesScenario((fs::path(o.out) / (base + "-" + suffix + ".png")).string())) return false;
  return true;
}

int writeReport(const Plan& plan, const std::string& out, bool json) {
  const std::vector<ScenarioRun>& scenarios = plan.scenarios;
  const std::vector<Row>& rows = plan.rows;
  const Axes& axes = plan.axes;
  const Rational refDt = plan.refDt;
  const int64_t ticks = plan.ticks, interval = plan.interval;
  const struct {
    std::string out;
    bool json;
    int repeats, threads;
  } o{out, json, plan.options.repeats, plan.options.threads};
  const std::vector<std::string> plotBase = plotBases(plan);
  // sweep.csv and sweep.json.
  const std::string csvPath = (fs::path(o.out) / "sweep.csv").string();
  const std::string csvHeader =
      "scenario,scalar,k,dt,dt_s,lod,broadphase,steps,ms_per_tick,ms_per_simulated_second,tip_rms_m,tip_max_m,"
      "body_pos_max_m,body_angle_max_rad,first_divergent_time,states_compared,status,pareto,pareto_tip_max,pareto_body,"
      "model_error_rms_m,model_error_max_m,pareto_model,model_error_body_rms_m,model_error_body_max_m,physics";
  const double refDtS = refDt.toDouble();
  if (!writeCsv("sweep", csvPath, csvHeader, [&](std::FILE* f) {
        for (const Row& r : rows) {
          const nlohmann::json j = rowJson(r, scenarios[r.scenario].name, scenarios[r.scenario].model, refDtS);
          std::fprintf(
              f, "%s,%s,%d,%s,%s,%s,%s,%" PRId64 ",%s,%s,%s,%s,%s,%s,%s,%" PRId64 ",%s,%d,%d,%d,%s,%s,%d,%s,%s,%s\n",
              csvField(scenarios[r.scenario].name).c_str(), scalarName(*r.settings.scalar), *r.settings.interpolation,
              r.settings.timeStep->toString().c_str(), csvNumber(r.dtSeconds()).c_str(),
              j["lod"].get<std::string>().c_str(), j["broadphase"].get<std::string>().c_str(), r.steps,
              csvNumber(r.msPerTick).c_str(), csvNumber(r.msPerSimSecond).c_str(),
              csvNumber(r.summary.tipRms()).c_str(), csvNumber(r.summary.tipMax).c_str(),
              csvNumber(r.summary.bodyPosMax).c_str(), csvNumber(r.summary.bodyAngleMax).c_str(),
              csvNumber(j["first_divergent_time"].get<double>()).c_str(), r.summary.ticks, csvField(r.status()).c_str(),
              r.pareto ? 1 : 0, r.paretoTipMax ? 1 : 0, r.paretoBody ? 1 : 0, csvNumber(r.modelError.tipRms).c_str(),
              csvNumber(r.modelError.tipMax).c_str(), r.paretoModel ? 1 : 0, csvNumber(r.modelError.bodyRms).c_str(),
              csvNumber(r.modelError.bodyMax).c_str(), physicsPathName(r.physics()));
        }
      }))
    return kExitBadInput;

  nlohmann::json doc;
  doc["reference"] = {{"scalar", "double"},   {"k", 1},          {"dt", refDt.toString()}, {"lod", "off"},
                      {"broadphase", "grid"}, {"physics", "cpu"}};
  doc["seconds"] = double(ticks) * refDtS;
  doc["compareEvery_s"] = double(interval) * refDtS;
  doc["repeats"] = o.repeats;
  doc["threads"] = o.threads;
  nlohmann::json scenarioList = nlohmann::json::array(), rowList = nlohmann::json::array();
  for (const ScenarioRun& sc : scenarios)
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
                            {"statesCompared", sc.statesCompared}});
  for (const Row& r : rows)
    rowList.push_back(rowJson(r, scenarios[r.scenario].name, scenarios[r.scenario].model, refDtS));
  doc["scenarios"] = std::move(scenarioList);
  doc["rows"] = std::move(rowList);

  // The plots: four per scenario.
  std::vector<std::string> pngs;
  for (size_t s = 0; s < scenarios.size(); ++s) {
    std::vector<const Row*> mine;
    for (const Row& r : rows)
      if (r.scenario == s) mine.push_back(&r);
    const std::string& base = plotBase[s];
    struct Kind {
      const char* suffix;
      const char* what;
      const char* unit;
      double (*error)(const Row&);
      bool Row::*front;
    };
    const Kind kinds[] = {
        {kPlotSuffixes[0], "tip RMS error", "m", [](const Row& r) { return r.summary.tipRms(); }, &Row::pareto},
        {kPlotSuffixes[1], "tip max error", "m", [](const Row& r) { return r.summary.tipMax; }, &Row::paretoTipMax},
        {kPlotSuffixes[2], "body position max error", "m", [](const Row& r) { return r.summary.bodyPosMax; },
         &Row::paretoBody},
        {kPlotSuffixes[3], "model error", "m", [](const Row& r) { return r.modelError.tipRms; }, &Row::paretoModel},
    };
    for (const Kind& k : kinds) {
      const std::string path = (fs::path(o.out) / (base + "-" + k.suffix + ".png")).string();
      std::string error;
      if (!plot::writePng(path,
                          plot::render(errorPlot(scenarios[s], mine, axes, k.what, k.unit, k.error, k.front, o.repeats,
                                                 o.threads, k.front == &Row::paretoModel)),
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
  for (const Row& r : rows) faults += r.fault.empty() ? 0 : 1;
  if (o.json) {
    std::printf("%s\n", doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  } else {
    std::printf(
        "reference  scalar=double interp=1 dt=%s lod=off; %g simulated s, compared every %g s; cost: median "
        "of %d run%s, %d thread%s\n",
        refDt.toString().c_str(), double(ticks) * refDtS, double(interval) * refDtS, o.repeats,
        o.repeats == 1 ? "" : "s", o.threads, o.threads == 1 ? "" : "s");
    for (size_t s = 0; s < scenarios.size(); ++s) {
      const ScenarioRun& sc = scenarios[s];
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
      for (const Row& r : rows) {
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
        "model err: one tuft's tip RMS against the reference blade (8 segments, double): 30 s of the scenario's wind, "
        "a press and two balls passing (docs/grass-models.md).\n");
  }
  if (faults > 0) {
    printError("simgrass sweep: %d variant%s faulted (status column in %s)\n", faults, faults == 1 ? "" : "s",
               csvPath.c_str());
    return kExitMismatch;
  }
  return kExitOk;
}
}  // namespace sg::sweep
