// A sweep split into jobs and merged (issue 20, docs/scale-out.md): the merged report holds the
// single-process report's numbers byte for byte; a merge refuses missing, duplicate, foreign and
// damaged shards by name; a job run again changes nothing; the job index comes from Slurm,
// Kubernetes or GNU parallel as each of them sets it, and the docs' Slurm script and Kubernetes
// commands run as written (with the scheduler's variables set by hand: no scheduler here).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "replay/cli/sweep_shard_format.h"
#include "replay/report/pareto.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {

/// `text` with every `from` replaced by `to`.
std::string replaceAll(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}
namespace fs = std::filesystem;

/// Two small scenarios (a ball and a gust; plain grass) and two variants each: 2 references + 4
/// variants.
class SweepScaleOut : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::make_unique<TempDir>();
    const std::string a = dir_->write("a.json", R"({"format": "simgrass-scenario/1", "name": "ball", "timeStep": "1/60",
 "field": {"patchesX": 21, "patchesZ": 21, "spacing": 0.25},
 "wind": {"schedule": [{"force": [0, 1, 0.9], "duration": 0.2}, {"force": [0, 0, 0], "duration": 0.2}]},
 "bodies": {"list": [{"name": "ball", "shape": {"type": "sphere", "radius": 0.3}, "mass": 0.45, "position": [-2, 0.3, 0]}]},
 "script": [{"tick": 2, "body": "ball", "command": "addVelocity", "value": [3, 0, 0]}]})");
    const std::string b =
        dir_->write("b.json", R"({"format": "simgrass-scenario/1", "name": "plain", "timeStep": "1/60",
 "field": {"patchesX": 11, "patchesZ": 11, "spacing": 0.25}})");
    settings_ = "--scenarios " + quote(a) + "," + quote(b) +
                " --seconds 0.2 --repeats 1 --scalars fx32,fx16 --k 1 --dt 1/60 --lod off";
    const CliResult plan = runCli("sweep " + settings_ + " --plan " + quote(file("plan.json")) + " --json");
    ASSERT_EQ(plan.exitCode, 0) << plan.describe();
    const json j = parseJson(plan);
    jobs_ = j.value("jobs", int64_t(0));
    refs_ = j["variants"][0].get<int64_t>();
    ASSERT_EQ(jobs_, 6);
    ASSERT_EQ(refs_, 2);
  }
  std::string file(const std::string& name) const { return dir_->file(name); }
  /// Runs jobs [from, to) of plan.json into `shards`.
  void runJobs(int64_t from, int64_t to, const std::string& shards) {
    for (int64_t j = from; j < to; ++j) {
      const CliResult r = runCli("sweep --plan " + quote(file("plan.json")) + " --job " + std::to_string(j) +
                                 " --out " + quote(file(shards)) + " --json");
      ASSERT_EQ(r.exitCode, 0) << r.describe();
    }
  }
  CliResult merge(const std::string& shards, const std::string& out) {
    return runCli("sweep --merge " + quote(file(shards)) + " --out " + quote(file(out)) + " --json");
  }
  std::unique_ptr<TempDir> dir_;
  std::string settings_;
  int64_t jobs_ = 0, refs_ = 0;
};

/// The columns that do not depend on where a job ran (every column but the costs and the flags
/// drawn from them).
const std::vector<std::string> kCostColumns = {
    "ms_per_tick", "ms_per_simulated_second", "pareto", "pareto_tip_max", "pareto_body", "pareto_model"};

void expectSameNumbers(const json& single, const json& merged) {
  ASSERT_EQ(single["rows"].size(), merged["rows"].size());
  for (size_t i = 0; i < single["rows"].size(); ++i) {
    json a = single["rows"][i], b = merged["rows"][i];
    for (const std::string& c : kCostColumns) a.erase(c), b.erase(c);
    EXPECT_EQ(a.dump(), b.dump()) << "row " << i;  // the dump: byte for byte, NaN included
  }
  EXPECT_EQ(single["scenarios"].dump(), merged["scenarios"].dump());
  for (const char* key : {"reference", "seconds", "compareEvery_s", "repeats", "threads"})
    EXPECT_EQ(single[key], merged[key]) << key;
}

/// The CSV's error columns, byte for byte (the cost columns and flags dropped).
std::vector<std::string> errorColumns(const std::string& csv) {
  std::vector<std::string> out;
  std::istringstream in(csv);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream cs(line);
    for (std::string c; std::getline(cs, c, ',');) cells.push_back(c);
    // scenario..steps (0-7), tip_rms..states_compared (10-15), status (16), model errors (20, 21)
    std::string kept;
    for (size_t k : {0, 1, 2, 3, 4, 5, 6, 7, 10, 11, 12, 13, 14, 15, 16, 20, 21})
      kept += (k < cells.size() ? cells[k] : std::string("?")) + ",";
    out.push_back(kept);
  }
  return out;
}

TEST_F(SweepScaleOut, TwoGnuParallelWorkersGiveTheSingleProcessReport) {
  if (test::slowBuild()) GTEST_SKIP() << "the same code as the release run: Release builds only";
  ASSERT_EQ(std::system("command -v parallel >/dev/null 2>&1"), 0)
      << "GNU parallel (Debian package parallel) is part of the test command's packages";
  const CliResult single = runCli("sweep " + settings_ + " --out " + quote(file("single")) + " --json");
  ASSERT_EQ(single.exitCode, 0) << single.describe();
  // The references, then the variants, two workers each, as docs/scale-out.md does.
  const std::string cli = quote(SIMGRASS_CLI), plan = quote(file("plan.json")), shards = quote(file("shards"));
  for (const auto& [from, to] : {std::pair<int64_t, int64_t>{0, refs_ - 1}, {refs_, jobs_ - 1}}) {
    const std::string cmd = "parallel -j 2 " + cli + " sweep --plan " + plan + " --job {} --out " + shards +
                            " --json ::: $(seq " + std::to_string(from) + " " + std::to_string(to) + ")";
    ASSERT_EQ(std::system(("timeout 120 bash -c " + quote(cmd) + " >/dev/null").c_str()), 0) << cmd;
  }
  const CliResult merged = merge("shards", "merged");
  ASSERT_EQ(merged.exitCode, 0) << merged.describe();
  const json s = parseJson(single), m = parseJson(merged);
  expectSameNumbers(s, m);
  EXPECT_EQ(errorColumns(readFile(file("single/sweep.csv"))), errorColumns(readFile(file("merged/sweep.csv"))));
  // The Pareto flags: the merge's code on the single run's costs gives the single run's flags.
  for (size_t scenario = 0; scenario < 2; ++scenario) {
    std::vector<double> cost, tipRms;
    std::vector<bool> ok, flags;
    const std::string name = s["scenarios"][scenario]["name"];
    for (size_t i = 0; i < s["rows"].size(); ++i) {
      if (s["rows"][i]["scenario"] != name) continue;
      cost.push_back(s["rows"][i]["ms_per_simulated_second"]);
      tipRms.push_back(m["rows"][i]["tip_rms_m"]);
      ok.push_back(m["rows"][i]["status"] == "ok");
      flags.push_back(s["rows"][i]["pareto"]);
    }
    EXPECT_EQ(paretoFront(cost, tipRms, ok), flags) << name;
  }
}

TEST_F(SweepScaleOut, MergeRefusesMissingDuplicateForeignAndDamagedShards) {
  runJobs(0, jobs_, "shards");
  auto refused = [&](const std::string& shards, const std::string& expected) {
    const CliResult r = merge(shards, "out-" + shards);
    EXPECT_EQ(r.exitCode, 2) << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_NE(r.err.find(expected), std::string::npos) << "expected '" << expected << "' in\n" << r.err;
  };
  auto copyOf = [&](const std::string& to) {
    fs::copy(file("shards"), file(to), fs::copy_options::recursive);
    return file(to);
  };
  fs::remove(copyOf("missing") + "/shard-000003.sgs");
  refused("missing", "job 3 (ball: scalar=fx16 interp=1 dt=1/60 lod=off broadphase=grid): missing from");
  fs::copy_file(file("shards/shard-000002.sgs"), copyOf("twice") + "/again.sgs");
  refused("twice", "job 2 (ball: scalar=fx32 interp=1 dt=1/60 lod=off broadphase=grid): two shards, ");
  // A shard of another plan (one more second of simulation: another fingerprint).
  const std::string other = file("other.json");
  const std::string otherSettings = replaceAll(settings_, "--seconds 0.2", "--seconds 0.25");
  ASSERT_EQ(runCli("sweep " + otherSettings + " --plan " + quote(other)).exitCode, 0);
  for (int64_t j : {0, 3})
    ASSERT_EQ(runCli("sweep --plan " + quote(other) + " --job " + std::to_string(j) + " --out " + quote(file("theirs")))
                  .exitCode,
              0);
  fs::copy_file(file("theirs/shard-000003.sgs"), copyOf("foreign") + "/shard-000003.sgs",
                fs::copy_options::overwrite_existing);
  refused("foreign", "shard-000003.sgs: $.fingerprint: expected a shard of this plan");
  // One byte changed anywhere: the checksum (the offset named).
  const std::string damaged = copyOf("damaged") + "/shard-000005.sgs";
  {
    std::fstream f(damaged, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(40);
    f.put('#');
  }
  refused("damaged", "shard-000005.sgs: byte ");
  fs::resize_file(copyOf("cut") + "/shard-000000.sgs", 100);
  refused("cut", "shard-000000.sgs: byte ");
  std::ofstream(copyOf("garbage") + "/shard-000002.sgs") << "not a shard";
  refused("garbage", "shard-000002.sgs: byte 0: expected a sweep shard (SGSWEEP1)");
  // A variant whose reference shard is not there yet: one line naming the job to run first.
  const CliResult early = runCli("sweep --plan " + quote(file("plan.json")) + " --job 4 --out " + quote(file("empty")));
  EXPECT_EQ(early.exitCode, 2) << early.describe();
  EXPECT_NE(early.err.find("job 4 needs the reference shard of job 1"), std::string::npos) << early.err;
  // A plan whose inputs changed since: refused before any job runs.
  std::ofstream(file("b.json"), std::ios::app) << "\n";
  const CliResult changed = runCli("sweep --plan " + quote(file("plan.json")) + " --job 1 --out " + quote(file("x")));
  EXPECT_EQ(changed.exitCode, 2);
  EXPECT_NE(changed.err.find("a scenario or a file it reads changed since"), std::string::npos) << changed.err;
}

TEST_F(SweepScaleOut, ADamagedPlanIsOneLineNamingItsJsonPath) {
  const json good = json::parse(readFile(file("plan.json")));
  auto refused = [&](const std::string& text, const std::string& expected) {
    const std::string bad = dir_->write("bad-plan.json", text);
    const CliResult r = runCli("sweep --plan " + quote(bad) + " --job 0 --out " + quote(file("s")));
    EXPECT_EQ(r.exitCode, 2) << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_NE(r.err.find(expected), std::string::npos) << "expected '" << expected << "' in\n" << r.err;
  };
  refused("not json", "bad-plan.json: $: expected a sweep plan");
  json j = good;
  j["format"] = "simgrass-sweep-plan/9";
  refused(j.dump(), "$.format: expected 'simgrass-sweep-plan/1'");
  j = good;
  j["build"] = "simgrass 0.0.1 other";
  refused(j.dump(), "$.build: expected a plan of this build");
  j = good;
  j["options"].erase("seconds");
  refused(j.dump(), "$.options.seconds: expected a value (missing)");
  j = good;
  j["options"]["repeats"] = "3";
  refused(j.dump(), "$.options.repeats: expected an integer");
  j = good;
  j["options"]["repeats"] = 100000;
  refused(j.dump(), "$.options.repeats: expected 1 to 100");
  j = good;
  j["options"]["k"] = "1,9";
  refused(j.dump(), "$.options: --k: expected a comma-separated list of 1, 2, 3, 4, got '9'");
  j = good;
  j["fingerprint"] = "0000000000000000";
  refused(j.dump(), "$.fingerprint: expected the inputs the plan was made from");
  const CliResult missing = runCli("sweep --merge " + quote(file("nothing")) + " --out " + quote(file("o")));
  EXPECT_EQ(missing.exitCode, 2);
  EXPECT_NE(missing.err.find("nothing/plan.json: $: expected"), std::string::npos) << missing.err;
}

TEST_F(SweepScaleOut, WhatAReviewerBrokeStaysFixed) {
  const std::string plan = quote(file("plan.json"));
  // An empty --job (`--job "$SLURM_ARRAY_TASK_ID"` outside Slurm) must not become "write a fresh
  // default plan over the shared one"; nor --plan with --out but no --job.
  const std::string before = readFile(file("plan.json"));
  for (const std::string& args :
       {"--plan " + plan + " --job '' --out " + quote(file("s")), "--plan " + plan + " --out " + quote(file("s")),
        "--merge '' --out " + quote(file("s")), "--plan '' --job 0 --out " + quote(file("s"))}) {
    const CliResult r = runCli("sweep " + args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  }
  EXPECT_EQ(readFile(file("plan.json")), before) << "the plan file was rewritten";

  // A shards folder holding another plan's copy: the job refuses before it runs (the merge would
  // otherwise refuse every new shard).
  fs::create_directories(file("mixed"));
  ASSERT_EQ(runCli("sweep " + replaceAll(settings_, "--seconds 0.2", "--seconds 0.25") + " --plan " +
                   quote(file("mixed/plan.json")))
                .exitCode,
            0);
  const CliResult mixed = runCli("sweep --plan " + plan + " --job 0 --out " + quote(file("mixed")));
  EXPECT_EQ(mixed.exitCode, 2) << mixed.describe();
  EXPECT_NE(mixed.err.find("shards of two plans in one folder"), std::string::npos) << mixed.err;
  EXPECT_FALSE(fs::exists(file("mixed/shard-000000.sgs")));

  // A merge needs no scenario file: it runs from another folder, after the inputs changed.
  runJobs(0, jobs_, "shards");
  const std::string scenarioB = readFile(file("b.json"));
  std::ofstream(file("b.json"), std::ios::app) << "\n";
  TempDir elsewhere;
  const CliResult away = runCli("sweep --merge " + quote(file("shards")) + " --out results --json", elsewhere.file(""));
  EXPECT_EQ(away.exitCode, 0) << away.describe();
  EXPECT_TRUE(fs::exists(elsewhere.file("results/sweep.json")));
  std::ofstream(file("b.json"), std::ios::trunc) << scenarioB;  // as planned again, for the jobs below

  // A zstd bomb in a reference shard (100 MB of zeros in a few kB): the variant job refuses it by
  // the payload bound this plan allows (well under a megabyte here), before allocating it.
  const json header = json::parse(std::string(readFile(file("shards/shard-000000.sgs")).substr(12, [&] {
    const std::string b = readFile(file("shards/shard-000000.sgs"));
    return size_t(uint8_t(b[8])) | size_t(uint8_t(b[9])) << 8 | size_t(uint8_t(b[10])) << 16 |
           size_t(uint8_t(b[11])) << 24;
  }())));
  const std::vector<uint8_t> bomb = sweep::shardBytes(header, std::vector<uint8_t>(size_t(100) << 20, 0));
  ASSERT_LT(bomb.size(), size_t(1) << 20);
  fs::create_directories(file("bombed"));
  std::ofstream(file("bombed/shard-000000.sgs"), std::ios::binary)
      .write(reinterpret_cast<const char*>(bomb.data()), std::streamsize(bomb.size()));
  fs::copy_file(file("shards/plan.json"), file("bombed/plan.json"));
  const CliResult bombed = runCli("sweep --plan " + plan + " --job 2 --out " + quote(file("bombed")));
  EXPECT_EQ(bombed.exitCode, 2) << bombed.describe();
  EXPECT_NE(bombed.err.find("a zstd payload of a known size within the plan's bounds"), std::string::npos)
      << bombed.err;

  // Numbers in a forged header (the checksum recomputed) are held to what the plan's runs give.
  const std::string variant = readFile(file("shards/shard-000003.sgs"));
  const size_t textBytes = size_t(uint8_t(variant[8])) | size_t(uint8_t(variant[9])) << 8;
  for (const auto& [key, value] :
       std::vector<std::pair<std::string, json>>{{"steps", -5},
                                                 {"summary.ticks", -1},
                                                 {"summary.ticks", 0},
                                                 // Text that reaches the terminal and sweep.csv (an
                                                 // independent pass, 2026-11-29): a newline and a
                                                 // colour escape, and a page of it.
                                                 {"fault", "tick 3\n\x1b[31mred"},
                                                 {"fault", std::string(100000, 'x')}}) {
    json h = json::parse(variant.substr(12, textBytes));
    if (key == "summary.ticks")
      h["summary"]["ticks"] = value;
    else
      h[key] = value;
    fs::remove_all(file("forged"));
    fs::copy(file("shards"), file("forged"), fs::copy_options::recursive);
    const std::vector<uint8_t> bytes = sweep::shardBytes(h, {});
    std::ofstream(file("forged/shard-000003.sgs"), std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    const CliResult r = merge("forged", "forged-out");
    EXPECT_EQ(r.exitCode, 2) << key << " = " << value << "\n" << r.describe();
    EXPECT_NE(r.err.find("shard-000003.sgs: $." + key), std::string::npos) << r.err;
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  }
  // A reference shard's patch count: at least one, at most its scenario's field (10^12 and 0
  // merged before).
  const std::vector<uint8_t> referenceBytes = [&] {
    const std::string b = readFile(file("shards/shard-000000.sgs"));
    return std::vector<uint8_t>(b.begin(), b.end());
  }();
  const sweep::Shard reference = sweep::parseShard(referenceBytes, "shard-000000.sgs", uint64_t(1) << 30, true);
  for (const int64_t patches : {int64_t(0), int64_t(1000000000000)}) {
    json h = reference.header;
    h["patches"] = patches;
    fs::remove_all(file("forged"));
    fs::copy(file("shards"), file("forged"), fs::copy_options::recursive);
    const std::vector<uint8_t> bytes = sweep::shardBytes(h, reference.payload);
    std::ofstream(file("forged/shard-000000.sgs"), std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    const CliResult r = merge("forged", "forged-out");
    EXPECT_EQ(r.exitCode, 2) << patches << " patches\n" << r.describe();
    EXPECT_NE(r.err.find("shard-000000.sgs: $.patches"), std::string::npos) << r.err;
  }
}

TEST_F(SweepScaleOut, AJobRunAgainReplacesItsShardAndChangesNoNumber) {
  if (test::slowBuild()) GTEST_SKIP() << "no parsing the other tests lack: Release builds only";
  runJobs(0, jobs_, "shards");
  const CliResult first = merge("shards", "first");
  ASSERT_EQ(first.exitCode, 0) << first.describe();
  runJobs(0, 1, "shards");  // a reference again (its variants' shards stay valid: the same bits)
  runJobs(5, 6, "shards");
  const CliResult again = merge("shards", "again");
  ASSERT_EQ(again.exitCode, 0) << again.describe();
  expectSameNumbers(parseJson(first), parseJson(again));
  size_t shards = 0;
  for (const auto& e : fs::directory_iterator(file("shards"))) shards += e.path().extension() == ".sgs";
  EXPECT_EQ(shards, size_t(jobs_));
}

TEST_F(SweepScaleOut, TheSchedulersIndexesAndTheDocsScriptsAsWritten) {
  if (test::slowBuild()) GTEST_SKIP() << "scripts and environment variables: Release builds only";
  // --job env: Slurm's, Kubernetes' and GNU parallel's variables (PARALLEL_SEQ counts from 1).
  const std::string plan = quote(file("plan.json"));
  auto envJob = [&](const std::string& var, const std::string& value, const std::string& extra = "") {
    const std::string cmd = "env -u SLURM_ARRAY_TASK_ID -u JOB_COMPLETION_INDEX -u PARALLEL_SEQ " + var + "=" + value +
                            " " + quote(SIMGRASS_CLI) + " sweep --plan " + plan + " --job env " + extra + " --out " +
                            quote(file("env")) + " --json";
    const int status = std::system(("timeout 60 " + cmd + " >/dev/null 2>" + quote(file("env.err"))).c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  EXPECT_EQ(envJob("SLURM_ARRAY_TASK_ID", "0"), 0);
  EXPECT_EQ(envJob("JOB_COMPLETION_INDEX", "0", "--job-offset 1"), 0);  // job 1
  EXPECT_EQ(envJob("PARALLEL_SEQ", "3"), 0);                            // job 2
  EXPECT_TRUE(fs::exists(file("env/shard-000000.sgs")) && fs::exists(file("env/shard-000001.sgs")) &&
              fs::exists(file("env/shard-000002.sgs")));
  EXPECT_EQ(envJob("PARALLEL_SEQ", "0"), 2);
  EXPECT_EQ(envJob("SLURM_ARRAY_TASK_ID", "6"), 2) << "out of range";
  EXPECT_EQ(envJob("JOB_COMPLETION_INDEX", "x"), 2);
  EXPECT_TRUE(isOneLine(readFile(file("env.err"))));
  const CliResult none = runCli("sweep --plan " + plan + " --job env --out " + quote(file("env")));
  EXPECT_EQ(none.exitCode, 2);  // no scheduler variable (ctest sets none of them)
  const CliResult settings = runCli("sweep --plan " + plan + " --job 0 --k 2 --out " + quote(file("env")));
  EXPECT_EQ(settings.exitCode, 2);
  EXPECT_NE(settings.err.find("--k: expected no settings with --job (the plan holds them)"), std::string::npos);

  // docs/scale-out/sweep.sbatch, as Slurm runs each array element: references, then variants.
  const std::string sbatch = quote(test::sourcePath("docs/scale-out/sweep.sbatch"));
  for (int64_t j = 0; j < jobs_; ++j) {
    const std::string cmd = "cd " + quote(file("")) + " && SLURM_SUBMIT_DIR=" + quote(file("")) +
                            " SLURM_ARRAY_TASK_ID=" + std::to_string(j) + " SIMGRASS=" + quote(SIMGRASS_CLI) +
                            " SHARDS=slurm bash " + sbatch + " >/dev/null";
    ASSERT_EQ(std::system(("timeout 60 bash -c " + quote(cmd)).c_str()), 0) << cmd;
  }
  EXPECT_EQ(merge("slurm", "slurm-results").exitCode, 0);

  // docs/scale-out/sweep-jobs.yaml: each Job's command, as its pods run it (JOB_COMPLETION_INDEX
  // from 0; the variants' Job with its --job-offset, which the YAML gives for R = 2, as here).
  const std::string yaml = readFile(test::sourcePath("docs/scale-out/sweep-jobs.yaml"));
  std::vector<std::string> commands;
  // Each `command: ["a", "b", ...]` line's words (no std::regex: GCC 12's -O1 -Wmaybe-uninitialized
  // misfires inside <regex> in the sanitizer preset).
  for (size_t at = yaml.find("command: ["); at != std::string::npos; at = yaml.find("command: [", at + 1)) {
    const size_t end = yaml.find(']', at);
    const std::string list = yaml.substr(at + 10, end - at - 10);
    std::string args;
    for (size_t q = list.find('"'); q != std::string::npos; q = list.find('"', list.find('"', q + 1) + 1)) {
      const std::string w = list.substr(q + 1, list.find('"', q + 1) - q - 1);
      args += " " + (w == "simgrass" ? quote(SIMGRASS_CLI) : quote(w));
    }
    commands.push_back(args);
  }
  ASSERT_EQ(commands.size(), 2u) << "two Jobs: the references and the variants";
  EXPECT_NE(commands[1].find("'--job-offset' '2'"), std::string::npos) << commands[1];
  const int64_t counts[2] = {refs_, jobs_ - refs_};
  for (int stage = 0; stage < 2; ++stage)
    for (int64_t i = 0; i < counts[stage]; ++i) {
      const std::string cmd = "cd " + quote(file("")) + " && JOB_COMPLETION_INDEX=" + std::to_string(i) +
                              commands[size_t(stage)] + " --json >/dev/null";
      ASSERT_EQ(std::system(("timeout 60 bash -c " + quote(cmd)).c_str()), 0) << cmd;
    }
  EXPECT_EQ(merge("shards", "k8s-results").exitCode, 0);
}

}  // namespace
}  // namespace sg
