// What writeFileAtomic does with what is already at an output's name (docs/robustness.md,
// "Outputs"): renaming a temporary file over it would replace a device, a FIFO or a symbolic link
// by a regular file (`--export-state /dev/null` once did). A regular file or a free name is
// replaced atomically; a symbolic link is followed (the link stays); a character device or FIFO is
// written straight to; a directory is refused.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "replay/cli/cli_common.h"
#include "replay/output_file.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

mode_t typeOf(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0 ? (st.st_mode & S_IFMT) : 0;
}

TEST(OutputTargets, AFifoNobodyReadsIsOneLineAndStaysAFifo) {
  TempDir dir;
  const std::string fifo = dir.file("out.fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string error;
  EXPECT_FALSE(writeFileAtomic(fifo, std::string("state"), &error));
  EXPECT_TRUE(contains(error, "no process reads the FIFO")) << error;
  EXPECT_EQ(typeOf(fifo), mode_t(S_IFIFO)) << "the FIFO was replaced";

  // The same through the command line: one line, exit 2, no wait.
  const CliResult r =
      runCli("replay " + quote(test::sourcePath("tests/data/sgr/tiny.sgr")) + " --to 3 --export-state " + quote(fifo));
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_TRUE(contains(r.err, "no process reads the FIFO")) << r.describe();
  EXPECT_EQ(typeOf(fifo), mode_t(S_IFIFO));
}

TEST(OutputTargets, AFifoWithAReaderGetsEveryByte) {
  TempDir dir;
  const std::string fifo = dir.file("out.fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // The read end is open before the write (non-blocking, so opening does not wait for a writer);
  // the reader thread drains it while the writer fills it: more than a pipe's buffer.
  const int readEnd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(readEnd, 0);
  std::string bytes(1 << 20, '\0');
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = char(i * 7 + 3);
  std::string got;
  std::thread reader([&] {
    char buf[65536];
    while (got.size() < bytes.size()) {
      pollfd p{readEnd, POLLIN, 0};
      if (::poll(&p, 1, 60000) <= 0) break;  // a broken writer fails the test instead of hanging it
      const ssize_t n = ::read(readEnd, buf, sizeof buf);
      if (n > 0) got.append(buf, size_t(n));
      if (n == 0 && (p.revents & POLLHUP)) break;
    }
  });
  std::string error;
  const bool written = writeFileAtomic(fifo, bytes, &error);
  reader.join();
  ::close(readEnd);
  EXPECT_TRUE(written) << error;
  EXPECT_TRUE(got == bytes) << "read " << got.size() << " of " << bytes.size() << " bytes";
  EXPECT_EQ(typeOf(fifo), mode_t(S_IFIFO));
}

TEST(OutputTargets, ASymbolicLinkIsFollowedAndStays) {
  TempDir dir;
  fs::create_directory(dir.path() / "real");
  const std::string target = dir.write("real/state.bin", "old");
  const std::string link = dir.file("link.bin");
  fs::create_symlink("real/state.bin", link);  // relative: resolved against the link's folder
  std::string error;
  ASSERT_TRUE(writeFileAtomic(link, std::string("new"), &error)) << error;
  EXPECT_EQ(typeOf(link), mode_t(S_IFLNK)) << "the link was replaced by a file";
  EXPECT_EQ(readFile(target), "new");

  // A dangling link: the file it names is created, the link stays.
  const std::string dangling = dir.file("dangling.bin");
  fs::create_symlink(dir.file("real/created.bin"), dangling);
  ASSERT_TRUE(writeFileAtomic(dangling, std::string("made"), &error)) << error;
  EXPECT_EQ(typeOf(dangling), mode_t(S_IFLNK));
  EXPECT_EQ(readFile(dir.file("real/created.bin")), "made");

  // A loop is one line, not a hang.
  const std::string a = dir.file("a"), b = dir.file("b");
  fs::create_symlink(b, a);
  fs::create_symlink(a, b);
  EXPECT_FALSE(writeFileAtomic(a, std::string("x"), &error));
  EXPECT_TRUE(contains(error, "symbolic link")) << error;
  EXPECT_EQ(typeOf(a), mode_t(S_IFLNK));
}

TEST(OutputTargets, ADirectoryIsRefused) {
  TempDir dir;
  const std::string folder = dir.file("folder");
  fs::create_directory(folder);
  std::string error;
  EXPECT_FALSE(writeFileAtomic(folder, std::string("x"), &error));
  EXPECT_TRUE(contains(error, "expected a file name, got a directory")) << error;
  EXPECT_TRUE(fs::is_directory(folder));
  EXPECT_TRUE(fs::is_empty(folder)) << "a temporary file was left behind";
}

TEST(OutputTargets, DevFullIsAFullDiskAndDevNullTakesEverything) {
  // Reached through symbolic links in a temporary folder, never by name: should the fix regress
  // (the temporary file renamed over the name given), only the link is replaced, not the device.
  for (const char* device : {"/dev/full", "/dev/null"})
    if (typeOf(device) != mode_t(S_IFCHR)) GTEST_SKIP() << device << " is not a character device here";
  TempDir dir;
  const std::string full = dir.file("full"), null = dir.file("null");
  fs::create_symlink("/dev/full", full);
  fs::create_symlink("/dev/null", null);
  std::string error;
  EXPECT_FALSE(writeFileAtomic(full, std::string("state"), &error));
  EXPECT_TRUE(contains(error, "No space left on device")) << error;
  EXPECT_TRUE(isOneLine(error + "\n"));
  EXPECT_EQ(typeOf(full), mode_t(S_IFLNK)) << "the link to /dev/full was replaced by a regular file";
  EXPECT_TRUE(writeFileAtomic(null, std::string("state"), &error)) << error;
  EXPECT_EQ(typeOf(null), mode_t(S_IFLNK)) << "the link to /dev/null was replaced by a regular file";
  EXPECT_EQ(typeOf("/dev/full"), mode_t(S_IFCHR));
  EXPECT_EQ(typeOf("/dev/null"), mode_t(S_IFCHR));

  // The same through the command line: the full disk is one line and exit 2.
  const CliResult r =
      runCli("replay " + quote(test::sourcePath("tests/data/sgr/tiny.sgr")) + " --to 3 --export-state " + quote(full));
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_TRUE(contains(r.err, "No space left on device")) << r.describe();
  EXPECT_EQ(typeOf(full), mode_t(S_IFLNK));
}

// ---- no output replaces a file the scenario reads (heightmap, meshes) or another output ---------

std::string tinyScenario() { return test::sourcePath("tests/data/sgr/tiny.json"); }

/// tiny.json with a heightmap terrain read from `heightmap` (relative to the scenario), named
/// `name`, its ball drawn as `mesh` when given.
std::string scenarioReading(const TempDir& dir, const std::string& heightmap, const std::string& name,
                            const std::string& mesh = "") {
  nlohmann::json s = nlohmann::json::parse(readFile(tinyScenario()));
  s["name"] = name;
  s["terrain"] = {{"type", "heightmap"}, {"file", heightmap}, {"cellSize", 0.5}, {"maxHeight", 1}, {"center", {0, 0}}};
  if (!mesh.empty()) s["bodies"]["list"][0]["mesh"] = mesh;
  return dir.write("s.json", s.dump());
}

const char* const kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

void expectRefusedOverwrite(const CliResult& r) {
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_TRUE(contains(r.err, "expected an output file other than the input")) << r.describe();
}

TEST(OutputTargets, SweepDoesNotWriteAPlotOverTheScenariosHeightmap) {
  TempDir dir;
  fs::create_directory(dir.path() / "o3");
  const std::string png = dir.write("o3/h-body.png", readFile(test::sourcePath("scenarios/hills.png")));
  const std::string scenario = scenarioReading(dir, "o3/h-body.png", "h");
  // --seconds 600: the plots' names are checked before the run, so this is refused at once (it
  // was refused only after the whole sweep ran, when the plot was about to be written).
  const CliResult r =
      runCli("sweep --scenarios " + quote(scenario) +
             " --seconds 600 --scalars fx32 --k 1 --dt 1/60 --lod off --repeats 1 --out " + quote(dir.file("o3")));
  expectRefusedOverwrite(r);
  EXPECT_EQ(readFile(png), readFile(test::sourcePath("scenarios/hills.png")));
  EXPECT_FALSE(fs::exists(dir.path() / "o3" / "sweep.csv"));
}

TEST(OutputTargets, RecordDoesNotWriteOverAMeshTheScenarioNames) {
  TempDir dir;
  const std::string mesh = dir.write("m.obj", kTriangle);
  nlohmann::json s = nlohmann::json::parse(readFile(tinyScenario()));
  s["bodies"]["list"][0]["mesh"] = "m.obj";
  const std::string scenario = dir.write("s.json", s.dump());
  expectRefusedOverwrite(runCli("record " + quote(scenario) + " -o " + quote(mesh) + " --ticks 2"));
  EXPECT_EQ(readFile(mesh), kTriangle);
}

#if SIMGRASS_HAS_VIEWER
TEST(OutputTargets, RenderDoesNotWriteAFrameOverTheScenariosHeightmap) {
  TempDir dir;
  fs::create_directory(dir.path() / "r5");
  const std::string hills = readFile(test::sourcePath("scenarios/hills.png"));
  const std::string png = dir.write("r5/frame-000003.png", hills);
  const std::string scenario = scenarioReading(dir, "r5/frame-000003.png", "r");
  const CliResult r = runCli("render " + quote(scenario) + " -o " + quote(dir.file("r5")) + " --ticks 3 --size 64x48");
  expectRefusedOverwrite(r);
  EXPECT_EQ(readFile(png), hills);
}

TEST(OutputTargets, RenderDoesNotWriteOverAMeshOrTwoOutputsOverEachOther) {
  TempDir dir;
  const std::string mesh = dir.write("m.obj", kTriangle);
  nlohmann::json s = nlohmann::json::parse(readFile(tinyScenario()));
  s["bodies"]["list"][0]["mesh"] = "m.obj";
  const std::string scenario = dir.write("s.json", s.dump());
  const std::string frames = dir.file("r3");
  const std::string base = "render " + quote(scenario) + " -o " + quote(frames) + " --ticks 0:2 --size 64x48";
  expectRefusedOverwrite(runCli(base + " --contact-sheet " + quote(mesh)));
  expectRefusedOverwrite(runCli(base + " --video " + quote(mesh)));
  EXPECT_EQ(readFile(mesh), kTriangle);
  // The sheet named as one of the frames (spelled differently too): refused before any frame.
  for (const std::string& sheet : {dir.file("r3/frame-000001.png"), dir.file("r3/./frame-000002.png")}) {
    const CliResult r = runCli(base + " --contact-sheet " + quote(sheet));
    EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_TRUE(contains(r.err, "expected a file other than a frame of -o")) << r.describe();
    EXPECT_FALSE(fs::exists(sheet));
  }
  // A sheet beside the frames under another name is fine.
  const CliResult ok = runCli(base + " --contact-sheet " + quote(dir.file("r3/sheet.png")));
  EXPECT_EQ(ok.exitCode, kExitOk) << ok.describe();
}

TEST(OutputTargets, RenderWithAMeshThatDoesNotLoadIsBadInput) {
  TempDir dir;
  const std::string nan = dir.write("nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string badIndex = dir.write("index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  const std::string empty = dir.write("empty.obj", "");
  for (const std::string& mesh : {nan, badIndex, empty, std::string("/dev/zero")}) {
    SCOPED_TRACE(mesh);
    nlohmann::json s = nlohmann::json::parse(readFile(tinyScenario()));
    s["bodies"]["list"][0]["mesh"] = mesh;
    const std::string scenario = dir.write("s.json", s.dump());
    const std::string frames = dir.file("frames");
    const CliResult r = runCli("render " + quote(scenario) + " -o " + quote(frames) + " --ticks 0 --size 64x48");
    EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_TRUE(contains(r.err, mesh)) << r.describe();
    EXPECT_FALSE(fs::exists(dir.file("frames/frame-000000.png"))) << "a frame without its mesh was written";
  }
}
#endif

}  // namespace
}  // namespace sg
