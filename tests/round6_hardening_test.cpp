// Hostile recordings an independent pass found read as if sound (2026-11-29, round 6;
// docs/robustness.md): a snapshot whose hash is not its tick's check, and camera positions beyond
// the scalar's range. Each must be one line naming the byte, and exit 2.
#include <gtest/gtest.h>
#include <xxhash.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "replay/variant.h"
#include "sim/scenario/json_bounds.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// Calls `edit(bytes, payloadAt)` on the first chunk of `type` (4 ASCII bytes) that `edit` takes
/// (returns true for), then recomputes that chunk's XXH3 checksum. Chunks: type, u32 length,
/// payload, u64 checksum (little-endian on the machines that run this). False if none was taken.
bool forgeChunk(std::vector<uint8_t>& bytes, const char* type,
                const std::function<bool(std::vector<uint8_t>&, size_t)>& edit) {
  for (size_t at = 12; at + 8 <= bytes.size();) {
    uint32_t length = 0;
    std::memcpy(&length, bytes.data() + at + 4, 4);
    if (std::memcmp(bytes.data() + at, type, 4) == 0 && edit(bytes, at + 8)) {
      const uint64_t sum = XXH3_64bits(bytes.data() + at, 8 + size_t(length));
      std::memcpy(bytes.data() + at + 8 + length, &sum, 8);
      return true;
    }
    at += 16 + size_t(length);
  }
  return false;
}

/// tests/data/sgr/tiny.json recorded for 24 ticks on one thread into `dir` as `name`, with
/// `options`; "" when the recording failed.
std::string recordTiny(TempDir& dir, const std::string& name, const std::string& options) {
  const std::string rec = dir.file(name);
  const CliResult r = runCli("record " + quote(test::sourcePath("tests/data/sgr/tiny.json")) +
                             " --ticks 24 --threads 1 -o " + quote(rec) + options);
  EXPECT_EQ(r.exitCode, 0) << r.describe();
  return r.exitCode == 0 ? rec : std::string();
}

TEST(Round6Hardening, ASnapshotWhoseHashIsNotItsTicksCheckIsRefused) {
  // A snapshot spliced in from another run keeps its own hash and checksum: `render` drew that
  // run's state with exit 0, and `replay --verify` printed the mismatch and then "matches".
  TempDir dir;
  const std::string rec = recordTiny(dir, "t.sgr", " --snapshot-every 10");
  ASSERT_FALSE(rec.empty());
  std::vector<uint8_t> bytes = readBytes(rec);
  ASSERT_TRUE(forgeChunk(bytes, "SNAP", [](std::vector<uint8_t>& b, size_t payload) {
    b[payload + 8] ^= 1;  // the snapshot hash, after its tick
    return true;
  }));
  writeBytes(rec, bytes);
  for (const std::string& command : {"replay " + quote(rec) + " --verify", "replay " + quote(rec) + " --to 12",
                                     "render " + quote(rec) + " --ticks 12 -o " + quote(dir.file("frames"))}) {
    const CliResult r = runCli(command);
    EXPECT_EQ(r.exitCode, 2) << command << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.err;
    EXPECT_TRUE(contains(r.err, "expected a snapshot whose hash is its tick's check hash")) << r.err;
  }
}

TEST(Round6Hardening, CameraCoordinatesBeyondTheScalarsRangeAreRefused) {
  // A camera at 2^30 m wrapped the level-of-detail window, and `replay --to 5 --export-state`
  // wrote the diverged state with exit 0 (no hash at tick 5 to catch it).
  TempDir dir;
  std::vector<uint8_t> bytes = readBytes(test::sourcePath("scenarios/recordings/lod-crossing-fx32.sgr"));
  ASSERT_TRUE(forgeChunk(bytes, "INPT", [](std::vector<uint8_t>& b, size_t payload) {
    if ((b[payload + 8] & 1) == 0 || b[payload + 9] != 1) return false;  // flags, then the camera flag
    const int64_t far = int64_t(1) << 62;                                // 2^30 m in Q32.32
    std::memcpy(b.data() + payload + 10, &far, 8);                       // x
    return true;
  }));
  const std::string rec = dir.file("far.sgr");
  writeBytes(rec, bytes);
  const CliResult r = runCli("replay " + quote(rec) + " --to 5 --export-state " + quote(dir.file("x.json")));
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.err;
  EXPECT_TRUE(contains(r.err, "expected camera coordinates within the fx32 range")) << r.err;
  EXPECT_FALSE(fs::exists(dir.file("x.json")));
}

TEST(Round6Hardening, RequestsThatWereIgnoredAreRefused) {
  // Each of these exited 0 having done less than was asked.
  TempDir dir;
  const std::string rec = quote(test::sourcePath("scenarios/recordings/thesis-bodies-fx32.sgr"));
  const std::string tiny = quote(test::sourcePath("tests/data/sgr/tiny.json"));
  const std::vector<std::pair<std::string, std::string>> cases{
      {"replay " + rec + " --info --to 5", "--to excludes --info"},
      {"replay " + rec + " --info --export-state " + quote(dir.file("i.bin")), "--export-state excludes --info"},
      {"replay " + rec + " --info --verify", "--verify excludes --info"},
      {"diff " + rec + " " + rec + " --heatmap-tick abc", "--heatmap-tick requires --heatmap"},
      {"record " + tiny + " --ticks 2 -o " + quote(dir.file("v.sgr")) + " --variant scalar=fx16 --variant scalar=fx32",
       "--variant scalar: expected each setting once across the --variant options"}};
  for (const auto& [command, phrase] : cases) {
    const CliResult r = runCli(command);
    EXPECT_EQ(r.exitCode, 2) << command << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.err;
    EXPECT_TRUE(contains(r.err, phrase)) << command << "\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(dir.file("i.bin")));
  EXPECT_FALSE(fs::exists(dir.file("v.sgr")));
  // Different keys in two --variant options still combine.
  EXPECT_EQ(runCli("record " + tiny + " --ticks 2 -o " + quote(dir.file("w.sgr")) +
                   " --variant scalar=fx16 --variant interp=1")
                .exitCode,
            0);
}

TEST(Round6Hardening, RenderWarnsOfACutRecording) {
  // replay, compare and diff warn of a recording cut before its END and exit 3; render drew it
  // silently with exit 0.
  TempDir dir;
  const std::string rec = recordTiny(dir, "cut.sgr", "");
  ASSERT_FALSE(rec.empty());
  std::vector<uint8_t> bytes = readBytes(rec);
  bytes.resize(bytes.size() - 5);  // inside the END chunk
  writeBytes(rec, bytes);
  const CliResult r =
      runCli("render " + quote(rec) + " --ticks 5 --size 64x48 --msaa 0 -o " + quote(dir.file("frames")));
  EXPECT_EQ(r.exitCode, 3) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.err;
  EXPECT_TRUE(contains(r.err, "simgrass render: warning: ")) << r.err;
  EXPECT_TRUE(fs::exists(dir.file("frames/frame-000005.png"))) << r.describe();
}

TEST(Round6Hardening, BidirectionalControlsAreEscapedInMessages) {
  // A scenario named with U+202E (right-to-left override) reversed the rest of its line on a
  // terminal: the bidi formatting characters are escaped byte by byte, other text kept.
  EXPECT_EQ(escapeControl("a\xe2\x80\xae"
                          "b"),
            "a\\xe2\\x80\\xaeb");                                                            // U+202E
  EXPECT_EQ(escapeControl("\xe2\x81\xa6x\xe2\x81\xa9"), "\\xe2\\x81\\xa6x\\xe2\\x81\\xa9");  // U+2066, U+2069
  EXPECT_EQ(escapeControl("\xe2\x80\x8f\xd8\x9c"), "\\xe2\\x80\\x8f\\xd8\\x9c");             // U+200F, U+061C
  EXPECT_EQ(escapeControl("\xe2\x80\x94 caf\xc3\xa9"), "\xe2\x80\x94 caf\xc3\xa9");          // an em dash, an e acute
  TempDir dir;
  const std::string scenario =
      dir.write("rlo.json", "{\"name\": \"x\xe2\x80\xaey\", \"field\": {\"patchesX\": 2, \"patchesZ\": 2}}");
  const CliResult r = runCli("run " + quote(scenario) + " --ticks 1");
  EXPECT_EQ(r.exitCode, 0) << r.describe();
  EXPECT_TRUE(contains(r.out, "x\\xe2\\x80\\xaey")) << r.out;
  EXPECT_FALSE(contains(r.out, "\xe2\x80\xae")) << r.out;
}

TEST(Round6Hardening, AControlCharacterInVariantTextIsNamedWhole) {
  // A NUL in a recording header's variant cut the message at it, so it named "interp=1".
  try {
    (void)VariantSettings::parse(std::string("scalar=fx32 interp=1\0junk", 25));
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_TRUE(contains(what, "'scalar=fx32 interp=1\\x00junk'")) << what;
    EXPECT_TRUE(contains(what, "a control character inside")) << what;
  }
}

}  // namespace
}  // namespace sg
