// simgrass-viewer's playback, A/B, body keys, panels' regenerate and error window (docs/viewer.md),
// driven by scripts under Xvfb (the helper of tests/viewer_test.cpp). Every number the viewer
// prints is checked against an independent computation by the CLI: `simgrass replay --to T`
// for state hashes, `simgrass compare --variant` for the A/B divergence, `simgrass replay
// --verify` for recordings made in the window, and `simgrass replay FILE` for the error line.
#include <gtest/gtest.h>

#include <regex>
#include <string>
#include <vector>

#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace viewer_test {
bool onPath(const std::string& program);  // tests/viewer_test.cpp
CliResult runViewer(const std::string& args, bool xvfb = true,
                    const std::string& cwd = "");  // tests/viewer_test.cpp
}  // namespace viewer_test

namespace {
using viewer_test::onPath;
using viewer_test::runViewer;

/// Small, fast windows: llvmpipe on a shared machine.
const std::string kWindow = " --size 320x240 --msaa 0";

std::string recording(const std::string& name) { return test::sourcePath("scenarios/recordings/" + name); }

/// The viewer's `print` lines ("state      tick T, hash H, ...").
struct StateLine {
  int64_t tick = -1;
  std::string hash, text;
  int64_t bodies = -1, patchesX = -1, patchesZ = -1;
  int64_t hashesOk = -1, mismatch = -2;
  double tipMax = -1;
  int64_t firstDivergent = -2;
};

std::vector<StateLine> stateLines(const std::string& out) {
  std::vector<StateLine> lines;
  static const std::regex head(R"(^state +tick (\d+), hash ([0-9a-f]{16}), patches (\d+)x(\d+), bodies (\d+))");
  static const std::regex play(R"(hashes ok (\d+), mismatch (-?\d+))");
  static const std::regex ab(R"(tipMax ([-0-9.e+]+) m, tipRms [-0-9.e+]+ m, first divergent tick (-?\d+))");
  size_t at = 0;
  while (at < out.size()) {
    const size_t end = out.find('\n', at);
    const std::string line = out.substr(at, end == std::string::npos ? std::string::npos : end - at);
    at = end == std::string::npos ? out.size() : end + 1;
    std::smatch m;
    if (!std::regex_search(line, m, head)) continue;
    StateLine s;
    s.text = line;
    s.tick = std::stoll(m[1]);
    s.hash = m[2];
    s.patchesX = std::stoll(m[3]);
    s.patchesZ = std::stoll(m[4]);
    s.bodies = std::stoll(m[5]);
    if (std::regex_search(line, m, play)) {
      s.hashesOk = std::stoll(m[1]);
      s.mismatch = std::stoll(m[2]);
    }
    if (std::regex_search(line, m, ab)) {
      s.tipMax = std::stod(m[1]);
      s.firstDivergent = std::stoll(m[2]);
    }
    lines.push_back(s);
  }
  return lines;
}

/// The state hash `simgrass replay FILE --to T --json` reports.
std::string cliHashAt(const std::string& file, int64_t tick) {
  const CliResult r = runCli("replay " + quote(file) + " --to " + std::to_string(tick) + " --json");
  EXPECT_EQ(r.exitCode, 0) << r.describe();
  return parseJson(r).value("hash", std::string());
}

TEST(ViewerPlayback, SeekStepAndSpeedLandOnTheCliHashes) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string rec = recording("thesis-bodies-fx32.sgr");
  // seek through the snapshot at 0, step 5 after pause, play 10 frames at 2x (20 ticks), then 8
  // frames at 0.25x (2 ticks), then seek backwards.
  const std::string script = dir.write("play.txt",
                                       "seek 100\nprint\npause\nstep 5\nprint\nplay\nspeed 2\nframes 10\nprint\n"
                                       "speed 0.25\nframes 8\nprint\nseek 37\nprint\nquit\n");
  const CliResult v = runViewer(quote(rec) + " --script " + quote(script) + kWindow);
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  const std::vector<StateLine> s = stateLines(v.out);
  ASSERT_EQ(s.size(), 5u) << v.describe();
  const int64_t want[] = {100, 105, 125, 127, 37};
  for (size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(s[i].tick, want[i]) << s[i].text;
    EXPECT_EQ(s[i].hash, cliHashAt(rec, want[i])) << "tick " << want[i] << ": " << s[i].text;
    EXPECT_EQ(s[i].mismatch, -1) << s[i].text;  // every recorded hash on the way matched
  }
  // The recording holds a hash every tick: stepping and playing checked each tick passed.
  EXPECT_GE(s[3].hashesOk, 127 - 100 + 1) << s[3].text;
  EXPECT_EQ(v.err, "") << v.describe();
}

TEST(ViewerPlayback, AbOfARecordingWithItselfIsZeroAndUnderAVariantMatchesCompare) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string rec = recording("thesis-bodies-fx32.sgr");
  const CliResult cmp = runCli("compare " + quote(rec) + " --variant interp=2 --json");
  ASSERT_EQ(cmp.exitCode, 0) << cmp.describe();
  const json variant = parseJson(cmp)["variants"][0];
  const int64_t first = variant.value("firstDivergentTick", int64_t(-1));
  const int64_t worstTick = variant.value("tipMaxTick", int64_t(-1));
  const double worst = variant.value("tipMax", -1.0);
  ASSERT_GT(first, 0);
  ASSERT_GT(worst, 0);
  ASSERT_GT(worstTick, first) << "the first print seeks past the first divergent tick";

  // First a jump past everything (the first divergent tick must not depend on what was seen:
  // it is the whole run's, as compare finds it), then step from 0 past compare's first divergent
  // tick, then jump to its worst tick.
  const std::string script =
      dir.write("ab.txt", "seek " + std::to_string(worstTick) + "\nprint\nseek 0\nstep " + std::to_string(first + 2) +
                              "\nprint\nab overlay\nframes 1\n" + "seek " + std::to_string(worstTick) +
                              "\nprint\nab side\nframes 1\nquit\n");
  const CliResult self = runViewer(quote(rec) + " --ab " + quote(rec) + " --script " + quote(script) + kWindow);
  ASSERT_EQ(self.exitCode, 0) << self.describe();
  for (const StateLine& s : stateLines(self.out)) {
    EXPECT_EQ(s.tipMax, 0.0) << s.text;
    EXPECT_EQ(s.firstDivergent, -1) << s.text;
  }

  const CliResult ab = runViewer(quote(rec) + " --ab-variant interp=2 --script " + quote(script) + kWindow);
  ASSERT_EQ(ab.exitCode, 0) << ab.describe();
  const std::vector<StateLine> all = stateLines(ab.out);
  ASSERT_EQ(all.size(), 3u) << ab.describe();
  EXPECT_EQ(all[0].firstDivergent, first) << "after a seek past it: " << all[0].text;
  const std::vector<StateLine> s(all.begin() + 1, all.end());
  EXPECT_EQ(s[0].firstDivergent, first) << s[0].text;
  EXPECT_GT(s[0].tipMax, 0.0) << s[0].text;
  EXPECT_EQ(s[1].tick, worstTick);
  // The same observations measured the same way; printed with 9 significant digits.
  EXPECT_NEAR(s[1].tipMax, worst, 1e-8 * worst) << s[1].text;
  // A stays the recording: its hash is the CLI's.
  EXPECT_EQ(s[1].hash, cliHashAt(rec, worstTick));
}

TEST(ViewerPlayback, SpawnResetAndMowerKeysRecordAReplayThatVerifies) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string out = dir.file("bodies.sgr");
  const std::string script =
      dir.write("bodies.txt", "record start " + out +
                                  "\nselect 0\nkey n down\nframes 1\nkey n up\nframes 4\n"
                                  "print\nkey t down\nframes 5\nkey t up\nkey z down\nframes 1\nkey z up\n"
                                  "key m down\nframes 1\nkey m up\nframes 3\nprint\nrecord stop\nquit\n");
  const std::string scenario = test::sourcePath("scenarios/mower-field.json");
  const CliResult v = runViewer(quote(scenario) + " --script " + quote(script) + kWindow);
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  const std::vector<StateLine> s = stateLines(v.out);
  ASSERT_EQ(s.size(), 2u) << v.describe();
  EXPECT_EQ(s[0].bodies, 2) << "N spawned a copy of the mower: " << s[0].text;

  const CliResult verify = runCli("replay " + quote(out) + " --verify");
  ASSERT_EQ(verify.exitCode, 0) << verify.describe();
  EXPECT_NE(verify.out.find("verified 15 ticks"), std::string::npos) << verify.describe();
  EXPECT_EQ(cliHashAt(out, 15), s[1].hash) << "the viewer's hash differs from a headless replay";

  // The keys did something: without M the session ends elsewhere (the blade state is state).
  const std::string noMower = dir.write("nomower.txt",
                                        "select 0\nkey n down\nframes 1\nkey n up\nframes 4\nkey t down\nframes 5\n"
                                        "key t up\nkey z down\nframes 1\nkey z up\nframes 4\nprint\nquit\n");
  const CliResult w = runViewer(quote(scenario) + " --script " + quote(noMower) + kWindow);
  ASSERT_EQ(w.exitCode, 0) << w.describe();
  const std::vector<StateLine> t = stateLines(w.out);
  ASSERT_EQ(t.size(), 1u) << w.describe();
  EXPECT_EQ(t[0].tick, 15);
  EXPECT_NE(t[0].hash, s[1].hash) << "M (mower off) changed nothing";
}

TEST(ViewerPlayback, RegenerateWithNewCountsAndLodToggle) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string out = dir.file("regen.sgr");
  const std::string script = dir.write("regen.txt",
                                       "frames 2\nprint\nset field.patchesX 41\nset field.patchesZ 31\nregenerate\n"
                                       "print\nrecord start " +
                                           out +
                                           "\nframes 4\nrecord stop\nlod on\nprint\n"
                                           "set field.spacing -1\nregenerate\nframes 1\nprint\nquit\n");
  const CliResult v = runViewer("--script " + quote(script) + kWindow);
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  const std::vector<StateLine> s = stateLines(v.out);
  ASSERT_EQ(s.size(), 4u) << v.describe();
  EXPECT_EQ(s[0].patchesX, 151);
  EXPECT_EQ(s[1].patchesX, 41);
  EXPECT_EQ(s[1].patchesZ, 31);
  EXPECT_EQ(s[1].tick, 0) << "a regenerated meadow starts at tick 0";
  // The level-of-detail toggle replays the inputs so far: same tick, the world goes on.
  EXPECT_EQ(s[2].tick, 4);
  // A bad edit: one line naming the JSON path, the previous session keeps running.
  EXPECT_TRUE(isOneLine(v.err)) << v.err;
  EXPECT_NE(v.err.find("$.field.spacing"), std::string::npos) << v.err;
  EXPECT_EQ(s[3].tick, 5);
  EXPECT_EQ(s[3].patchesX, 41);
  // The edited scenario is what the recording embeds: it verifies headless.
  const CliResult verify = runCli("replay " + quote(out) + " --verify");
  EXPECT_EQ(verify.exitCode, 0) << verify.describe();
}

TEST(ViewerPlayback, DamagedRecordingShowsTheCliMessage) {
  TempDir dir;
  const std::string bad = test::sourcePath("tests/data/sgr/damaged/flip-HEAD-checksum.sgr");
  const CliResult cli = runCli("replay " + quote(bad) + " --verify");
  ASSERT_EQ(cli.exitCode, 2) << cli.describe();
  const std::string prefix = "simgrass replay: ";
  ASSERT_EQ(cli.err.rfind(prefix, 0), 0u) << cli.err;
  const std::string message = cli.err.substr(prefix.size());  // with its newline

  // From the command line, without a window: exit 2 with that line (no display needed).
  const CliResult direct = runViewer(quote(bad), false);
  EXPECT_EQ(direct.exitCode, 2) << direct.describe();
  EXPECT_EQ(direct.err, "simgrass-viewer: " + message);

  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  // From a script: the error is printed (and shown in the window), the session goes on, exit 0.
  const std::string script = dir.write("open.txt", "frames 1\nopen " + bad + "\nframes 1\nprint\nquit\n");
  const CliResult v = runViewer("--script " + quote(script) + kWindow);
  EXPECT_EQ(v.exitCode, 0) << v.describe();
  EXPECT_EQ(v.err, "simgrass-viewer: " + message);
  const std::vector<StateLine> s = stateLines(v.out);
  ASSERT_EQ(s.size(), 1u) << v.describe();
  EXPECT_EQ(s[0].tick, 2) << "the previous session kept running";

  // --keep-open-on-error: the window opens (the built-in meadow) with the error shown.
  const std::string frames = dir.write("frames.txt", "frames 1\nprint\nquit\n");
  const CliResult k = runViewer(quote(bad) + " --keep-open-on-error --script " + quote(frames) + kWindow);
  EXPECT_EQ(k.exitCode, 0) << k.describe();
  EXPECT_EQ(k.err, "simgrass-viewer: " + message);
  EXPECT_EQ(stateLines(k.out).size(), 1u) << k.describe();
}

TEST(ViewerPlayback, PlaybackScriptCommandsOutsidePlaybackAreOneLineErrors) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const CliResult r = runViewer("--script " + quote(dir.write("s.txt", "frames 1\nseek 3\n")) + kWindow);
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err));
  EXPECT_NE(r.err.find("s.txt:2: seek"), std::string::npos) << r.err;
  // Parse errors come before any window: the speed range.
  const CliResult p = runViewer("--script " + quote(dir.write("p.txt", "speed 16\n")), false);
  EXPECT_EQ(p.exitCode, 2) << p.describe();
  EXPECT_NE(p.err.find("p.txt:1: expected 'speed X' (X from 0.25 to 8)"), std::string::npos) << p.err;
}

}  // namespace
}  // namespace sg
