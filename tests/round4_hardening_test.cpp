// Hostile inputs an independent pass found accepted or echoed unbounded (2026-11-28, round 4;
// docs/robustness.md): a megabyte file name in a scenario, an empty --scenarios list, an empty
// --variant. Each must be one line naming the place, and exit 2.
#include <gtest/gtest.h>

#include <xxhash.h>

#include <cstring>
#include <string>
#include <vector>

#include "replay/recording.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(Round4Hardening, AMegabyteHeightmapNameIsEchoedInSixtyCharacters) {
  // The name is the scenario's text: an error quotes at most 60 characters of what it found. The
  // 1,000,000-character name used to be echoed whole, a one-megabyte error line.
  TempDir dir;
  const std::string name(100000, 'y');
  const std::string scenario =
      dir.write("long.json", R"({"field": {"patchesX": 6, "patchesZ": 6}, "terrain": {"type": "heightmap", "file": ")" +
                                 name + R"(.png"}})");
  const CliResult r = runCli("run " + quote(scenario) + " --ticks 1 --threads 1");
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.err.substr(0, 400);
  EXPECT_TRUE(contains(r.err, "$.terrain.file")) << r.err.substr(0, 400);
  // The scenario's own path, the JSON path, 60 characters of the name and the reason.
  EXPECT_LT(r.err.size(), scenario.size() + 300) << r.err.substr(0, 400);
}

TEST(Round4Hardening, AnEmptyScenarioListIsRefused) {
  // `--scenarios ''` swept nothing and wrote an empty table (and a plan that --merge refuses);
  // `--scenarios ','` was already refused.
  TempDir dir;
  for (const std::string& tail :
       {std::string(" --out ") + quote(dir.file("out")), std::string(" --plan ") + quote(dir.file("plan.json"))}) {
    const CliResult r = runCli("sweep --scenarios '' --scalars fx32 --k 1 --dt 1/60 --lod off" + tail);
    EXPECT_EQ(r.exitCode, 2) << tail << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.err;
    EXPECT_TRUE(contains(r.err, "--scenarios")) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir.file("out"))) << "nothing is written for a refused sweep";
  EXPECT_FALSE(fs::exists(dir.file("plan.json")));
}

TEST(Round4Hardening, AnEmptyVariantIsRefused) {
  // `--variant ''` recorded with the scenario's own settings and compared a "(recorded settings)"
  // row: an empty value where KEY=VALUE is required, as `--scalars ''` already was.
  TempDir dir;
  const std::string scenario = test::sourcePath("tests/data/sgr/tiny.json");
  const std::string out = dir.file("v.sgr");
  const CliResult record = runCli("record " + quote(scenario) + " --ticks 3 --threads 1 --variant '' -o " + quote(out));
  EXPECT_EQ(record.exitCode, 2) << record.describe();
  EXPECT_TRUE(isOneLine(record.err)) << record.err;
  EXPECT_TRUE(contains(record.err, "--variant")) << record.err;
  EXPECT_FALSE(fs::exists(out));

  ASSERT_EQ(runCli("record " + quote(scenario) + " --ticks 3 --threads 1 -o " + quote(out)).exitCode, 0);
  const CliResult compare = runCli("compare " + quote(out) + " --variant ''");
  EXPECT_EQ(compare.exitCode, 2) << compare.describe();
  EXPECT_TRUE(isOneLine(compare.err)) << compare.err;
  EXPECT_TRUE(contains(compare.err, "--variant")) << compare.err;
}

TEST(Round4Hardening, AnEndThatClaimsAFaultTheReplayDoesNotMeetIsSaidSo) {
  // The END chunk's fault flag set (its checksum recomputed) on a clean recording: the replay steps
  // on past the last tick without a fault. That was reported as "hash mismatch at tick 25:
  // recorded 0000000000000000, replayed 0000000000000000", two hashes nobody computed.
  TempDir dir;
  const std::string rec = dir.file("t.sgr");
  ASSERT_EQ(runCli("record " + quote(test::sourcePath("tests/data/sgr/tiny.json")) + " --ticks 24 --threads 1 -o " +
                   quote(rec))
                .exitCode,
            0);
  std::vector<uint8_t> bytes = readBytes(rec);
  bool forged = false;
  for (size_t at = 12; at + 8 <= bytes.size();) {  // chunks: type, u32 length, payload, u64 XXH3
    uint32_t length = 0;
    std::memcpy(&length, bytes.data() + at + 4, 4);  // little-endian on the machines that run this
    if (std::memcmp(bytes.data() + at, "END ", 4) == 0) {
      bytes[at + 8 + 16] = 1;  // after the final tick and hash
      const uint64_t sum = XXH3_64bits(bytes.data() + at, 8 + size_t(length));
      std::memcpy(bytes.data() + at + 8 + length, &sum, 8);
      forged = true;
    }
    at += 16 + size_t(length);
  }
  ASSERT_TRUE(forged);
  writeBytes(rec, bytes);
  const CliResult r = runCli("replay " + quote(rec) + " --verify");
  EXPECT_EQ(r.exitCode, 1) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.err;
  EXPECT_TRUE(
      contains(r.err, "the recording says the step from tick 24 faulted; the replay stepped it without a fault"))
      << r.err;
  EXPECT_FALSE(contains(r.err, "0000000000000000")) << r.err;
  // The library says the same (verifyRecording, what the CLI is built on).
  const VerifyResult v = verifyRecording(rec, 1);
  EXPECT_FALSE(v.ok);
  EXPECT_TRUE(v.recordedFaultMissing);
  EXPECT_EQ(v.firstMismatchTick, 25);
  EXPECT_TRUE(contains(v.error, "the replay stepped it without a fault")) << v.error;
}

TEST(Round4Hardening, AFloatParticlePast2To48FaultsAndWhatWasRecordedReplays) {
  // A lift of 1e14 m/s^2 (the largest value a float scenario may give) speeds the tufts past 2^48
  // m/s, beyond what a saved state may hold: the run went on, and `record` wrote snapshots its own
  // replay refused. Now the particle stage faults there, as a body does, in float and double, on
  // either kernel.
  TempDir dir;
  const std::string scenario = dir.write(
      "lift.json",
      R"({"scalar": "float", "field": {"patchesX": 2, "patchesZ": 2}, "particles": {"acceleration": [1e14, 1e14, 1e14]}})");
  for (const std::string& options :
       {std::string("--scalar float"), std::string("--scalar double"), std::string("--scalar float --kernel scalar"),
        std::string("--scalar double --kernel scalar")}) {
    const CliResult r = runCli("run " + quote(scenario) + " --ticks 300 --threads 1 " + options);
    EXPECT_EQ(r.exitCode, 1) << options << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.err;
    EXPECT_TRUE(contains(r.err, "beyond +-2^48 (a saved state's range)")) << r.err;
  }
  const std::string rec = dir.file("lift.sgr");
  const CliResult record = runCli("record " + quote(scenario) + " --ticks 300 --threads 1 -o " + quote(rec));
  EXPECT_EQ(record.exitCode, 1) << record.describe();
  const CliResult verify = runCli("replay " + quote(rec) + " --verify");
  EXPECT_EQ(verify.exitCode, 0) << verify.describe();
  const CliResult exported =
      runCli("replay " + quote(rec) + " --to 100 --export-state " + quote(dir.file("state.json")));
  EXPECT_EQ(exported.exitCode, 0) << exported.describe();
}

}  // namespace
}  // namespace sg
