// Promises of docs/robustness.md that an independent tester broke (issue 14, round 2):
//  - a --threads the machine cannot start is one line and exit 2, never a hang in the pool;
//  - integer options are decimal (no octal "010", no hex "0x10");
//  - ...
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "sim/world/chunk_pool.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

std::string tinyScenario() { return test::sourcePath("tests/data/sgr/tiny.json"); }

// --- threads the machine will not start ---------------------------------------------------

// In a forked child with an address-space limit too small for 256 thread stacks, the pool
// throws ThreadStartError after joining what it started; before the fix the child hung in
// pthread_cond_destroy (the alarm turns a hang into SIGALRM, a failure).
TEST(ThreadStartLimits, ChunkPoolThatCannotStartItsThreadsThrowsAndJoins) {
#ifdef SIMGRASS_TEST_ASAN
  GTEST_SKIP() << "an address-space limit and AddressSanitizer's shadow memory do not mix";
#else
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    alarm(30);
    rlimit limit{};
    limit.rlim_cur = limit.rlim_max = rlim_t(1) << 30;  // 1 GiB: far less than 256 x 8 MiB stacks
    if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(10);
    try {
      ChunkPool pool(256);
      _exit(11);  // started them all: the limit did not bite
    } catch (const ThreadStartError& e) {
      const std::string what = e.what();
      _exit(e.requested() == 256 && e.created() >= 1 && e.created() < 256 &&
                    contains(what, "--threads: expected a thread count this machine can start (created ") &&
                    contains(what, " of 256)")
                ? 0
                : 12);
    } catch (...) {
      _exit(13);
    }
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "child killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  EXPECT_EQ(WEXITSTATUS(status), 0);
#endif
}

TEST(ThreadStartLimits, RunReplayAndCompareWithTooManyThreadsAreOneLine) {
#ifdef SIMGRASS_TEST_ASAN
  GTEST_SKIP() << "an address-space limit and AddressSanitizer's shadow memory do not mix";
#else
  TempDir dir;
  const std::string rec = test::sourcePath("tests/data/sgr/tiny.sgr");
  for (const std::string& args :
       {"run " + quote(tinyScenario()) + " --threads 256 --ticks 3", "replay " + quote(rec) + " --threads 256",
        "compare " + quote(rec) + " --threads 240 --variant interp=2"}) {
    const std::string out = dir.file("out"), err = dir.file("err");
    const std::string cmd = "(ulimit -v 1500000; timeout -k 5 60 " + quote(SIMGRASS_CLI) + " " + args +
                            " </dev/null >" + quote(out) + " 2>" + quote(err) + ")";
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status)) << args;
    const std::string stderrText = readFile(err);
    EXPECT_EQ(WEXITSTATUS(status), 2) << args << "\n" << stderrText;
    EXPECT_TRUE(isOneLine(stderrText)) << args;
    EXPECT_TRUE(contains(stderrText, "--threads: expected a thread count this machine can start (created "))
        << args << "\n"
        << stderrText;
  }
#endif
}

// --- worlds larger than this process may allocate ------------------------------------------

// Under ulimit -v the memory budget is the address-space limit: a 1048576 x 64 field (about
// 9 GiB) is refused by the estimate, naming the file, where `record` printed "internal error:
// out of memory".
TEST(WorldMemoryLimits, RecordRefusesAFieldLargerThanTheAddressSpaceLimit) {
#ifdef SIMGRASS_TEST_ASAN
  GTEST_SKIP() << "an address-space limit and AddressSanitizer's shadow memory do not mix";
#else
  TempDir dir;
  const std::string scenario = dir.write("bigf.json", R"({"field":{"patchesX":1048576,"patchesZ":64,"spacing":0.25}})");
  const std::string out = dir.file("out"), err = dir.file("err");
  const std::string cmd = "(ulimit -v 4000000; timeout -k 5 60 " + quote(SIMGRASS_CLI) + " record " + quote(scenario) +
                          " -o " + quote(dir.file("big.sgr")) + " --ticks 1 </dev/null >" + quote(out) + " 2>" +
                          quote(err) + ")";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  const std::string stderrText = readFile(err);
  EXPECT_EQ(WEXITSTATUS(status), 2) << stderrText;
  EXPECT_TRUE(isOneLine(stderrText));
  EXPECT_TRUE(contains(stderrText, "simgrass record: " + scenario + ": $.field: expected ")) << stderrText;
  EXPECT_FALSE(contains(stderrText, "internal error")) << stderrText;
  EXPECT_FALSE(fs::exists(dir.file("big.sgr")));
#endif
}

// --- integer options are decimal -----------------------------------------------------------

TEST(DecimalOptions, LeadingZerosAreDecimalNotOctal) {
  const CliResult r = runCli("run " + quote(tinyScenario()) + " --ticks 010 --json");
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  EXPECT_EQ(parseJson(r)["ticks"], 10) << r.describe();  // CLI11 alone: 8 (octal)
  const CliResult replay = runCli("replay " + quote(test::sourcePath("tests/data/sgr/tiny.sgr")) + " --to 010");
  ASSERT_EQ(replay.exitCode, 0) << replay.describe();
  EXPECT_TRUE(contains(replay.out, "tick 10 hash")) << replay.describe();
}

TEST(DecimalOptions, HexOctalAndBinarySpellingsAreRefusedInOneLine) {
  for (const std::string& args :
       {"run " + quote(tinyScenario()) + " --ticks 0x10", "run " + quote(tinyScenario()) + " --threads 0b11",
        "run " + quote(tinyScenario()) + " --ticks 0o7",
        "replay " + quote(test::sourcePath("tests/data/sgr/tiny.sgr")) + " --to 0x1"}) {
    const CliResult r = runCli(args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << args;
    EXPECT_TRUE(contains(r.err, "expected a decimal integer")) << args << "\n" << r.describe();
  }
  // A leading-zero value still meets the option's range: 0257 is 257, above --threads' 256.
  const CliResult r = runCli("run " + quote(tinyScenario()) + " --threads 0257");
  EXPECT_EQ(r.exitCode, 2) << r.describe();
}

// CLI11 echoed a 5000-character option value whole.
TEST(DecimalOptions, ParseErrorsCutTheEchoedValue) {
  const CliResult r = runCli("run " + quote(tinyScenario()) + " --scalar " + std::string(5000, 'x'));
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err));
  EXPECT_LT(r.err.size(), 400u) << r.err.size();
}

// --- NUL bytes and control characters ------------------------------------------------------

// nlohmann's lexer ends the input at a NUL: the garbage after it was silently ignored (exit 0).
TEST(NulBytes, ScenarioAndInputTrackWithANulAfterTheValueAreRefusedAtItsByte) {
  TempDir dir;
  const std::string text = std::string(R"({"field":{"patchesX":4,"patchesZ":4}})") + '\0' + "GARBAGE {{";
  const std::string scenario = dir.write("nul.json", text);
  const CliResult r = runCli("run " + quote(scenario) + " --ticks 1");
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err));
  EXPECT_TRUE(contains(r.err, scenario + ": byte 38 (line 1, column 38): expected valid JSON")) << r.describe();

  const std::string track = dir.write("track.json", std::string(R"({"ticks": 2})") + '\0' + "junk");
  const CliResult t =
      runCli("record " + quote(tinyScenario()) + " --input " + quote(track) + " -o " + quote(dir.file("t.sgr")));
  EXPECT_EQ(t.exitCode, 2) << t.describe();
  EXPECT_TRUE(isOneLine(t.err));
  EXPECT_TRUE(contains(t.err, track + ": byte 13")) << t.describe();
  EXPECT_FALSE(fs::exists(dir.file("t.sgr")));
}

// "ok.png\u0000junk" read ok.png (and record embedded the longer name).
TEST(NulBytes, FileNamesWithControlCharactersAreRefusedWithTheirPath) {
  TempDir dir;
  const std::string heightmap =
      dir.write("hm.json", R"({"terrain":{"type":"heightmap","file":"ok.png\u0000junk","cellSize":1,"maxHeight":1}})");
  const CliResult r = runCli("run " + quote(heightmap) + " --ticks 1");
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err));
  EXPECT_TRUE(contains(r.err, "$.terrain.file: expected a file name without control characters")) << r.describe();

  const std::string mesh =
      dir.write("mesh.json",
                R"({"bodies":{"list":[{"name":"rock","shape":{"type":"sphere","radius":0.5},"mesh":"a\u0001.obj"}]}})");
  const CliResult m = runCli("run " + quote(mesh) + " --ticks 1");
  EXPECT_EQ(m.exitCode, 2) << m.describe();
  EXPECT_TRUE(isOneLine(m.err));
  EXPECT_TRUE(contains(m.err, ".mesh: expected a file name without control characters")) << m.describe();
}

// --- limits and messages ---------------------------------------------------------------------

// A 64 MiB track of "[]" peaked at 1.6 GB: the track limit is 16 MiB.
TEST(Round2Limits, InputTrackAbove16MiBIsRefusedBeforeItIsRead) {
  TempDir dir;
  const std::string track = dir.write("track.json", std::string((16u << 20) + 1, ' ') + "{}");
  const CliResult r = runCli("record " + quote(tinyScenario()) + " --input " + quote(track) + " -o " +
                             quote(dir.file("t.sgr")) + " --ticks 1");
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err));
  EXPECT_TRUE(contains(r.err, track + ": $: expected a file of at most 16777216 bytes")) << r.describe();
}

TEST(Round2Limits, VariantNamingASettingTwiceIsRefused) {
  const CliResult r =
      runCli("compare " + quote(test::sourcePath("tests/data/sgr/tiny.sgr")) + " --variant scalar=fx16,scalar=double");
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err));
  EXPECT_TRUE(contains(r.err, "expected each key once (scalar is given twice)")) << r.describe();
}

// The docs say below 2^40: 2^40 itself was accepted.
TEST(Round2Limits, InputTrackTicksOf2Pow40AreRefused) {
  TempDir dir;
  const std::string track = dir.write("track.json", R"({"format": "simgrass-input-track/1", "ticks": 1099511627776})");
  const CliResult r =
      runCli("record " + quote(tinyScenario()) + " --input " + quote(track) + " -o " + quote(dir.file("t.sgr")));
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err));
  EXPECT_TRUE(contains(r.err, track + ": $.ticks: expected an integer from 0 to 1099511627775")) << r.describe();
}

}  // namespace
}  // namespace sg
