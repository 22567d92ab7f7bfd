// What a new user of the README's tour met (issue 18) and what now holds: `run` reports the last
// tick's contacts, a timing table leaves out the stage it cannot time on its own, `record` takes
// `run`'s flags, every command counts the same hashed ticks of one recording, and `sweep` never
// writes into the committed docs/results unless told to.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "sim/world/sim_world.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {
using nlohmann::json;

std::string scenarioPath(const std::string& name) { return test::sourcePath("scenarios/" + name); }

TEST(CliTour, RunReportsTheLastTicksContacts) {
  // The library's own count after the same ticks: the CLI must print that, not the count before
  // the first tick (always 0: it was read before the loop).
  const Scenario s = loadScenarioFile(scenarioPath("thesis-bodies.json"));
  auto world = makeWorld(s);
  const int64_t ticks = 240;
  for (int64_t t = 0; t < ticks; ++t) ASSERT_TRUE(world->step(scriptedInput(s, world->tick())).ok);
  const int64_t contacts = world->counts().contacts;
  ASSERT_GT(contacts, 0) << "the bodies rest on the ground at tick 240: the test needs contacts";

  const CliResult j = runCli("run " + quote(scenarioPath("thesis-bodies.json")) + " --ticks 240 --json");
  ASSERT_EQ(j.exitCode, 0) << j.describe();
  EXPECT_EQ(parseJson(j)["counts"].value("contacts", int64_t(-1)), contacts) << j.out;
  const CliResult t = runCli("run " + quote(scenarioPath("thesis-bodies.json")) + " --ticks 240");
  ASSERT_EQ(t.exitCode, 0) << t.describe();
  EXPECT_NE(t.out.find("bodies     3, " + std::to_string(contacts) + " contacts in the last tick"), std::string::npos)
      << t.out;
}

TEST(CliTour, StageTimesNameTheFusedRodProjection) {
  // The rod projection runs inside the integration pass: no "constraints 0.000" line of a stage
  // that is never timed; the integration's time is named for both.
  const CliResult t = runCli("run --ticks 3");
  ASSERT_EQ(t.exitCode, 0) << t.describe();
  EXPECT_NE(t.out.find("integrate+constraints "), std::string::npos) << t.out;
  EXPECT_EQ(t.out.find(" constraints "), std::string::npos) << t.out;
  const CliResult j = runCli("run --ticks 3 --json");
  ASSERT_EQ(j.exitCode, 0) << j.describe();
  const json stages = parseJson(j)["timing"]["stageMsPerTick"];
  EXPECT_TRUE(stages.contains("integrate+constraints")) << stages.dump();
  EXPECT_FALSE(stages.contains("constraints")) << stages.dump();
  EXPECT_FALSE(stages.contains("integrate")) << stages.dump();
  EXPECT_TRUE(stages.contains("wind") && stages.contains("patch-state")) << stages.dump();
}

TEST(CliTour, RecordTakesRunsFlagsAsVariants) {
  TempDir dir;
  const std::string scenario = quote(scenarioPath("lod-crossing.json"));
  const CliResult flag =
      runCli("record " + scenario + " --lod off --scalar fx16 --ticks 8 -o " + quote(dir.file("flag.sgr")) + " --json");
  ASSERT_EQ(flag.exitCode, 0) << flag.describe();
  const CliResult variant = runCli("record " + scenario + " --variant lod=off --variant scalar=fx16 --ticks 8 -o " +
                                   quote(dir.file("variant.sgr")) + " --json");
  ASSERT_EQ(variant.exitCode, 0) << variant.describe();
  const json a = parseJson(flag), b = parseJson(variant);
  EXPECT_EQ(a["variant"], b["variant"]);
  EXPECT_NE(a["variant"].get<std::string>().find("lod=off"), std::string::npos) << a.dump();
  EXPECT_NE(a["variant"].get<std::string>().find("scalar=fx16"), std::string::npos) << a.dump();
  EXPECT_EQ(a["finalHash"], b["finalHash"]);

  // The same setting twice, as a flag and as a --variant: refused, not silently one of them.
  const CliResult both =
      runCli("record " + scenario + " --lod off --variant lod=window --ticks 8 -o " + quote(dir.file("both.sgr")));
  EXPECT_EQ(both.exitCode, 2) << both.describe();
  EXPECT_TRUE(isOneLine(both.err)) << both.describe();
  EXPECT_NE(both.err.find("lod"), std::string::npos) << both.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("both.sgr")));
  const CliResult bad = runCli("record --lod sideways -o " + quote(dir.file("bad.sgr")));
  EXPECT_NE(bad.exitCode, 0) << bad.describe();
  // A given flag is a value: empty or spaced values are refused, not read as "no flag".
  for (const std::string flag : {"--interp ''", "--interp ' 2'", "--dt ''", "--interp 7", "--dt 1/0"}) {
    const CliResult r = runCli("record " + flag + " --ticks 1 -o " + quote(dir.file("flag.sgr")));
    EXPECT_EQ(r.exitCode, 2) << flag << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_NE(r.err.find(flag.substr(0, flag.find(' '))), std::string::npos) << "names the flag: " << r.err;
  }
}

TEST(CliTour, EveryCommandCountsTheSameHashedTicks) {
  // One recording, four readers: --info, --verify, diff and compare (and the viewer, in
  // ViewerPlayback) count the ticks with a recorded hash, each tick once, the start included.
  TempDir dir;
  const std::string rec = dir.file("run.sgr");
  const int64_t ticks = 12;
  ASSERT_EQ(runCli("record " + quote(scenarioPath("thesis-bodies.json")) + " --ticks " + std::to_string(ticks) +
                   " --snapshot-every 4 -o " + quote(rec))
                .exitCode,
            0);
  const json info = parseJson(runCli("replay " + quote(rec) + " --info --json"));
  EXPECT_EQ(info.value("hashedTicks", int64_t(-1)), ticks + 1) << info.dump();
  const json verify = parseJson(runCli("replay " + quote(rec) + " --verify --json"));
  EXPECT_EQ(verify.value("hashesChecked", int64_t(-1)), ticks + 1) << verify.dump();
  const json diff = parseJson(runCli("diff " + quote(rec) + " " + quote(rec) + " --json"));
  EXPECT_EQ(diff["a"].value("hashesChecked", int64_t(-1)), ticks + 1) << diff.dump();
  const json compare = parseJson(runCli("compare " + quote(rec) + " --variant threads=2 --json"));
  EXPECT_EQ(compare["reference"].value("hashesChecked", int64_t(-1)), ticks + 1) << compare.dump();
  const CliResult text = runCli("replay " + quote(rec) + " --verify");
  EXPECT_NE(text.out.find("13 of 13 hashed ticks match"), std::string::npos) << text.out;
  // diff replays only as far as the shorter run: it says how far, and of how many.
  const std::string shorter = dir.file("short.sgr");
  ASSERT_EQ(runCli("record " + quote(scenarioPath("thesis-bodies.json")) + " --ticks 6 -o " + quote(shorter)).exitCode,
            0);
  const json partial = parseJson(runCli("diff " + quote(rec) + " " + quote(shorter) + " --json"));
  EXPECT_EQ(partial["a"].value("replayedTo", int64_t(-1)), 6) << partial.dump();
  EXPECT_EQ(partial["a"].value("hashesChecked", int64_t(-1)), 7) << partial.dump();
  EXPECT_EQ(partial["a"].value("hashedTicks", int64_t(-1)), ticks + 1) << partial.dump();
  const CliResult partialText = runCli("diff " + quote(rec) + " " + quote(shorter));
  EXPECT_NE(partialText.out.find("replay verified to tick 6 (7 of 13 hashed ticks match"), std::string::npos)
      << partialText.out;
}

TEST(CliTour, SweepWritesIntoTheCurrentFolderByDefault) {
  // Run from a folder holding a docs/results of its own (as the repository root does): the
  // default output is ./sweep-results, and docs/results is left alone.
  TempDir dir;
  std::filesystem::create_directories(dir.file("docs/results"));
  const std::string committed = dir.write("docs/results/sweep.json", "{\"committed\": true}\n");
  const std::string tiny = dir.write("tiny.json",
                                     R"({"format": "simgrass-scenario/1", "name": "tiny", "timeStep": "1/60",
          "field": {"patchesX": 21, "patchesZ": 21, "spacing": 0.25}, "lod": {"mode": "off"}})");
  const CliResult r = runCli("sweep --scenarios " + quote(tiny) +
                                 " --seconds 0.05 --repeats 1 --scalars fx32 --k 1 --dt 1/60 --lod off --json",
                             dir.file(""));
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  EXPECT_TRUE(std::filesystem::exists(dir.file("sweep-results/sweep.json")));
  EXPECT_EQ(readFile(committed), "{\"committed\": true}\n");
}

}  // namespace
}  // namespace sg
