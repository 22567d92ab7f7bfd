// Damaged, cut-off and tampered `.sgr` recordings. The committed corpus tests/data/sgr/damaged/
// (every cut of tiny.sgr, bit flips in each chunk type, wrong magic and version, unknown chunks,
// absurd lengths, damage behind valid checksums; made by make_damaged.py, see the README there)
// is read in-process and through `simgrass replay --verify`; a recorder killed by SIGKILL leaves a
// file that replays up to the cut; a recording whose scenario no longer loads is one line.
// Contract: one line naming the file, the byte offset and what was expected; exit code 2 (3 for
// a recording cut off before END whose contents verify); never a crash, a hang or a huge allocation.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <xxhash.h>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "replay/cli/cli_common.h"
#include "replay/format/sgr_reader.h"
#include "replay/format/sgr_writer.h"
#include "replay/player.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"

extern char** environ;

namespace sg {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

fs::path corpusDir() { return test::sourcePath("tests/data/sgr/damaged"); }
std::string tinyRecording() { return test::sourcePath("tests/data/sgr/tiny.sgr"); }

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// One entry of EXPECTED.json.
struct Expectation {
  std::string file, kind, outcome, message;
  std::optional<uint64_t> offset, truncatedAt;
};

std::vector<Expectation> loadExpectations() {
  const json j = json::parse(readFile(corpusDir() / "EXPECTED.json"));
  std::vector<Expectation> out;
  for (const auto& [file, e] : j.at("files").items()) {
    Expectation x{file,
                  e.at("kind").get<std::string>(),
                  e.at("outcome").get<std::string>(),
                  e.value("message", std::string()),
                  std::nullopt,
                  std::nullopt};
    if (e.contains("offset")) x.offset = e["offset"].get<uint64_t>();
    if (e.contains("truncatedAt")) x.truncatedAt = e["truncatedAt"].get<uint64_t>();
    out.push_back(x);
  }
  return out;
}

/// What reading a recording the way `simgrass replay --verify` does gives: parse it, decompress
/// every snapshot, build the player (scenario, body indices, initial state), verify every hash.
struct Outcome {
  std::string outcome;  ///< "ok", "truncated", "error" or "mismatch"
  std::string message;  ///< RecordingError::what(), or what the reader expected at the cut
  uint64_t offset = 0;  ///< the error's offset, or Recording::truncatedAt
  std::string step;     ///< where it failed
};

Outcome readThrough(const std::string& path) {
  Outcome o;
  o.step = "readRecording";
  try {
    const sgr::Recording r = sgr::readRecording(path);
    o.step = "snapshotState";
    for (const sgr::SnapshotInfo& s : r.snapshots) (void)r.snapshotState(s);
    o.step = "Player";
    Player player(r);
    o.step = "verify";
    const VerifyReport v = player.verify();
    if (!v.ok) {
      o.outcome = "mismatch";
      o.message = "verify failed at tick " + std::to_string(v.firstMismatchTick);
      return o;
    }
    o.outcome = r.truncated ? "truncated" : "ok";
    o.message = r.truncatedExpected;
    o.offset = r.truncatedAt;
  } catch (const sgr::RecordingError& e) {
    o.outcome = "error";
    o.message = e.what();
    o.offset = e.offset();
  }
  return o;
}

// ---- the committed corpus, in-process ----------------------------------------------------------

TEST(RecordingRobustness, TheCorpusSourceIsACompleteRecordingThatVerifies) {
  const sgr::Recording r = sgr::readRecording(tinyRecording());
  EXPECT_FALSE(r.truncated);
  ASSERT_TRUE(r.end.has_value());
  EXPECT_FALSE(r.inputs.empty());
  EXPECT_FALSE(r.checks.empty());
  EXPECT_GE(r.snapshots.size(), 2u);
  const Outcome o = readThrough(tinyRecording());
  EXPECT_EQ(o.outcome, "ok") << o.step << ": " << o.message
                             << "\n(re-record the corpus when the physics changed: tests/data/sgr/README.md)";
}

TEST(RecordingRobustness, EveryCorpusFileIsListedWithItsExpectedOutcome) {
  const std::vector<Expectation> expected = loadExpectations();
  std::set<std::string> listed;
  for (const Expectation& e : expected) listed.insert(e.file);
  std::set<std::string> present;
  for (const fs::directory_entry& f : fs::directory_iterator(corpusDir()))
    if (f.path().filename() != "EXPECTED.json") present.insert(f.path().filename().string());
  EXPECT_EQ(listed, present);
  std::set<std::string> kinds;
  for (const Expectation& e : expected) {
    kinds.insert(e.kind);
    EXPECT_TRUE(e.outcome == "error" || e.outcome == "truncated") << e.file << ": " << e.outcome;
    EXPECT_TRUE(e.outcome == "error" ? e.offset.has_value() : e.truncatedAt.has_value()) << e.file;
  }
  for (const char* kind :
       {"cut", "cut-head", "cut-preamble", "flip-type", "flip-length", "flip-payload", "flip-checksum", "magic",
        "version", "unknown-type", "absurd-length", "zstd", "body-index", "scenario", "missing-chunk", "tick-span"})
    EXPECT_TRUE(kinds.count(kind)) << "no damaged file of kind " << kind;
}

TEST(RecordingRobustness, EveryDamagedFileGivesItsExpectedOutcomeInProcess) {
  const std::vector<Expectation> expected = loadExpectations();
  ASSERT_GT(expected.size(), 100u);
  for (const Expectation& e : expected) {
    const std::string path = (corpusDir() / e.file).string();
    const Outcome o = readThrough(path);  // cut-off files replay and verify up to the cut
    EXPECT_EQ(o.outcome, e.outcome) << e.file << " (" << e.kind << "), at " << o.step << ": " << o.message;
    if (o.outcome != e.outcome) continue;
    EXPECT_TRUE(contains(o.message, e.message))
        << e.file << ": expected a message containing '" << e.message << "', got: " << o.message;
    if (e.outcome == "error") {
      EXPECT_EQ(o.offset, *e.offset) << e.file << ": " << o.message;
      const std::string prefix = path + ": byte " + std::to_string(o.offset) + ": expected ";
      EXPECT_EQ(o.message.rfind(prefix, 0), 0u) << e.file << ": " << o.message;
      EXPECT_FALSE(contains(o.message, "\n")) << e.file << ": " << o.message;
    } else {
      EXPECT_EQ(o.offset, *e.truncatedAt) << e.file << ": " << o.message;
    }
  }
}

// ---- the corpus through `simgrass replay --verify` ---------------------------------------------

/// One file per (kind, outcome), the first in name order.
std::vector<Expectation> cliSample() {
  std::map<std::pair<std::string, std::string>, Expectation> first;
  for (const Expectation& e : loadExpectations()) first.emplace(std::make_pair(e.kind, e.outcome), e);
  std::vector<Expectation> out;
  for (const auto& [key, e] : first) out.push_back(e);
  return out;
}

TEST(RecordingRobustness, ReplayVerifyOfADamagedFileIsOneLineAndExitCode2Or3) {
  const std::vector<Expectation> sample = cliSample();
  ASSERT_GE(sample.size(), 14u);
  for (const Expectation& e : sample) {
    const std::string path = (corpusDir() / e.file).string();
    const CliResult r = runCli("replay " + quote(path) + " --verify");
    SCOPED_TRACE(e.file + " (" + e.kind + ")");
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_TRUE(contains(r.err, path)) << r.describe();
    EXPECT_TRUE(contains(r.err, "expected ")) << r.describe();
    if (e.outcome == "error") {
      EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
      EXPECT_TRUE(contains(r.err, ": byte " + std::to_string(*e.offset) + ": expected ")) << r.describe();
      EXPECT_TRUE(contains(r.err, e.message)) << r.describe();
    } else {
      EXPECT_EQ(r.exitCode, kExitTruncated) << r.describe();
      EXPECT_TRUE(contains(r.err, "warning")) << r.describe();
      EXPECT_TRUE(contains(r.err, ": byte " + std::to_string(*e.truncatedAt) + ": expected ")) << r.describe();
      EXPECT_TRUE(contains(r.out, "verified ")) << r.describe();
    }
  }
}

TEST(RecordingRobustness, SeekingThroughADamagedSnapshotIsOneLine) {
  const std::string path = (corpusDir() / "snap-zstd-magic.sgr").string();
  const CliResult r = runCli("replay " + quote(path) + " --to 10");  // through the snapshot of tick 8
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_TRUE(contains(r.err, path + ": byte ")) << r.describe();
  EXPECT_TRUE(contains(r.err, "a zstd frame")) << r.describe();
}

// ---- a recorder killed mid-write ---------------------------------------------------------------

/// A child process, killed (SIGKILL) and reaped when it goes out of scope.
class Child {
 public:
  Child(const std::vector<std::string>& args, const std::string& outputFile) {
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, outputFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~Child() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      wait();
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  pid_t pid() const { return pid_; }
  /// Reaps the child; its wait status.
  int wait() {
    if (pid_ > 0)
      while (::waitpid(pid_, &status_, 0) < 0 && errno == EINTR) {
      }
    pid_ = -1;
    return status_;
  }
  /// False once it has exited (then reaped).
  bool running() {
    if (pid_ > 0 && ::waitpid(pid_, &status_, WNOHANG) == pid_) pid_ = -1;
    return pid_ > 0;
  }

 private:
  pid_t pid_ = -1;
  int status_ = 0;
};

TEST(RecordingRobustness, RecorderKilledMidWriteReplaysUpToTheCut) {
  // Release: the thesis bodies scene (151 x 151 tufts, 3 bodies, commands at ticks 10, 20, 40
  // and 200); the sanitizer build: the tiny corpus scenario.
  const bool slow = test::slowBuild();
  const std::string scenario =
      slow ? test::sourcePath("tests/data/sgr/tiny.json") : test::sourcePath("scenarios/thesis-bodies.json");
  const size_t wantChecks = slow ? 40 : 210;
  const size_t wantSnapshots = 2;
  TempDir dir;
  const std::string recording = dir.file("killed.sgr");
  Child child(
      {SIMGRASS_CLI, "record", scenario, "-o", recording, "--ticks", "100000", "--snapshot-every", slow ? "15" : "100"},
      dir.file("recorder.log"));
  ASSERT_GT(child.pid(), 0) << "cannot start " << SIMGRASS_CLI;

  // Wait (at most 60 s) until the file holds enough hashes and snapshots.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  size_t checks = 0, snapshots = 0;
  while (std::chrono::steady_clock::now() < deadline && child.running()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::error_code ec;
    if (fs::file_size(recording, ec) < 1024 || ec) continue;
    try {
      const sgr::Recording partial = sgr::readRecording(recording);
      checks = partial.checks.size();
      snapshots = partial.snapshots.size();
    } catch (const sgr::RecordingError& e) {
      FAIL() << "a recording being written must always read: " << e.what();
    }
    if (checks >= wantChecks && snapshots >= wantSnapshots) break;
  }
  ASSERT_TRUE(child.running()) << "the recorder stopped by itself:\n" << readFile(dir.file("recorder.log"));
  ASSERT_TRUE(checks >= wantChecks && snapshots >= wantSnapshots)
      << "the recording did not grow in 60 s: " << checks << " hashes, " << snapshots << " snapshots";
  ::kill(child.pid(), SIGKILL);
  const int status = child.wait();
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "wait status " << status;

  const sgr::Recording r = sgr::readRecording(recording);
  EXPECT_TRUE(r.truncated);
  EXPECT_FALSE(r.end.has_value());
  // Mid-chunk: what the cut chunk should have been; exactly on a chunk boundary: the END chunk.
  EXPECT_FALSE(r.truncatedExpected.empty());
  EXPECT_GE(r.checks.size(), wantChecks);
  EXPECT_GE(r.snapshots.size(), wantSnapshots);

  const CliResult c = runCli("replay " + quote(recording) + " --verify --json");
  EXPECT_EQ(c.exitCode, kExitTruncated) << c.describe();
  EXPECT_TRUE(isOneLine(c.err)) << c.describe();
  EXPECT_TRUE(contains(c.err, "warning: " + recording + ": byte " + std::to_string(r.truncatedAt) + ": expected "))
      << c.describe();
  const json j = parseJson(c);
  ASSERT_TRUE(j.is_object()) << c.describe();
  EXPECT_EQ(j.value("verified", false), true) << c.out;
  EXPECT_EQ(j.value("complete", true), false) << c.out;
  EXPECT_GT(j.value("ticks", int64_t(0)), 0) << c.out;
  EXPECT_EQ(j.value("ticks", int64_t(0)), r.lastTick()) << c.out;
  EXPECT_EQ(j.value("hashesChecked", int64_t(0)), r.hashedTicks()) << c.out;
  EXPECT_EQ(j.value("matchesRecording", false), true) << c.out;
}

// ---- a recording whose scenario no longer loads -------------------------------------------------

/// tiny.sgr with its HEAD's scenario text replaced (hash and checksum recomputed).
std::vector<uint8_t> withScenarioText(const std::string& text) {
  const std::vector<uint8_t> bytes = readBytes(tinyRecording());
  const sgr::Recording r = sgr::parseRecording(bytes, "tiny.sgr");
  const std::vector<uint8_t> head = sgr::frameChunk(sgr::ChunkType::Head, sgr::encodeHead(r.header));
  const size_t headEnd = sgr::kPreambleBytes + head.size();
  EXPECT_TRUE(std::equal(head.begin(), head.end(), bytes.begin() + sgr::kPreambleBytes))
      << "encodeHead(parse(HEAD)) must give the recorded HEAD back";
  sgr::Header h = r.header;
  h.scenarioText = text;
  h.scenarioHash = XXH3_64bits(text.data(), text.size());
  std::vector<uint8_t> out(bytes.begin(), bytes.begin() + sgr::kPreambleBytes);
  const std::vector<uint8_t> changed = sgr::frameChunk(sgr::ChunkType::Head, sgr::encodeHead(h));
  out.insert(out.end(), changed.begin(), changed.end());
  out.insert(out.end(), bytes.begin() + ptrdiff_t(headEnd), bytes.end());
  return out;
}

TEST(RecordingRobustness, ARecordingWhoseScenarioNoLongerLoadsIsOneLineAtHead) {
  std::string text = readFile(test::sourcePath("tests/data/sgr/tiny.json"));
  ASSERT_EQ(text.rfind("{", 0), 0u);
  text.insert(1, "\n  \"grassColour\": \"green\",");
  TempDir dir;
  const std::string path = dir.file("changed-scenario.sgr");
  writeBytes(path, withScenarioText(text));

  const sgr::Recording r = sgr::readRecording(path);  // the file itself is sound
  EXPECT_FALSE(r.truncated);
  try {
    (void)recordedScenario(r);
    FAIL() << "the unknown key was accepted";
  } catch (const sgr::RecordingError& e) {
    EXPECT_EQ(e.offset(), sgr::kPreambleBytes);
    EXPECT_TRUE(contains(e.what(), "grassColour")) << e.what();
  }

  const CliResult c = runCli("replay " + quote(path) + " --verify");
  EXPECT_EQ(c.exitCode, kExitBadInput) << c.describe();
  EXPECT_TRUE(isOneLine(c.err)) << c.describe();
  EXPECT_TRUE(contains(c.err, path + ": byte 12: expected a scenario that loads")) << c.describe();
  EXPECT_TRUE(contains(c.err, "grassColour")) << c.describe();
}

TEST(RecordingRobustness, ARecordingWhoseWorldDoesNotFitInMemoryIsOneLineAtHead) {
  // A scenario that parses but would need far more memory than any machine has.
  TempDir dir;
  const std::string path = dir.file("huge-field.sgr");
  writeBytes(path, withScenarioText(R"({"name": "huge", "field": {"patchesX": 1048576, "patchesZ": 1048576}})"));
  const CliResult c = runCli("replay " + quote(path) + " --verify");
  EXPECT_EQ(c.exitCode, kExitBadInput) << c.describe();
  EXPECT_TRUE(isOneLine(c.err)) << c.describe();
  EXPECT_TRUE(contains(c.err, path + ": byte 12: expected a scenario this build can run")) << c.describe();
}

}  // namespace
}  // namespace sg
