// Hostile recordings an independent pass found read as if sound (2026-11-29, round 6;
// docs/robustness.md): a snapshot whose hash is not its tick's check, and camera positions beyond
// the scalar's range. Each must be one line naming the byte, and exit 2.
#include <gtest/gtest.h>
#include <xxhash.h>
#include <zstd.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "replay/variant.h"
#include "sim/scenario/fingerprint.h"
#include "sim/scenario/json_bounds.h"
#include "sim/scenario/scenario.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// A refusal: exit 2 and one line on stderr holding `phrase`.
void expectRefused(const CliResult& r, const std::string& phrase) {
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.err;
  EXPECT_TRUE(contains(r.err, phrase)) << r.err;
}

/// Where each chunk of a recording's bytes starts, and its payload length, in file order. Chunks:
/// type (4 ASCII bytes), u32 length, payload, u64 XXH3 checksum of the rest (little-endian on the
/// machines that run this).
std::vector<std::pair<size_t, uint32_t>> chunksOf(const std::vector<uint8_t>& bytes) {
  std::vector<std::pair<size_t, uint32_t>> chunks;
  for (size_t at = 12; at + 8 <= bytes.size();) {
    uint32_t length = 0;
    std::memcpy(&length, bytes.data() + at + 4, 4);
    chunks.emplace_back(at, length);
    at += 16 + size_t(length);
  }
  return chunks;
}

/// A chunk's bytes: `type`, the payload's length, the payload and the checksum.
std::vector<uint8_t> chunkBytes(const char* type, const std::vector<uint8_t>& payload) {
  std::vector<uint8_t> chunk(type, type + 4);
  const uint32_t length = uint32_t(payload.size());
  chunk.insert(chunk.end(), reinterpret_cast<const uint8_t*>(&length), reinterpret_cast<const uint8_t*>(&length) + 4);
  chunk.insert(chunk.end(), payload.begin(), payload.end());
  const uint64_t sum = XXH3_64bits(chunk.data(), chunk.size());
  chunk.insert(chunk.end(), reinterpret_cast<const uint8_t*>(&sum), reinterpret_cast<const uint8_t*>(&sum) + 8);
  return chunk;
}

/// Replaces the payload of the first chunk of `type` that `edit` takes (returns true for) by what
/// `edit` made of it, the chunk rebuilt around it. False if none was taken.
bool forgeChunk(std::vector<uint8_t>& bytes, const char* type, const std::function<bool(std::vector<uint8_t>&)>& edit) {
  for (const auto& [at, length] : chunksOf(bytes)) {
    if (std::memcmp(bytes.data() + at, type, 4) != 0) continue;
    std::vector<uint8_t> payload(bytes.begin() + long(at + 8), bytes.begin() + long(at + 8 + length));
    if (!edit(payload)) continue;
    const std::vector<uint8_t> chunk = chunkBytes(type, payload);
    bytes.erase(bytes.begin() + long(at), bytes.begin() + long(at + 16 + length));
    bytes.insert(bytes.begin() + long(at), chunk.begin(), chunk.end());
    return true;
  }
  return false;
}

/// tests/data/sgr/tiny.json recorded for 24 ticks on one thread to `rec`, with `options`: its
/// bytes (none when the recording failed).
std::vector<uint8_t> recordTiny(const std::string& rec, const std::string& options) {
  const CliResult r = runCli("record " + quote(test::sourcePath("tests/data/sgr/tiny.json")) +
                             " --ticks 24 --threads 1 -o " + quote(rec) + options);
  EXPECT_EQ(r.exitCode, 0) << r.describe();
  return r.exitCode == 0 ? readBytes(rec) : std::vector<uint8_t>();
}

/// recordTiny to `rec`, then cut inside its END chunk (its last 5 bytes); false if it failed.
bool recordCutTiny(const std::string& rec) {
  std::vector<uint8_t> bytes = recordTiny(rec, "");
  if (bytes.size() < 5) return false;
  bytes.resize(bytes.size() - 5);
  writeBytes(rec, bytes);
  return true;
}

TEST(Round6Hardening, ASnapshotWhoseHashIsNotItsTicksCheckIsRefused) {
  // A snapshot spliced in from another run keeps its own hash and checksum: `render` drew that
  // run's state with exit 0, and `replay --verify` printed the mismatch and then "matches".
  TempDir dir;
  const std::string rec = dir.file("t.sgr");
  std::vector<uint8_t> bytes = recordTiny(rec, " --snapshot-every 10");
  ASSERT_FALSE(bytes.empty());
  ASSERT_TRUE(forgeChunk(bytes, "SNAP", [](std::vector<uint8_t>& payload) {
    payload[8] ^= 1;  // the snapshot hash, after its tick
    return true;
  }));
  writeBytes(rec, bytes);
  std::vector<std::string> commands{"replay " + quote(rec) + " --verify", "replay " + quote(rec) + " --to 12"};
  if (SIMGRASS_HAS_VIEWER)  // the sanitizer build has no viewer: its `render` only says so
    commands.push_back("render " + quote(rec) + " --ticks 12 -o " + quote(dir.file("frames")));
  for (const std::string& command : commands) {
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
  ASSERT_TRUE(forgeChunk(bytes, "INPT", [](std::vector<uint8_t>& payload) {
    if ((payload[8] & 1) == 0 || payload[9] != 1) return false;  // flags, then the camera flag
    const int64_t far = int64_t(1) << 62;                        // 2^30 m in Q32.32
    std::memcpy(payload.data() + 10, &far, 8);                   // x
    return true;
  }));
  const std::string rec = dir.file("far.sgr");
  writeBytes(rec, bytes);
  const CliResult r = runCli("replay " + quote(rec) + " --to 5 --export-state " + quote(dir.file("x.json")));
  expectRefused(r, "expected camera coordinates within the fx32 range");
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
  if (!SIMGRASS_HAS_VIEWER) GTEST_SKIP() << "a build without the viewer (its `render` only says so)";
  // replay, compare and diff warn of a recording cut before its END and exit 3; render drew it
  // silently with exit 0.
  TempDir dir;
  const std::string rec = dir.file("cut.sgr");
  ASSERT_TRUE(recordCutTiny(rec));
  const CliResult r =
      runCli("render " + quote(rec) + " --ticks 5 --size 64x48 --msaa 0 -o " + quote(dir.file("frames")));
  EXPECT_EQ(r.exitCode, 3) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.err;
  EXPECT_TRUE(contains(r.err, "simgrass render: warning: ")) << r.err;
  EXPECT_TRUE(fs::exists(dir.file("frames/frame-000005.png"))) << r.describe();
}

TEST(Round6Hardening, ACutRecordingWithABadSeekIsOneLine) {
  // `replay cut.sgr --to 29` printed the cut's warning and then the --to error: two lines.
  TempDir dir;
  const std::string rec = dir.file("cut.sgr");
  ASSERT_TRUE(recordCutTiny(rec));
  expectRefused(runCli("replay " + quote(rec) + " --to 29"), "--to: expected a tick from 0 to 24");
  const CliResult ok = runCli("replay " + quote(rec) + " --to 5");
  EXPECT_EQ(ok.exitCode, 3) << ok.describe();
  EXPECT_TRUE(isOneLine(ok.err) && contains(ok.err, "simgrass replay: warning: ")) << ok.err;
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

TEST(Round6Hardening, ASnapshotThatDoesNotRestoreNamesItsStateByteOnce) {
  // "state byte 8: expected byte 8: expected ..." named the byte twice.
  TempDir dir;
  const std::string rec = dir.file("s.sgr");
  std::vector<uint8_t> bytes = recordTiny(rec, " --snapshot-every 10");
  ASSERT_FALSE(bytes.empty());
  ASSERT_TRUE(forgeChunk(bytes, "SNAP", [](std::vector<uint8_t>& payload) {
    // Payload: tick, hash, raw size (u64 each), then the zstd frame of the state.
    uint64_t raw = 0;
    std::memcpy(&raw, payload.data() + 16, 8);
    std::vector<uint8_t> state(raw);
    if (ZSTD_decompress(state.data(), state.size(), payload.data() + 24, payload.size() - 24) != raw) return false;
    state[8] ^= 0xff;  // the first section's tag, after the 8-byte magic
    std::vector<uint8_t> frame(ZSTD_compressBound(state.size()));
    frame.resize(ZSTD_compress(frame.data(), frame.size(), state.data(), state.size(), 3));
    payload.resize(24);
    payload.insert(payload.end(), frame.begin(), frame.end());
    return true;
  }));
  writeBytes(rec, bytes);
  const CliResult r = runCli("replay " + quote(rec) + " --to 12");
  expectRefused(r, "expected a snapshot of this scenario's state (state byte 8: expected ");
  EXPECT_FALSE(contains(r.err, "expected byte 8")) << r.err;
}

TEST(Round6Hardening, AnInputAtTheFinalTickSaysWhatIsMissing) {
  // An INPT of the END's tick (whose step was then taken, so the check after it is missing) said
  // "expected a final tick from 25 to 24".
  TempDir dir;
  const std::string rec = dir.file("i.sgr");
  std::vector<uint8_t> bytes = recordTiny(rec, "");
  ASSERT_FALSE(bytes.empty());
  const auto chunks = chunksOf(bytes);
  ASSERT_EQ(std::memcmp(bytes.data() + chunks.back().first, "END ", 4), 0);
  std::vector<uint8_t> payload(8, 0);  // tick 24, flags 0, no commands
  const int64_t tick = 24;
  std::memcpy(payload.data(), &tick, 8);
  payload.insert(payload.end(), {0, 0, 0, 0, 0});
  const std::vector<uint8_t> input = chunkBytes("INPT", payload);
  bytes.insert(bytes.begin() + long(chunks.back().first), input.begin(), input.end());
  writeBytes(rec, bytes);
  const CliResult r = runCli("replay " + quote(rec) + " --verify");
  expectRefused(r, "expected the check or snapshot due at tick 25 before this END");
}

TEST(Round6Hardening, ASeedOfMinusZeroIsZero) {
  // "seed": -0 was refused as "expected an integer from 0 to 2^64-1, got 0" (JSON keeps -0 signed).
  const Scenario minusZero = parseScenario(R"({"seed": -0})", "s.json", {});
  const Scenario zero = parseScenario(R"({"seed": 0})", "s.json", {});
  EXPECT_EQ(minusZero.seed, 0u);
  EXPECT_EQ(scenarioFingerprint(minusZero), scenarioFingerprint(zero));
  try {
    (void)parseScenario(R"({"seed": -1})", "s.json", {});
    FAIL() << "accepted";
  } catch (const ScenarioError& e) {
    EXPECT_TRUE(contains(e.what(), "$.seed: expected an integer from 0 to 2^64-1, got -1")) << e.what();
  }
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
