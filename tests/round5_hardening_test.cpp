// Hostile inputs an independent pass found accepted or misreported (2026-11-28, round 5;
// docs/robustness.md): empty option values that ran as if the option were absent, and the
// further cases below. Each must be one line naming the place, and exit 2.
#include <gtest/gtest.h>

#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// `simgrass run` of a scenario written into `dir` as `name`, with `args`.
CliResult runScenario(TempDir& dir, const std::string& name, const std::string& text, const std::string& args) {
  return runCli("run " + quote(dir.write(name, text)) + " " + args);
}

/// Refused as bad input: exit 2, one line, saying `phrase`.
void expectRefused(const CliResult& r, const std::string& phrase) {
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err));
  EXPECT_TRUE(contains(r.err, phrase)) << r.err;
}

/// The options of `simgrass <command> --help` that take a value ("  --name TYPE", one space between
/// them; a flag's description follows after a wider gap), and its positionals.
std::vector<std::string> valueOptions(const std::string& command) {
  const CliResult help = runCli(command + " --help");
  EXPECT_EQ(help.exitCode, 0) << help.describe();
  std::vector<std::string> options;
  // A build without the viewer (the sanitizer build) has a `render` that takes nothing.
  if (command == "render" && help.out.find("needs a build with the viewer") != std::string::npos) return options;
  const std::regex option(R"(^  (?:-\w,)?(--[\w-]+) [A-Z]+\b)"), positional(R"(^  ([a-z][\w-]*) [A-Z]+\b)");
  std::istringstream lines(help.out);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_search(line, m, option) || std::regex_search(line, m, positional)) options.push_back(m[1]);
  }
  return options;
}

TEST(Round5Hardening, EveryOptionRefusesAnEmptyValue) {
  // `replay --export-state ''`, `diff --csv ''`, `compare --series ''`, `render --debug ''` or
  // `record --input ''` ran as if the option were absent, exit 0; `run ''` ran the built-in
  // meadow. Every option of every command that takes a value is tried, from its --help, so an
  // option added later is held to it too.
  size_t tried = 0;
  for (const std::string command : {"run", "record", "replay", "diff", "compare", "sweep", "render"}) {
    const std::vector<std::string> options = valueOptions(command);
    if (options.empty() && command == "render") continue;  // the stub of a build without the viewer
    EXPECT_GE(options.size(), 3u) << command << ": the --help parse found too few options";
    std::string positionalsBefore;  // `diff x ''`: the second positional empty, the first not
    for (const std::string& option : options) {
      const bool positional = option.rfind("--", 0) != 0;
      const CliResult r = runCli(command + (positional ? positionalsBefore + " ''" : " " + option + " ''"));
      if (positional) positionalsBefore += " x";
      EXPECT_EQ(r.exitCode, 2) << command << " " << option << " ''\n" << r.describe();
      EXPECT_TRUE(isOneLine(r.err)) << command << " " << option;
      EXPECT_TRUE(contains(r.err, option + ": expected")) << command << " " << option << ": " << r.err;
      ++tried;
    }
  }
  EXPECT_GE(tried, 50u);  // 72 with the viewer's render, 61 without
}

TEST(Round5Hardening, ABladeFileThatAsksForThePushIsRefused) {
  // The blade always holds: "tipContact": "push" with "model": "blade" ran exactly as "hold"
  // (the same hash, the same fingerprint). "hold", or no key, runs; a thesis file still pushes.
  TempDir dir;
  const std::string blade = R"({"field": {"patchesX": 6, "patchesZ": 6}, "particles": {"model": "blade"},
      "bodies": {"tipContact": "TIP", "list": [{"name": "b", "shape": {"type": "sphere", "radius": 0.3}}]}})";
  auto with = [&](const std::string& tip) {
    std::string text = blade;
    text.replace(text.find("TIP"), 3, tip);
    return dir.write(tip + ".json", text);
  };
  const CliResult push = runCli("run " + quote(with("push")) + " --ticks 1");
  EXPECT_EQ(push.exitCode, 2) << push.describe();
  EXPECT_TRUE(isOneLine(push.err));
  EXPECT_TRUE(contains(push.err, "$.bodies.tipContact: expected \"hold\" or no tipContact")) << push.err;
  const CliResult hold = runCli("run " + quote(with("hold")) + " --ticks 1");
  EXPECT_EQ(hold.exitCode, 0) << hold.describe();
}

TEST(Round5Hardening, EveryListedBodyIsAddressableByIndexAsByName) {
  // 65 listed bodies: `"body": "b64"` worked and recorded INPT index 64, `"body": 64` was refused
  // ("0 to 63"). Indices now run to max(64, listed) - 1 in scripts, tracks and recordings alike.
  TempDir dir;
  std::string list, script;
  for (int i = 0; i < 65; ++i)
    list += std::string(i ? "," : "") + R"({"name": "b)" + std::to_string(i) +
            R"(", "shape": {"type": "sphere", "radius": 0.1}, "position": [)" + std::to_string((i % 9) * 0.3 - 1.2) +
            ", 0.1, " + std::to_string((i / 9) * 0.3 - 1.2) + "]}";
  auto scenario = [&](const std::string& body) {
    return dir.write("s" + body + ".json", R"({"field": {"patchesX": 12, "patchesZ": 12}, "bodies": {"list": [)" +
                                               list + R"(]}, "script": [{"tick": 2, "body": )" + body +
                                               R"(, "command": "teleport", "value": [0, 2, 0]}]})");
  };
  const CliResult byIndex = runCli("run " + quote(scenario("64")) + " --ticks 4");
  const CliResult byName = runCli("run " + quote(scenario("\"b64\"")) + " --ticks 4");
  ASSERT_EQ(byIndex.exitCode, 0) << byIndex.describe();
  ASSERT_EQ(byName.exitCode, 0) << byName.describe();
  const auto hashLine = [](const std::string& out) { return out.substr(out.find("hash")); };
  EXPECT_EQ(hashLine(byIndex.out).substr(0, 40), hashLine(byName.out).substr(0, 40));
  const CliResult past = runCli("run " + quote(scenario("65")) + " --ticks 4");
  EXPECT_EQ(past.exitCode, 2) << past.describe();
  EXPECT_TRUE(contains(past.err, "$.script[0].body: expected an integer from 0 to 64, got 65")) << past.err;
}

TEST(Round5Hardening, ListsNameEachValueOnceAndHaveNoEmptyItems) {
  // `sweep --k 1,1` ran the same variant twice (16 identical rows fed the Pareto plots);
  // `--variant 'interp=2,'` ran as `interp=2`.
  TempDir dir;
  const std::string base = " --seconds 0.05 --repeats 1 --out " + quote(dir.file("out"));
  for (const auto& [args, phrase] : std::vector<std::pair<std::string, std::string>>{
           {"--k 1,1 --scalars fx32 --dt 1/60 --lod off", "--k: expected each value once, got '1' twice"},
           {"--k 1 --scalars fx32,fx32 --dt 1/60 --lod off", "--scalars: expected each value once"},
           {"--k 1 --scalars fx32 --dt 1/60,2/120 --lod off", "--dt: expected each value once, got '2/120' twice"},
           {"--k 1 --scalars fx32 --dt 1/60 --lod off,off", "--lod: expected each value once"},
           {"--scenarios scenarios/thesis-meadow.json,scenarios/thesis-meadow.json --k 1 --scalars fx32 --dt 1/60",
            "expected each scenario file once"}}) {
    const CliResult r = runCli("sweep " + args + base, test::sourcePath("."));
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << args;
    EXPECT_TRUE(contains(r.err, phrase)) << args << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(dir.file("out")));
  const std::string recording = test::sourcePath("scenarios/recordings/thesis-bodies-fx32.sgr");
  for (const std::string variant : {"interp=2,", ",interp=2", "interp=2,,scalar=fx16", "interp=2, ,scalar=fx16"}) {
    const CliResult r = runCli("compare " + quote(recording) + " --ticks 2 --variant " + quote(variant));
    EXPECT_EQ(r.exitCode, 2) << variant << "\n" << r.describe();
    EXPECT_TRUE(contains(r.err, "an empty item")) << variant << ": " << r.err;
  }
  const CliResult spaced = runCli("compare " + quote(recording) + " --ticks 2 --variant 'interp=2, scalar=fx16'");
  EXPECT_EQ(spaced.exitCode, 0) << spaced.describe();
}

TEST(Round5Hardening, TicksAreBelow2To40Everywhere) {
  // The docs say ticks < 2^40; `run --ticks 2^40` and a script tick of 2^40 were accepted while an
  // input track's "ticks": 2^40 was refused.
  TempDir dir;
  constexpr const char* k2To40 = "1099511627776";
  for (const std::string command : {"run --ticks", "run --hash-every", "record -o x.sgr --ticks"}) {
    const CliResult r = runCli(command + " " + k2To40);
    EXPECT_EQ(r.exitCode, 2) << command << "\n" << r.describe();
    EXPECT_TRUE(contains(r.err, "1099511627775")) << command << ": " << r.err;
  }
  const std::string scenario =
      dir.write("t.json", std::string(R"({"field": {"patchesX": 6, "patchesZ": 6}, "bodies": {"list": [{"name": "b",
      "shape": {"type": "sphere", "radius": 0.3}}]}, "script": [{"tick": )") +
                              k2To40 + R"(, "body": 0, "command": "reset"}]})");
  const CliResult script = runCli("run " + quote(scenario) + " --ticks 1");
  EXPECT_EQ(script.exitCode, 2) << script.describe();
  EXPECT_TRUE(contains(script.err, "$.script[0].tick: expected an integer from 0 to 1099511627775")) << script.err;
}

TEST(Round5Hardening, AFixedPointFaultInTheBodyStagesNamesNoBodyItCannotKnow) {
  // Body 1 (spawned far out, then sped up) overflowed fx16; the message said "body 0", which was
  // at rest on the ground. Fault bits are per thread: the message names the last input instead.
  TempDir dir;
  const std::string scenario = dir.write("f.json", R"({"field": {"patchesX": 16, "patchesZ": 16},
      "bodies": {"list": [{"name": "a", "shape": {"type": "sphere", "radius": 0.3}}]},
      "script": [{"tick": 1, "body": "a", "command": "spawn", "value": [8000, 8000, 8000]},
                 {"tick": 2, "body": 1, "command": "addVelocity", "value": [8000, 8000, 8000]}]})");
  const CliResult r = runCli("run " + quote(scenario) + " --scalar fx16 --ticks 400");
  EXPECT_EQ(r.exitCode, 1) << r.describe();
  EXPECT_TRUE(isOneLine(r.err));
  EXPECT_TRUE(contains(r.err, "stage 'response': fixed-point overflow")) << r.err;
  EXPECT_FALSE(contains(r.err, ", body 0")) << r.err;
  EXPECT_TRUE(contains(r.err, "$.script[1] (addVelocity to body 1 at tick 2)")) << r.err;
}

TEST(Round5Hardening, AUnitQuaternionOfManyDigitsIsUnit) {
  // Squaring a component's exact fraction overflowed 128 bits (a component of -3.52e-18, or
  // 0.7071 written to 30 digits) and the quaternion was called non-unit.
  TempDir dir;
  auto boxTurnedBy = [](const std::string& q) {
    return R"({"field": {"patchesX": 6, "patchesZ": 6}, "bodies": {"list": [{"name": "b",
        "shape": {"type": "box", "halfExtents": [0.2, 0.2, 0.2]}, "orientation": )" +
           q + "}]}}";
  };
  for (const std::string q :
       {"[1, 0, -3.52e-18, 0]", "[0.707106781186547524400844362105, 0, 0.707106781186547524400844362105, 0]"}) {
    const CliResult r = runScenario(dir, "q.json", boxTurnedBy(q), "--ticks 1");
    EXPECT_EQ(r.exitCode, 0) << q << "\n" << r.describe();
  }
  expectRefused(runScenario(dir, "off.json", boxTurnedBy("[1, 0, 0.1, 0]"), "--ticks 1"),
                "$.bodies.list[0].orientation: expected a unit quaternion");
}

TEST(Round5Hardening, AnEmptyFileNameInAScenarioIsSaidSo) {
  // "file": "" named the scenario's own folder: "expected '' to be a regular file, got a directory".
  TempDir dir;
  expectRefused(runScenario(dir, "e.json", R"({"field": {"patchesX": 6, "patchesZ": 6},
      "terrain": {"type": "heightmap", "file": ""}})",
                            "--ticks 1"),
                "$.terrain.file: expected a file name, got an empty string");
}

}  // namespace
}  // namespace sg
