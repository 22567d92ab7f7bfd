#include "replay/cli/sweep_command.h"

#include <cinttypes>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "replay/cli/cli_common.h"
#include "replay/cli/sweep_engine.h"
#include "replay/cli/sweep_report.h"
#include "replay/cli/sweep_shards.h"
#include "replay/progress.h"
#include "sim/scenario/scenario.h"

namespace sg {
namespace {
struct SweepCommandOptions {
  sweep::Options run;
  std::string out = "sweep-results";  // never the committed docs/results by default
  bool json = false;
  // Scale-out (docs/scale-out.md).
  std::string plan, job, merge;
  int64_t jobOffset = 0;
};

/// One process: the references, then every variant; repeats are the outer loop so that each
/// variant's timings are spread over the whole sweep (a busy minute does not hit one variant only).
int sweepHere(const SweepCommandOptions& o) {
  sweep::Plan plan;
  try {
    plan = sweep::makePlan(o.run, true);
  } catch (const std::exception& e) {  // std::invalid_argument (an option), ScenarioError (a file)
    printError("simgrass sweep: %s\n", e.what());
    return kExitBadInput;
  }
  if (!sweep::checkOutputs(plan, o.out)) return kExitBadInput;
  const int64_t ticks = plan.ticks;
  ProgressBar bar("sweep", int64_t(plan.scenarios.size()) * ticks + int64_t(plan.rows.size()) * o.run.repeats * ticks,
                  !o.json);
  int64_t done = 0;
  for (size_t s = 0; s < plan.scenarios.size(); ++s) {
    try {
      sweep::runReference(plan, s);
    } catch (const std::exception& e) {
      bar.finish();
      printError("simgrass sweep: %s\n", e.what());
      return kExitMismatch;
    }
    done += ticks;
    bar.update(done);
  }
  for (int rep = 0; rep < o.run.repeats; ++rep)
    for (sweep::Row& r : plan.rows) {
      if (!r.fault.empty()) continue;
      const int64_t base = done;
      sweep::runVariant(plan, r, rep == 0, [&](int64_t t) { bar.update(base + t); });
      done = base + ticks;
      bar.update(done);
    }
  bar.finish();
  sweep::finishRows(plan);
  return sweep::writeReport(plan, o.out, o.json);
}

/// --plan without --job: writes the plan file and says what to run.
int writePlanFile(const SweepCommandOptions& o) {
  sweep::Plan plan;
  try {
    plan = sweep::makePlan(o.run, false);
  } catch (const std::exception& e) {
    printError("simgrass sweep: %s\n", e.what());
    return kExitBadInput;
  }
  if (overwritesInput("sweep", "--plan", o.plan, [&] {
        std::vector<std::string> in;
        for (const sweep::ScenarioRun& sc : plan.scenarios) in.push_back(sc.file);
        return in;
      }()))
    return kExitBadInput;
  if (!sweep::writePlan(plan, o.plan)) return kExitBadInput;
  const int64_t refs = sweep::referenceJobs(plan), jobs = sweep::jobCount(plan);
  if (o.json) {
    nlohmann::json j = {{"plan", o.plan},
                        {"fingerprint", sweep::fingerprintOf(plan)},
                        {"jobs", jobs},
                        {"references", {0, refs - 1}},
                        {"variants", {refs, jobs - 1}}};
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("plan       %s: %" PRId64 " jobs (fingerprint %s)\n", escapeControl(o.plan).c_str(), jobs,
                sweep::fingerprintOf(plan).c_str());
    std::printf("references jobs 0 to %" PRId64 " (run these first: each variant reads its scenario's)\n", refs - 1);
    std::printf("variants   jobs %" PRId64 " to %" PRId64 "\n", refs, jobs - 1);
    std::printf("run        simgrass sweep --plan %s --job I --out SHARDS  (I: a number, or env)\n",
                escapeControl(o.plan).c_str());
    std::printf("merge      simgrass sweep --merge SHARDS --out RESULTS\n");
  }
  return kExitOk;
}

int runOneJob(const SweepCommandOptions& o) {
  std::string fingerprint;
  sweep::Plan plan;
  try {
    plan = sweep::readPlan(o.plan, &fingerprint);
  } catch (const std::exception& e) {
    printError("simgrass sweep: %s\n", e.what());
    return kExitBadInput;
  }
  int64_t job = 0;
  try {
    job = sweep::jobIndex(o.job, o.jobOffset, sweep::jobCount(plan));
  } catch (const std::invalid_argument& e) {
    printError("simgrass sweep: %s\n", e.what());
    return kExitBadInput;
  }
  return sweep::runJob(plan, fingerprint, job, o.out, o.json);
}

int mergeShardFolder(const SweepCommandOptions& o) {
  const std::string planPath = o.plan.empty() ? (std::filesystem::path(o.merge) / "plan.json").string() : o.plan;
  std::string fingerprint, error;
  sweep::Plan plan;
  try {
    plan = sweep::readPlanForMerge(planPath, &fingerprint);
  } catch (const std::exception& e) {
    printError("simgrass sweep: --merge: %s\n", e.what());
    return kExitBadInput;
  }
  if (!sweep::mergeShards(plan, fingerprint, o.merge, &error)) {
    printError("simgrass sweep: --merge: %s\n", error.c_str());
    return kExitBadInput;
  }
  if (!sweep::checkOutputs(plan, o.out)) return kExitBadInput;
  sweep::finishRows(plan);
  return sweep::writeReport(plan, o.out, o.json);
}

int sweepCommand(const SweepCommandOptions& o, const CLI::App& cmd) {
  // The plan holds every setting of a sharded sweep: its jobs and its merge take none.
  static constexpr const char* kRunOptions[] = {"--scenarios", "--seconds",    "--scalars", "--k",       "--dt",
                                                "--lod",       "--broadphase", "--models",  "--repeats", "--threads"};
  // Given but empty (`--job "$SLURM_ARRAY_TASK_ID"` outside Slurm): never read as "not given", which
  // would turn a job into writing a fresh default plan over the shared one.
  for (const char* name : {"--plan", "--job", "--merge", "--out"})
    if (cmd.count(name) > 0 && cmd.get_option(name)->as<std::string>().empty()) {
      printError("simgrass sweep: %s: expected a value, got an empty one\n", name);
      return kExitBadInput;
    }
  const bool sharded = !o.job.empty() || !o.merge.empty();
  if (sharded)
    for (const char* name : kRunOptions)
      if (cmd.count(name) > 0) {
        printError("simgrass sweep: %s: expected no settings with %s (the plan holds them)\n", name,
                   o.merge.empty() ? "--job" : "--merge");
        return kExitBadInput;
      }
  if (!o.job.empty() && !o.merge.empty()) {
    printError("simgrass sweep: --job, --merge: expected one of the two, got both\n");
    return kExitBadInput;
  }
  if (!o.job.empty() && o.plan.empty()) {
    printError("simgrass sweep: --job: expected --plan PLAN.json (the plan the job belongs to)\n");
    return kExitBadInput;
  }
  if (!o.job.empty() && cmd.count("--out") == 0) {
    printError("simgrass sweep: --job: expected --out SHARDS (the folder of the plan's shards)\n");
    return kExitBadInput;
  }
  if (o.jobOffset != 0 && o.job.empty()) {
    printError("simgrass sweep: --job-offset: expected --job too\n");
    return kExitBadInput;
  }
  if (!o.merge.empty()) return mergeShardFolder(o);
  if (!o.job.empty()) return runOneJob(o);
  if (!o.plan.empty() && cmd.count("--out") > 0) {  // a job whose --job was left out
    printError(
        "simgrass sweep: --plan, --out: expected --job I to run a job of the plan into --out (--plan alone "
        "writes the plan and runs nothing)\n");
    return kExitBadInput;
  }
  if (!o.plan.empty()) return writePlanFile(o);
  return sweepHere(o);
}
}  // namespace

void addSweepCommand(CLI::App& app, int* exitCode) {
  auto o = std::make_shared<SweepCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "sweep",
      "Every variant (scalar x k x dt x LOD) against a double, k=1, dt=1/240 reference: cost per simulated "
      "second against tip and body error; CSV, JSON and PNG plots with the Pareto front");
  cmd->add_option("--scenarios", o->run.scenarios, "Comma-separated scenario files")->capture_default_str();
  cmd->add_option("--seconds", o->run.seconds, "Simulated seconds per run")
      ->check(CLI::Range(1e-3, 3600.0))
      ->capture_default_str();
  cmd->add_option("--out", o->out, "Folder for sweep.csv, sweep.json and the plots (created if missing)")
      ->capture_default_str();
  cmd->add_option("--scalars", o->run.scalars, "Scalars to sweep (subset of fx16,fx32,float,double)")
      ->capture_default_str();
  cmd->add_option("--k", o->run.ks, "Interpolation factors to sweep (subset of 1,2,3,4)")->capture_default_str();
  cmd->add_option("--dt", o->run.dts, "Time steps to sweep (whole multiples or fractions of the reference's 1/240)")
      ->capture_default_str();
  cmd->add_option("--lod", o->run.lods, "Level-of-detail modes to sweep (subset of off,window)")->capture_default_str();
  cmd->add_option("--broadphase", o->run.broadphases,
                  "Particle broad phases to sweep (grid,brute; results are identical)")
      ->capture_default_str();
  cmd->add_option("--models", o->run.models,
                  "Grass models to sweep (subset of thesis,pbd,blade), each against its own reference; "
                  "default: each scenario's own model");
  cmd->add_option("--physics", o->run.physics,
                  "Where the grass stages run, swept (subset of cpu,gpu,gpu-readback; a device path takes the scalars "
                  "that have one: not double; docs/gpu-physics.md)")
      ->capture_default_str();
  cmd->add_option("--repeats", o->run.repeats, "Timed runs per variant (the cost is their median)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--threads", o->run.threads, "Worker threads per run")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  cmd->add_flag("--json", o->json, "Print sweep.json on stdout instead of the table");
  // Scale-out (docs/scale-out.md).
  cmd->add_option("--plan", o->plan,
                  "Write the plan of this sweep (its jobs) to this file and stop; with --job: the plan the job is of");
  cmd->add_option("--job", o->job,
                  "Run one job of --plan into --out: an index from 0, or 'env' (SLURM_ARRAY_TASK_ID, "
                  "JOB_COMPLETION_INDEX, or GNU parallel's PARALLEL_SEQ - 1)");
  cmd->add_option("--job-offset", o->jobOffset, "Added to the --job index (a Kubernetes Job of the variants only)")
      ->check(CLI::Range(int64_t(0), int64_t(1) << 40));
  cmd->add_option("--merge", o->merge,
                  "Merge the shards of this folder (every job once, of one plan) into --out's CSV, JSON and plots");
  cmd->footer(
      "Exit codes: 0 ok, 1 the reference or a variant faulted (the variant's row says so), 2 bad input.\n"
      "Scale-out: --plan P writes the jobs; --plan P --job I --out SHARDS runs one; --merge SHARDS --out R merges "
      "(docs/scale-out.md).");
  cmd->callback([o, exitCode, cmd] { *exitCode = sweepCommand(*o, *cmd); });
}
}  // namespace sg
