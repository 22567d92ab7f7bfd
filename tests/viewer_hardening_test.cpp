// Hostile input to simgrass-viewer and `simgrass render` (issue 14): files that are not regular
// files (FIFOs, folders, devices), JSON values nested 100000 deep, list indices that would
// allocate 50 M entries, frame sizes that need gigabytes, outputs over inputs, a full disk. Each
// one is a one-line error (exit 2, as for every output that cannot be written) or, inside a running
// viewer, the one-line error in the window's error area (`status` prints it) while the session
// goes on. Never a crash, a hang (every run is under a timeout) or an unbounded allocation.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <csignal>

#include <regex>
#include <string>
#include <vector>

#include "tests/cli_support.h"
#include "tests/test_support.h"
#include "viewer/app/input_history.h"

namespace sg {
namespace viewer_test {
bool onPath(const std::string& program);                                                      // tests/viewer_test.cpp
CliResult runViewer(const std::string& args, bool xvfb = true, const std::string& cwd = "");  // tests/viewer_test.cpp
}  // namespace viewer_test

namespace {
using viewer_test::onPath;
using viewer_test::runViewer;

const std::string kWindow = " --size 320x240 --msaa 0";

std::vector<std::string> linesOf(const std::string& text) {
  std::vector<std::string> lines;
  size_t at = 0;
  while (at < text.size()) {
    const size_t end = text.find('\n', at);
    lines.push_back(text.substr(at, end == std::string::npos ? std::string::npos : end - at));
    at = end == std::string::npos ? text.size() : end + 1;
  }
  return lines;
}

/// The `error      ...` lines the `status` command printed (what the error window showed).
std::vector<std::string> errorLines(const std::string& out) {
  std::vector<std::string> errors;
  for (const std::string& line : linesOf(out))
    if (line.rfind("error      ", 0) == 0) errors.push_back(line.substr(11));
  return errors;
}

std::string fifo(const TempDir& dir, const std::string& name) {
  const std::string path = dir.file(name);
  EXPECT_EQ(mkfifo(path.c_str(), 0600), 0);
  return path;
}

std::string smallScenario(const TempDir& dir) {
  json j = json::parse(readFile(test::sourcePath("scenarios/thesis-meadow.json")));
  j["name"] = "small-meadow";
  j["field"]["patchesX"] = 31;
  j["field"]["patchesZ"] = 31;
  return dir.write("small.json", j.dump(2));
}

TEST(ViewerHardening, ScriptThatIsAFifoFolderDeviceOrTooLargeIsOneLine) {
  TempDir dir;
  const std::string big = dir.write("big.txt", std::string((size_t(4) << 20) + 1, '#'));
  for (const std::string& script : {fifo(dir, "script.fifo"), dir.file(""), std::string("/dev/zero"), big}) {
    // No display: the script is read before any window; a FIFO must not block (120 s timeout).
    const CliResult r = runViewer("--script " + quote(script), false);
    EXPECT_EQ(r.exitCode, 2) << script << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.err;
    EXPECT_NE(r.err.find("expected a"), std::string::npos) << r.err;
  }
}

TEST(ViewerHardening, InputThatIsAFifoOrFolderIsOneLine) {
  TempDir dir;
  for (const std::string& input : {fifo(dir, "in.json"), fifo(dir, "in.sgr"), dir.file("")}) {
    const CliResult r = runViewer(quote(input), false);  // before any window: no display needed
    EXPECT_EQ(r.exitCode, 2) << input << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.err;
    EXPECT_NE(r.err.find("expected a regular file, got a"), std::string::npos) << r.err;
  }
  // The A/B recording too.
  const std::string rec = test::sourcePath("scenarios/recordings/thesis-bodies-fx32.sgr");
  const CliResult ab = runViewer(quote(rec) + " --ab " + quote(fifo(dir, "b.sgr")), false);
  EXPECT_EQ(ab.exitCode, 2) << ab.describe();
  EXPECT_NE(ab.err.find("b.sgr: byte 0: expected a regular file, got a FIFO"), std::string::npos) << ab.err;
}

TEST(ViewerHardening, WindowSizeTimesSamplesIsBounded) {
  const CliResult r = runViewer("--size 8192x8192 --msaa 8", false);
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err));
  EXPECT_NE(r.err.find("--size, --msaa: expected at most 67108864 samples"), std::string::npos) << r.err;
}

TEST(ViewerHardening, OpeningBadFilesShowsTheOneLineErrorInTheWindowAndGoesOn) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string scenarioFifo = fifo(dir, "s.json"), recordingFifo = fifo(dir, "r.sgr");
  // A sparse file one byte over the heightmap limit (64 MiB): refused before it is read.
  const std::string bigHeightmap = dir.write("big.png", "");
  fs::resize_file(bigHeightmap, (uintmax_t(64) << 20) + 1);
  const std::string script =
      dir.write("open.txt", "frames 1\nopen " + scenarioFifo + "\nstatus\nopen " + dir.file("") + "\nstatus\nopen " +
                                recordingFifo + "\nstatus\nopen " + dir.file("missing.json") +
                                "\nstatus\nset field.spacing -1\nregenerate\nstatus\n"
                                "set terrain {\"type\": \"heightmap\", \"file\": \"" +
                                bigHeightmap +
                                "\", \"cellSize\": 1, \"maxHeight\": 5}\nregenerate\nstatus\n"
                                "frames 1\nprint\nquit\n");
  const CliResult v = runViewer("--script " + quote(script) + kWindow);
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  // Each error: one line on stderr, and the same line in the window's error area.
  const std::vector<std::string> err = linesOf(v.err), shown = errorLines(v.out);
  ASSERT_EQ(err.size(), 6u) << v.describe();
  ASSERT_EQ(shown.size(), 6u) << v.describe();
  for (size_t i = 0; i < err.size(); ++i) EXPECT_EQ(err[i], "simgrass-viewer: " + shown[i]);
  EXPECT_NE(shown[0].find(scenarioFifo), std::string::npos) << shown[0];
  EXPECT_NE(shown[0].find("FIFO"), std::string::npos) << shown[0];
  EXPECT_NE(shown[1].find("directory"), std::string::npos) << shown[1];
  EXPECT_NE(shown[2].find(recordingFifo), std::string::npos) << shown[2];
  EXPECT_NE(shown[2].find("FIFO"), std::string::npos) << shown[2];
  EXPECT_NE(shown[3].find("not found"), std::string::npos) << shown[3];
  EXPECT_NE(shown[4].find("$.field.spacing"), std::string::npos) << shown[4];
  EXPECT_NE(shown[5].find("a file of at most 67108864 bytes"), std::string::npos) << shown[5];
  // The session went on: the built-in meadow, two frames.
  EXPECT_NE(v.out.find("state      tick 2,"), std::string::npos) << v.out;
}

TEST(ViewerHardening, SetValuesThatAreTooDeepTooLongOrTooFarAreShortOneLineErrors) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  std::string deepPath = "a";
  for (int i = 0; i < 20000; ++i) deepPath += ".a";
  struct Case {
    std::string line, expected;
  };
  const Case cases[] = {
      // 100000 levels: refused before nlohmann's recursive code (dump, destructor) sees it.
      {"set field.patchesX " + std::string(100000, '[') + std::string(100000, ']'), "nested at most"},
      // json_pointer would fill the list with 50 M nulls.
      {"set particles.acceleration.50000000 1", "an index from 0 to 3"},
      {"set " + deepPath + " 1", "a path of at most 256 characters"},
      // Echoed input: control characters escaped, truncated.
      {"set field.patchesX \x01" + std::string(5000, 'x'), "a JSON value, got '\\x01xxx"},
      // A name that is not UTF-8 would make the regenerate's dump throw out of the frame loop.
      {"set field.\xff 1\nregenerate", "a path of UTF-8 names"},
  };
  for (const Case& c : cases) {
    const std::string script = dir.write("set.txt", c.line + "\nquit\n");
    const CliResult v = runViewer("--script " + quote(script) + kWindow);
    EXPECT_EQ(v.exitCode, 2) << c.line.substr(0, 80) << "\n" << v.describe();
    EXPECT_TRUE(isOneLine(v.err)) << v.err.substr(0, 400);
    EXPECT_LT(v.err.size(), 400u) << "the message echoes unbounded input: " << v.err.substr(0, 400);
    EXPECT_NE(v.err.find(c.expected), std::string::npos) << v.err;
  }
}

TEST(ViewerHardening, OutputsNeverReplaceAnInput) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string scenario = smallScenario(dir);
  const std::string before = readFile(scenario);
  const std::string shot = dir.write("shot.txt", "frames 1\nscreenshot " + scenario + "\nquit\n");
  const CliResult s = runViewer(quote(scenario) + " --script " + quote(shot) + kWindow);
  EXPECT_EQ(s.exitCode, 2) << s.describe();
  EXPECT_TRUE(isOneLine(s.err));
  EXPECT_NE(s.err.find("expected an output file other than the input"), std::string::npos) << s.err;
  EXPECT_EQ(readFile(scenario), before);

  // The running script itself, as a recording's output.
  const std::string rec = dir.file("rec.txt");
  dir.write("rec.txt", "record start " + rec + "\nframes 1\nquit\n");
  const std::string script = readFile(rec);
  const CliResult r = runViewer(quote(scenario) + " --script " + quote(rec) + kWindow);
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err));
  EXPECT_NE(r.err.find("expected an output file other than the input"), std::string::npos) << r.err;
  EXPECT_EQ(readFile(rec), script) << "the script was overwritten";
}

TEST(ViewerHardening, ARecordingThatCannotBeWrittenStopsWithTheErrorShownAndTheSessionGoesOn) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string scenario = smallScenario(dir), out = dir.file("out.sgr");
  // The file-size limit (in KiB, SIGXFSZ ignored: writes fail with EFBIG as on a full disk) lets
  // HEAD through and stops the recording some ticks later.
  const std::string head = dir.file("head.sgr");
  ASSERT_EQ(runCli("record " + quote(scenario) + " --ticks 0 -o " + quote(head)).exitCode, 0);
  const uintmax_t limitKiB = fs::file_size(head) / 1024 + 1;
  ASSERT_LT(fs::file_size(head) + 200, limitKiB * 1024) << "HEAD must fit with room for a few ticks";
  const std::string script = dir.write("rec.txt", "record start " + out + "\nframes 60\nstatus\nprint\nquit\n");
  // As runViewer (tests/viewer_test.cpp) with the limit on the viewer alone (Xvfb writes more):
  // xvfb-run's own clean-up now and then fails after the viewer (exit 5): run it again.
  std::string err, outText;
  int status = -1;
  for (int attempt = 0; attempt < 3; ++attempt) {
    TempDir xvfbTmp;
    const std::string stdoutFile = xvfbTmp.file("stdout"), stderrFile = xvfbTmp.file("stderr");
    const std::string viewer = "trap '' XFSZ; ulimit -f " + std::to_string(limitKiB) + "; exec " +
                               quote(SIMGRASS_VIEWER) + " " + quote(scenario) + " --script " + quote(script) + kWindow;
    const std::string cmd = "env TMPDIR=" + quote(xvfbTmp.file("")) +
                            " timeout -k 5 120 xvfb-run -a -s '-screen 0 1024x768x24' bash -c " + quote(viewer) +
                            " </dev/null >" + quote(stdoutFile) + " 2>" + quote(stderrFile);
    fs::remove(out);
    status = std::system(cmd.c_str());
    err = readFile(stderrFile);
    outText = readFile(stdoutFile);
    const bool harnessFailed = WIFEXITED(status) && WEXITSTATUS(status) == 5 &&
                               err.find("xvfb-run: error: problem while cleaning up") != std::string::npos;
    if (!harnessFailed) break;
  }
  ASSERT_TRUE(WIFEXITED(status)) << status;
  EXPECT_EQ(WEXITSTATUS(status), 1) << err << outText;  // not a clean run: ticks went unrecorded
  EXPECT_TRUE(isOneLine(err)) << err;
  EXPECT_NE(err.find(out), std::string::npos) << err;
  EXPECT_NE(err.find("the recording stopped there"), std::string::npos) << err;
  const std::vector<std::string> shown = errorLines(outText);
  ASSERT_EQ(shown.size(), 1u) << outText;
  EXPECT_EQ(err, "simgrass-viewer: " + shown[0] + "\n");
  EXPECT_NE(outText.find("state      tick 60,"), std::string::npos) << "the session went on: " << outText;
  // What was written is a readable recording cut off before END (exit 3: everything in it checks).
  const CliResult verify = runCli("replay " + quote(out) + " --verify");
  EXPECT_EQ(verify.exitCode, 3) << verify.describe();
}

TEST(ViewerHardening, StepsAndSeeksStopAtTheRecordingsLastTick) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string rec = test::sourcePath("scenarios/recordings/thesis-bodies-fx32.sgr");
  const CliResult info = runCli("replay " + quote(rec) + " --json");
  ASSERT_EQ(info.exitCode, 0) << info.describe();
  // A step of 100 M ticks runs frame by frame (the script waits for it) and ends at the end.
  const std::string script = dir.write("s.txt", "step 100000000\nprint\nstatus\nseek 3\nprint\nquit\n");
  const CliResult v = runViewer(quote(rec) + " --script " + quote(script) + kWindow);
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  const std::regex playback(R"(playback (\d+)/(\d+))");
  std::vector<std::pair<int64_t, int64_t>> at;
  for (const std::string& line : linesOf(v.out)) {
    std::smatch m;
    if (std::regex_search(line, m, playback)) at.emplace_back(std::stoll(m[1]), std::stoll(m[2]));
  }
  ASSERT_EQ(at.size(), 2u) << v.describe();
  EXPECT_EQ(at[0].first, at[0].second) << "step stops at the last tick";
  EXPECT_EQ(at[1].first, 3);
  EXPECT_EQ(v.err, "") << v.describe();
}

TEST(ViewerHardening, ASeekThroughADamagedSnapshotShowsTheCliLineAndStaysPut) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  // Its first snapshot (tick 8) is damaged behind a valid checksum: only decompressing it (a
  // seek, or --verify) finds out.
  const std::string rec = test::sourcePath("tests/data/sgr/damaged/snap-zstd-magic.sgr");
  const CliResult cli = runCli("replay " + quote(rec) + " --verify");
  ASSERT_EQ(cli.exitCode, 2) << cli.describe();
  const std::string message = cli.err.substr(std::string("simgrass replay: ").size());
  const std::string script = dir.write("s.txt", "seek 10\nprint\nstatus\nseek 24\nprint\nquit\n");
  const CliResult v = runViewer(quote(rec) + " --script " + quote(script) + kWindow);
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  EXPECT_EQ(v.err, "simgrass-viewer: " + message);
  const std::vector<std::string> shown = errorLines(v.out);
  ASSERT_EQ(shown.size(), 1u) << v.describe();
  EXPECT_EQ(shown[0] + "\n", message);
  EXPECT_NE(v.out.find("playback 0/24"), std::string::npos) << "the failed seek stays where it was: " << v.out;
  EXPECT_NE(v.out.find("playback 24/24"), std::string::npos) << "the next seek works: " << v.out;
}

TEST(ViewerHardening, ADamagedSnapshotOfTheBSideIsTheOneLineErrorNotACrash) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  // B is A (tiny.sgr) with its first snapshot damaged behind a valid checksum: seeking back to
  // tick 10 rewinds B through it.
  const std::string a = test::sourcePath("tests/data/sgr/tiny.sgr");
  const std::string b = test::sourcePath("tests/data/sgr/damaged/snap-zstd-magic.sgr");
  const std::string script = dir.write("ab.txt", "seek 24\nprint\nseek 10\nprint\nstatus\nquit\n");
  const CliResult v = runViewer(quote(a) + " --ab " + quote(b) + " --script " + quote(script) + kWindow);
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  EXPECT_TRUE(isOneLine(v.err)) << v.err;
  EXPECT_NE(v.err.find(b + ": byte 1165: expected a zstd frame"), std::string::npos) << v.err;
  const std::vector<std::string> shown = errorLines(v.out);
  ASSERT_EQ(shown.size(), 1u) << v.describe();
  EXPECT_EQ("simgrass-viewer: " + shown[0] + "\n", v.err);
  EXPECT_NE(v.out.find("playback 10/24"), std::string::npos) << "A went on: " << v.out;
  EXPECT_NE(v.out.find("tipMax -1 m"), std::string::npos) << "B is not measured: " << v.out;
}

// ---- simgrass render ------------------------------------------------------------------------

TEST(RenderHardening, FrameSamplesAndContactSheetsAreBounded) {
  TempDir dir;
  const std::string scenario = smallScenario(dir), out = " -o " + quote(dir.file("out"));
  const CliResult big = runCli("render " + quote(scenario) + " --size 8192x8192 --msaa 4" + out);
  EXPECT_EQ(big.exitCode, 2) << big.describe();
  EXPECT_TRUE(isOneLine(big.err));
  EXPECT_NE(big.err.find("--size, --msaa: expected at most 67108864 samples"), std::string::npos) << big.err;
  const CliResult sheet =
      runCli("render " + quote(scenario) + " --ticks 0:300 --contact-sheet " + quote(dir.file("s.png")) + out);
  EXPECT_EQ(sheet.exitCode, 2) << sheet.describe();
  EXPECT_TRUE(isOneLine(sheet.err));
  EXPECT_NE(sheet.err.find("--contact-sheet: expected at most 256 frames"), std::string::npos) << sheet.err;
}

TEST(RenderHardening, InputsThatAreNotRegularFilesAreOneLine) {
  TempDir dir;
  for (const std::string& input : {fifo(dir, "in.sgr"), fifo(dir, "in.json"), dir.file(""), std::string("/dev/zero")}) {
    const CliResult r = runCli("render " + quote(input) + " -o " + quote(dir.file("out")));
    EXPECT_EQ(r.exitCode, 2) << input << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.err;
  }
}

TEST(RenderHardening, OutputsNeverReplaceTheInput) {
  TempDir dir;
  const std::string scenario = smallScenario(dir), before = readFile(scenario);
  const CliResult sheet = runCli("render " + quote(scenario) + " --size 32x32 -o " + quote(dir.file("out")) +
                                 " --contact-sheet " + quote(scenario));
  EXPECT_EQ(sheet.exitCode, 2) << sheet.describe();
  EXPECT_TRUE(isOneLine(sheet.err));
  EXPECT_NE(sheet.err.find("expected an output file other than the input"), std::string::npos) << sheet.err;
  // A scenario that is itself named like the first frame, in the output folder.
  fs::create_directories(dir.file("frames"));
  const std::string named = (fs::path(dir.file("frames")) / "frame-000000.png").string();
  fs::copy_file(scenario, named);
  const CliResult frame = runCli("render " + quote(named) + " --size 32x32 -o " + quote(dir.file("frames")));
  EXPECT_EQ(frame.exitCode, 2) << frame.describe();
  EXPECT_NE(frame.err.find("expected an output file other than the input"), std::string::npos) << frame.err;
  EXPECT_EQ(readFile(named), before);
}

TEST(RenderHardening, AFullDiskIsAOneLineErrorAndLeavesNoPartialFrame) {
  TempDir dir;
  const std::string scenario = smallScenario(dir), frames = dir.file("frames");
  // RLIMIT_FSIZE of 16 KiB (SIGXFSZ ignored, so the write fails with EFBIG): a 256x256 frame
  // does not fit.
  const std::string err = dir.file("err");
  const std::string cmd = "bash -c " +
                          quote("trap '' XFSZ; ulimit -f 16; exec timeout -k 5 60 " + quote(SIMGRASS_CLI) + " render " +
                                quote(scenario) + " --size 256x256 --msaa 0 -o " + quote(frames) + " 2>" + quote(err)) +
                          " >/dev/null </dev/null";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << status;
  EXPECT_EQ(WEXITSTATUS(status), 2) << readFile(err);  // as every CLI output that cannot be written
  EXPECT_TRUE(isOneLine(readFile(err)));
  EXPECT_NE(readFile(err).find("frame-000000.png"), std::string::npos) << readFile(err);
  for (const auto& entry : fs::directory_iterator(frames))
    ADD_FAILURE() << "left behind: " << entry.path() << " (" << fs::file_size(entry.path()) << " bytes)";
}

}  // namespace
}  // namespace sg

namespace sg {
namespace {

// `set particles.model "blade"` on a scenario written with the model's old name (constraintMode)
// replaces that name (both would be a scenario error) and the regenerated session runs the blade.
TEST(ViewerHardening, SetTheGrassModelByItsNewName) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string script =
      dir.write("model.txt", "set particles.model \"blade\"\nregenerate\nframes 2\nstatus\nprint\nquit\n");
  const CliResult v = runViewer("--script " + quote(script) + kWindow);
  EXPECT_EQ(v.exitCode, 0) << v.describe();
  EXPECT_NE(v.out.find("error      -"), std::string::npos) << v.out;
  EXPECT_NE(v.out.find("state      tick 2,"), std::string::npos) << v.out;
}

// ---- round 4 (2026-11-28): an independent pass's hostile cases ------------------------------------

/// `program args` under `ulimit -f 1` (1 KiB; SIGXFSZ left at its default, as a user's shell has
/// it), stdout and stderr captured, with `xvfb-run` in front when `xvfb`.
CliResult runWithFileLimit(const std::string& program, const std::string& args, bool xvfb) {
  TempDir io;
  const std::string stdoutFile = io.file("stdout"), stderrFile = io.file("stderr");
  const std::string inner = "ulimit -f 1; exec " + quote(program) + " " + args;
  const std::string cmd = "env TMPDIR=" + quote(io.file("")) + " timeout -k 5 120 " +
                          (xvfb ? "xvfb-run -a -s '-screen 0 1024x768x24' " : "") + "bash -c " + quote(inner) +
                          " </dev/null >" + quote(stdoutFile) + " 2>" + quote(stderrFile);
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = readFile(stdoutFile);
  r.err = readFile(stderrFile);
  return r;
}

TEST(ViewerHardening, AFileSizeLimitIsAFailedWriteForTheAtlasAndTheViewerNotASignal) {
  // Both tools were killed by SIGXFSZ (exit 153 from bash) half-way through a PNG, leaving their
  // temporary file; simgrass already ignored the signal and reported the failed write.
  TempDir dir;
  const CliResult atlas = runWithFileLimit(SIMGRASS_ATLAS, quote(dir.file("atlas")), false);
  EXPECT_EQ(atlas.exitCode, 1) << atlas.describe();
  EXPECT_TRUE(isOneLine(atlas.err)) << atlas.err;
  for (const auto& entry : fs::directory_iterator(dir.file("atlas")))
    EXPECT_EQ(entry.path().filename().string().rfind(".", 0), std::string::npos) << "left behind: " << entry.path();

  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  const std::string scenario = smallScenario(dir), shot = dir.file("shot.png");
  const std::string script = dir.write("shot.txt", "frames 1\nscreenshot " + shot + "\nquit\n");
  const CliResult v = runWithFileLimit(SIMGRASS_VIEWER, quote(scenario) + " --script " + quote(script) + kWindow, true);
  EXPECT_NE(v.exitCode, 128 + SIGXFSZ) << v.describe();
  EXPECT_NE(v.exitCode, 153) << v.describe();  // bash's 128 + 25 for a child killed by SIGXFSZ
  EXPECT_NE(v.err.find("shot.png"), std::string::npos) << v.describe();
  EXPECT_FALSE(fs::exists(shot));
  for (const auto& entry : fs::directory_iterator(dir.path()))
    EXPECT_EQ(entry.path().filename().string().find(".shot.png.tmp"), std::string::npos)
        << "left behind: " << entry.path();
}

TEST(ViewerHardening, AtlasSeedOutOfRangeIsRefused) {
  // CLI11 read "-1" as 2^64 - 1 and clamped 2^64 to it: three atlases of one seed without a word.
  TempDir dir;
  for (const char* seed : {"-1", "18446744073709551616", "99999999999999999999999", "1e3", "''"}) {
    const std::string cmd = quote(SIMGRASS_ATLAS) + " " + quote(dir.file("a")) + " --seed " + seed + " 2>" +
                            quote(dir.file("err")) + " >/dev/null";
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status)) << seed;
    EXPECT_EQ(WEXITSTATUS(status), 2) << seed;
    const std::string err = readFile(dir.file("err"));
    EXPECT_TRUE(isOneLine(err)) << seed << ": " << err;
    EXPECT_NE(err.find("--seed"), std::string::npos) << seed << ": " << err;
  }
  EXPECT_FALSE(fs::exists(dir.file("a")));
  const std::string ok = quote(SIMGRASS_ATLAS) + " " + quote(dir.file("b")) + " --seed 18446744073709551615 >/dev/null";
  EXPECT_EQ(std::system(ok.c_str()), 0);
  EXPECT_TRUE(fs::exists(dir.file("b/tuft-atlas.png")));
}

TEST(ViewerHardening, RenderRefusesAnEmptyCameraAndEchoesALongMeshNameInSixtyCharacters) {
  TempDir dir;
  const std::string scenario = smallScenario(dir);
  const CliResult camera =
      runCli("render " + quote(scenario) + " -o " + quote(dir.file("frames")) + " --size 32x32 --msaa 0 --camera ''");
  EXPECT_EQ(camera.exitCode, 2) << camera.describe();
  EXPECT_TRUE(isOneLine(camera.err)) << camera.err;
  EXPECT_NE(camera.err.find("--camera"), std::string::npos) << camera.err;

  // A body's mesh name comes from the scenario: quoted in at most 60 characters like any text the
  // scenario holds (it was echoed whole: a one-megabyte error line).
  json j = json::parse(readFile(scenario));
  j["bodies"]["list"] = json::array({json{{"name", "ball"},
                                          {"shape", {{"type", "sphere"}, {"radius", 0.3}}},
                                          {"position", {0, 0.3, 0}},
                                          {"mesh", std::string(100000, 'z') + ".obj"}}});
  const std::string meshScenario = dir.write("mesh.json", j.dump());
  const CliResult mesh =
      runCli("render " + quote(meshScenario) + " -o " + quote(dir.file("frames2")) + " --size 32x32 --msaa 0");
  EXPECT_EQ(mesh.exitCode, 2) << mesh.describe();
  EXPECT_TRUE(isOneLine(mesh.err)) << mesh.err.substr(0, 400);
  EXPECT_LT(mesh.err.size(), meshScenario.size() + 300) << mesh.err.substr(0, 400);
  EXPECT_NE(mesh.err.find("zzzz.obj"), std::string::npos) << "the end of the path, with the file name, is shown";
}

TEST(ViewerHardening, TheSessionsInputHistoryGrowsWithChangesNotTicks) {
  // A scripted `step 5000000` on a 6 x 6 meadow held 550 MB of per-tick inputs (and a step of
  // 10^8 ten times that); the history now keeps runs of equal inputs.
  viewer::InputHistory h;
  TickInput quiet, moved;
  moved.hasCamera = true;
  moved.camera = {1, 2, 3};
  for (int64_t t = 0; t < 5000000; ++t) h.push_back(quiet);
  EXPECT_EQ(h.size(), 5000000);
  EXPECT_EQ(h.runCount(), 1u);
  h.push_back(moved);
  h.push_back(moved);
  h.push_back(quiet);
  EXPECT_EQ(h.runCount(), 3u);
  EXPECT_EQ(h[0], quiet);
  EXPECT_EQ(h[4999999], quiet);
  EXPECT_EQ(h[5000000], moved);
  EXPECT_EQ(h[5000001], moved);
  EXPECT_EQ(h[5000002], quiet);
  // A new branch from tick 5000001: the old future goes, the run that started before it stays.
  h.resize(5000001);
  EXPECT_EQ(h.size(), 5000001);
  EXPECT_EQ(h.runCount(), 2u);
  EXPECT_EQ(h[5000000], moved);
  h.push_back(quiet);
  EXPECT_EQ(h[5000001], quiet);
  h.resize(0);
  EXPECT_EQ(h.size(), 0);
  EXPECT_EQ(h.runCount(), 0u);
}

}  // namespace
}  // namespace sg
