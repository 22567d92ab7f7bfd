// The `simgrass` command line, run as a separate process: help, the run subcommand's output
// (JSON, hashes, thread independence) and its failures. A bad scenario or command line must end
// with exactly one line on stderr and a non-zero exit code (2 for a bad scenario), never a
// crash or a hang.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

std::string scenarioPath(const std::string& name) { return test::sourcePath("scenarios/" + name); }

// ---- help --------------------------------------------------------------------------------------

TEST(CliHelp, TopLevelHelpListsRun) {
  const CliResult r = runCli("--help");
  EXPECT_EQ(r.exitCode, 0) << r.describe();
  EXPECT_NE(r.out.find("run"), std::string::npos) << r.describe();
}

TEST(CliHelp, RunHelpListsEveryOption) {
  const CliResult r = runCli("run --help");
  EXPECT_EQ(r.exitCode, 0) << r.describe();
  for (const char* opt : {"--ticks", "--scalar", "--interp", "--threads", "--hash-every", "--kernel", "--json"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt << "\n" << r.describe();
}

TEST(CliHelp, Version) {
  const CliResult r = runCli("--version");
  EXPECT_EQ(r.exitCode, 0) << r.describe();
  EXPECT_NE(r.out.find("simgrass"), std::string::npos) << r.describe();
}

// ---- run -----------------------------------------------------------------------------------

TEST(CliRun, JsonOutputOfTheBuiltInMeadow) {
  const CliResult r = runCli("run --ticks 5 --json");
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  EXPECT_EQ(r.err, "") << "a successful --json run writes nothing on stderr";
  const json j = parseJson(r);
  ASSERT_TRUE(j.is_object()) << r.describe();
  ASSERT_TRUE(j.contains("finalHash") && j["finalHash"].is_string()) << r.out;
  EXPECT_TRUE(isHex16(j["finalHash"].get<std::string>())) << j["finalHash"];
  EXPECT_EQ(j.value("ticks", -1), 5);
  EXPECT_EQ(j.value("scenario", ""), "thesis-meadow");
  EXPECT_EQ(j.value("scalar", ""), "fx32");
  ASSERT_TRUE(j.contains("counts")) << r.out;
  EXPECT_EQ(j["counts"].value("patches", -1), 22801);
  EXPECT_EQ(j["counts"].value("patchesX", -1), 151);
  EXPECT_EQ(j["counts"].value("particles", -1), 22801);
  EXPECT_FALSE(j.contains("hashes")) << "no --hash-every";
  EXPECT_FALSE(j.contains("error"));
}

TEST(CliRun, HashIsIndependentOfThreadCount) {
  const CliResult one = runCli("run --ticks 5 --json --threads 1");
  const CliResult two = runCli("run --ticks 5 --json --threads 2");
  const CliResult dflt = runCli("run --ticks 5 --json");
  ASSERT_EQ(one.exitCode, 0) << one.describe();
  ASSERT_EQ(two.exitCode, 0) << two.describe();
  ASSERT_EQ(dflt.exitCode, 0) << dflt.describe();
  const json a = parseJson(one), b = parseJson(two), c = parseJson(dflt);
  EXPECT_EQ(a.value("threads", -1), 1);
  EXPECT_EQ(b.value("threads", -1), 2);
  EXPECT_TRUE(isHex16(a.value("finalHash", "")));
  EXPECT_EQ(a.value("finalHash", "a"), b.value("finalHash", "b"));
  EXPECT_EQ(a.value("finalHash", "a"), c.value("finalHash", "c"));
}

TEST(CliRun, HashIsIndependentOfTheParticleKernel) {
  for (const char* scalar : {"fx32", "fx16", "float", "double"}) {
    const std::string base = std::string("run --ticks 20 --json --interp 2 --scalar ") + scalar;
    const CliResult ref = runCli(base + " --kernel scalar");
    const CliResult vec = runCli(base + " --kernel avx2");
    const CliResult aut = runCli(base);
    ASSERT_EQ(ref.exitCode, 0) << ref.describe();
    ASSERT_EQ(vec.exitCode, 0) << vec.describe();
    ASSERT_EQ(aut.exitCode, 0) << aut.describe();
    const json a = parseJson(ref), b = parseJson(vec), c = parseJson(aut);
    EXPECT_EQ(a.value("kernel", ""), "scalar");
    // avx2 where the CPU has it; the reference otherwise (and the output says which ran)
    EXPECT_EQ(b.value("kernel", ""), sg::avx2KernelAvailable() ? "avx2" : "scalar");
    EXPECT_EQ(c.value("kernel", ""), b.value("kernel", "")) << "auto picks the vector kernel where available";
    EXPECT_TRUE(isHex16(a.value("finalHash", "")));
    EXPECT_EQ(a.value("finalHash", "a"), b.value("finalHash", "b")) << scalar;
    EXPECT_EQ(a.value("finalHash", "a"), c.value("finalHash", "c")) << scalar;
  }
  // What ran, where only part of the tick has AVX2 lanes: float's blade row runs its reference
  // whatever --kernel says, and the output says so.
  const CliResult flt =
      runCli("run " + scenarioPath("blade-bodies.json") + " --ticks 2 --json --scalar float --kernel avx2");
  ASSERT_EQ(flt.exitCode, 0) << flt.describe();
  EXPECT_EQ(parseJson(flt).value("kernel", ""), "scalar");
  const CliResult fxb =
      runCli("run " + scenarioPath("blade-bodies.json") + " --ticks 2 --json --scalar fx16 --kernel avx2");
  ASSERT_EQ(fxb.exitCode, 0) << fxb.describe();
  EXPECT_EQ(parseJson(fxb).value("kernel", ""), sg::avx2KernelAvailable() ? "avx2" : "scalar");
  // The text output names the same kernels.
  const CliResult text = runCli("run " + scenarioPath("blade-bodies.json") + " --ticks 2 --scalar fx16 --kernel avx2");
  ASSERT_EQ(text.exitCode, 0) << text.describe();
  const std::string vectorName = sg::avx2KernelAvailable() ? "avx2" : "scalar";
  EXPECT_NE(text.out.find(vectorName + " blade kernel, " + vectorName + " patch kernel"), std::string::npos)
      << text.describe();
  const CliResult floatText =
      runCli("run " + scenarioPath("blade-bodies.json") + " --ticks 2 --scalar float --kernel avx2");
  ASSERT_EQ(floatText.exitCode, 0) << floatText.describe();
  EXPECT_NE(floatText.out.find("scalar blade kernel, " + vectorName + " patch kernel"), std::string::npos)
      << floatText.describe();
  const CliResult fxp = runCli("run --ticks 2 --json --scalar float --kernel avx2");
  ASSERT_EQ(fxp.exitCode, 0) << fxp.describe();
  EXPECT_EQ(parseJson(fxp).value("patchKernel", ""), sg::avx2KernelAvailable() ? "avx2" : "scalar");
  const CliResult bad = runCli("run --ticks 2 --kernel sse9");
  EXPECT_EQ(bad.exitCode, 2) << bad.describe();
  EXPECT_NE(bad.err.find("--kernel"), std::string::npos) << bad.describe();
}

TEST(CliRun, HashEveryListsIntermediateHashes) {
  const CliResult r = runCli("run --hash-every 2 --ticks 6 --json");
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  const json j = parseJson(r);
  ASSERT_TRUE(j.contains("hashes") && j["hashes"].is_array()) << r.out;
  const json& h = j["hashes"];
  ASSERT_EQ(h.size(), 3u) << h.dump();
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(h[i].value("tick", -1), int64_t(2 * (i + 1))) << h.dump();
    EXPECT_TRUE(isHex16(h[i].value("hash", ""))) << h.dump();
  }
  EXPECT_EQ(h[2].value("hash", "x"), j.value("finalHash", "y"));
  EXPECT_NE(h[0].value("hash", "x"), h[1].value("hash", "x")) << "the state changes between ticks 2 and 4";

  // The same hashes as plain runs of 2 and 6 ticks.
  const CliResult two = runCli("run --ticks 2 --json");
  ASSERT_EQ(two.exitCode, 0) << two.describe();
  EXPECT_EQ(parseJson(two).value("finalHash", "a"), h[0].value("hash", "b"));
}

TEST(CliRun, TextOutputNamesTheHash) {
  const CliResult r = runCli("run --ticks 2 --hash-every 1");
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  EXPECT_NE(r.out.find("hash"), std::string::npos) << r.describe();
  EXPECT_NE(r.out.find("tick 1 "), std::string::npos) << r.describe();
  EXPECT_NE(r.out.find("thesis-meadow"), std::string::npos) << r.describe();
}

TEST(CliRun, EveryScalarAndInterpolationOverride) {
  for (const char* scalar : {"fx32", "fx16", "float", "double"}) {
    const CliResult r = runCli(std::string("run --ticks 2 --json --interp 2 --scalar ") + scalar);
    ASSERT_EQ(r.exitCode, 0) << scalar << "\n" << r.describe();
    const json j = parseJson(r);
    EXPECT_EQ(j.value("scalar", ""), scalar);
    EXPECT_EQ(j.value("interpolation", -1), 2);
    EXPECT_EQ(j["counts"].value("patches", -1), 22801);
    EXPECT_EQ(j["counts"].value("particles", -1), 76 * 76);  // ceil(150 / 2) + 1 per side
    EXPECT_TRUE(isHex16(j.value("finalHash", ""))) << r.out;
  }
}

TEST(CliRun, ZeroTicks) {
  const CliResult r = runCli("run --ticks 0 --json");
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  const json j = parseJson(r);
  EXPECT_EQ(j.value("ticks", -1), 0);
  EXPECT_TRUE(isHex16(j.value("finalHash", ""))) << r.out;
}

TEST(CliRun, ShippedScenarios) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(test::sourcePath("scenarios")))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 3u);
  for (const fs::path& f : files) {
    SCOPED_TRACE(f.string());
    const CliResult r = runCli("run " + quote(f.string()) + " --ticks 3 --json");
    ASSERT_EQ(r.exitCode, 0) << r.describe();
    const json j = parseJson(r);
    EXPECT_EQ(j.value("scenario", ""), f.stem().string());
    EXPECT_EQ(j.value("source", ""), f.string());
    EXPECT_EQ(j.value("ticks", -1), 3);
    EXPECT_TRUE(isHex16(j.value("finalHash", ""))) << r.out;
    EXPECT_FALSE(j.contains("error")) << r.out;
    const json& c = j["counts"];
    EXPECT_EQ(c.value("patches", int64_t(-1)), c.value("patchesX", int64_t(0)) * c.value("patchesZ", int64_t(0)));
  }
}

TEST(CliRun, BuiltInMeadowEqualsTheThesisMeadowFile) {
  const CliResult builtIn = runCli("run --ticks 3 --json");
  const CliResult file = runCli("run " + quote(scenarioPath("thesis-meadow.json")) + " --ticks 3 --json");
  ASSERT_EQ(builtIn.exitCode, 0) << builtIn.describe();
  ASSERT_EQ(file.exitCode, 0) << file.describe();
  EXPECT_EQ(parseJson(builtIn).value("finalHash", "a"), parseJson(file).value("finalHash", "b"));
}

TEST(CliRun, HeightmapRelativeToTheScenarioFile) {
  // A copy of the hilly meadow in another folder, next to its own copy of the heightmap.
  TempDir dir;
  fs::copy_file(scenarioPath("hills.png"), dir.path() / "hills.png");
  const std::string copy = dir.write("hilly.json", readFile(scenarioPath("hilly-meadow.json")));
  const CliResult a = runCli("run " + quote(copy) + " --ticks 3 --json");
  const CliResult b = runCli("run " + quote(scenarioPath("hilly-meadow.json")) + " --ticks 3 --json");
  ASSERT_EQ(a.exitCode, 0) << a.describe();
  ASSERT_EQ(b.exitCode, 0) << b.describe();
  EXPECT_EQ(parseJson(a).value("finalHash", "a"), parseJson(b).value("finalHash", "b"));
}

// ---- bad scenarios: exit code 2, one line naming the file and the JSON path -------------------------

/// Exit code 2, exactly one line on stderr naming the file, the path and what was expected,
/// nothing on stdout.
testing::AssertionResult isScenarioFailure(const CliResult& r, const std::string& file, const std::string& path) {
  auto fail = [&]() { return testing::AssertionFailure() << r.describe() << "\n  "; };
  if (r.exitCode != 2) return fail() << "expected exit code 2";
  if (!isOneLine(r.err)) return fail() << "expected exactly one line on stderr";
  if (r.err.find(file) == std::string::npos) return fail() << "expected stderr to name the file '" << file << "'";
  if (r.err.find(path) == std::string::npos) return fail() << "expected stderr to name the path '" << path << "'";
  if (r.err.find("expected") == std::string::npos) return fail() << "expected stderr to say what was expected";
  if (!r.out.empty()) return fail() << "expected nothing on stdout";
  return testing::AssertionSuccess();
}

TEST(CliBadScenario, MissingFile) {
  TempDir dir;
  const std::string missing = dir.file("no-such-scenario.json");
  EXPECT_TRUE(isScenarioFailure(runCli("run " + quote(missing) + " --ticks 3"), missing, "$"));
}

TEST(CliBadScenario, DirectoryInsteadOfFile) {
  TempDir dir;
  EXPECT_TRUE(isScenarioFailure(runCli("run " + quote(dir.path().string()) + " --ticks 3"), dir.path().string(), "$"));
}

struct BadFileCase {
  std::string name;
  std::string text;
  std::string path;
  std::string extraArgs = "";
};
void PrintTo(const BadFileCase& c, std::ostream* os) { *os << c.name << ": " << c.text; }
std::string badFileName(const testing::TestParamInfo<BadFileCase>& info) { return info.param.name; }

class CliBadScenarioFile : public testing::TestWithParam<BadFileCase> {};

TEST_P(CliBadScenarioFile, OneLineAndExitCode2) {
  const BadFileCase& c = GetParam();
  TempDir dir;
  dir.write("notes.png", "not a png, but named in one case as a heightmap");
  const std::string file = dir.write(c.name + ".json", c.text);
  EXPECT_TRUE(isScenarioFailure(runCli("run " + quote(file) + " --ticks 3" + c.extraArgs), file, c.path));
}

const std::vector<BadFileCase> kBadFiles = {
    {"ZeroSpacing", R"({"field": {"spacing": 0}})", "$.field.spacing"},
    {"SyntaxError", "{\n  \"seed\": ,\n}", "line 2, column 11"},
    {"Empty", "", "byte 1"},
    {"TopLevelArray", "[]", "$"},
    {"UnknownKey", R"({"wind": {"schedule": [{"force": [0, 1, 0], "duration": 1, "gust": 1}]}})",
     "$.wind.schedule[0].gust"},
    {"DuplicateKey", R"({"field": {"spacing": 0.25, "spacing": 0.5}})", "$.field.spacing"},
    {"GustWithoutDuration", R"({"wind": {"schedule": [{"force": [0, 1, 0]}]}})", "$.wind.schedule[0].duration"},
    {"GustShorterThanOneTick", R"({"wind": {"schedule": [{"force": [0, 1, 0], "duration": 0.001}]}})",
     "$.wind.schedule[0].duration"},
    {"ScalarFx64", R"({"scalar": "fx64"})", "$.scalar"},
    {"JsonInfinity", R"({"field": {"spacing": 1e400}})", "$.field.spacing"},
    {"TooManyDigits", R"({"field": {"spacing": 0.1234567890123456789012345678901}})", "$.field.spacing"},
    {"HeightmapMissing", R"({"terrain": {"type": "heightmap", "file": "missing.png"}})", "$.terrain.file"},
    {"HeightmapNotPng", R"({"terrain": {"type": "heightmap", "file": "notes.png"}})", "$.terrain.file"},
    {"HeightmapIsDirectory", R"({"terrain": {"type": "heightmap", "file": "."}})", "$.terrain.file"},
    {"FlatWithFile", R"({"terrain": {"type": "flat", "file": "hills.png"}})", "$.terrain.file"},
    // Fits fx32 but not fx16 (--scalar fx16 overrides the scenario's fx32).
    {"BeyondFx16ByOption", R"({"field": {"patchesX": 100, "patchesZ": 100, "spacing": 1000}})", "$.field.patchesX",
     " --scalar fx16"},
    {"BeyondFx16InFile", R"({"scalar": "fx16", "field": {"patchesX": 100, "patchesZ": 100, "spacing": 1000}})",
     "$.field.patchesX"},
    // Tens of TB: rejected against the machine's memory, never allocated.
    {"TooBigForMemory", R"({"field": {"patchesX": 1048576, "patchesZ": 1048576, "spacing": 0.001}})", "$.field"},
    // An escaped newline in a key must not make the message two lines.
    {"KeyWithNewline", "{\"a\\nb\": 1}", "$."},
};
INSTANTIATE_TEST_SUITE_P(CliBad, CliBadScenarioFile, testing::ValuesIn(kBadFiles), badFileName);

// Numbers with 30 significant digits (the documented maximum) whose products overflow 128-bit
// exact arithmetic: the run either works or ends with one scenario error line; never a crash.
TEST(CliLongDecimals, RunOrOneLineNeverACrash) {
  const std::string a = "0.123456789012345678901234567891", b = "0.987654321098765432109876543211";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"jitter-times-spacing", R"({"field": {"spacing": )" + a + R"(, "jitter": 0.499999999999999999999999999999}})"},
      {"center-minus-half-field", R"({"field": {"spacing": )" + a + R"(, "center": [)" + b + ", 0]}}"},
      {"heightmap-center", R"({"terrain": {"type": "heightmap", "file": "hills.png", "cellSize": )" + a +
                               R"(, "center": [)" + b + ", 0]}}"},
  };
  for (const auto& [name, text] : cases) {
    TempDir dir;
    fs::copy_file(scenarioPath("hills.png"), dir.path() / "hills.png");
    const std::string file = dir.write(name + ".json", text);
    const CliResult r = runCli("run " + quote(file) + " --ticks 3 --json");
    if (r.exitCode == 0) {
      EXPECT_TRUE(isHex16(parseJson(r).value("finalHash", ""))) << name << "\n" << r.describe();
    } else {
      EXPECT_TRUE(isScenarioFailure(r, file, "$.")) << name;
    }
  }
}

// ---- bad command lines: one line, non-zero ---------------------------------------------------

/// Non-zero exit (not a signal), exactly one line on stderr, nothing on stdout.
testing::AssertionResult isCommandLineFailure(const CliResult& r) {
  auto fail = [&]() { return testing::AssertionFailure() << r.describe() << "\n  "; };
  if (r.exitCode == 0) return fail() << "expected a non-zero exit code";
  if (r.exitCode >= 124) return fail() << "expected an error exit, not a timeout or a signal";
  if (!isOneLine(r.err)) return fail() << "expected exactly one line on stderr";
  if (!r.out.empty()) return fail() << "expected nothing on stdout";
  return testing::AssertionSuccess();
}

TEST(CliBadCommandLine, UnknownOption) {
  const CliResult r = runCli("run --bogus");
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isCommandLineFailure(r));
  EXPECT_NE(r.err.find("--bogus"), std::string::npos) << r.describe();
}

TEST(CliBadCommandLine, UnknownScalar) {
  const CliResult r = runCli("run --scalar fx64 --ticks 1");
  EXPECT_TRUE(isCommandLineFailure(r));
  EXPECT_NE(r.err.find("fx64"), std::string::npos) << r.describe();
}

TEST(CliBadCommandLine, NegativeTicks) { EXPECT_TRUE(isCommandLineFailure(runCli("run --ticks -1"))); }

TEST(CliBadCommandLine, MissingSubcommand) { EXPECT_TRUE(isCommandLineFailure(runCli(""))); }

TEST(CliBadCommandLine, UnknownSubcommand) { EXPECT_TRUE(isCommandLineFailure(runCli("walk"))); }

TEST(CliBadCommandLine, OtherBadValues) {
  for (const char* args : {"run --ticks abc", "run --ticks", "run --ticks 1.5", "run --threads 0", "run --threads 257",
                           "run --interp 5", "run --interp 0", "run --hash-every -2", "run --json=maybe",
                           "run a.json b.json", "run --ticks 99999999999999999999999"}) {
    EXPECT_TRUE(isCommandLineFailure(runCli(args))) << "simgrass " << args;
  }
}

}  // namespace
}  // namespace sg
