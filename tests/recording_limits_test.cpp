// The limits a `.sgr` reader enforces (docs/replay-format.md, "Limits a reader enforces") and the
// output side of every replay command, found by hostile testing:
//  - the preamble and HEAD header are checked before the rest of a file is read;
//  - no tick lies more than sgr::kMaxTickGap after the last one the file names (a forged END or
//    start tick cannot make replay, compare or diff run for ever; diff reserves nothing for it);
//  - a snapshot declaring more than the scenario's largest state is refused before decompressing;
//  - a recording missing a CHCK or SNAP its header promises is damaged;
//  - `record` refuses, before writing, anything `replay` would refuse;
//  - outputs are complete or absent, a full disk (ulimit -f, /dev/full) is one line and non-zero;
//  - no command overwrites one of its own inputs;
//  - error lines escape control characters; nothing aborts.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <xxhash.h>
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "replay/cli/cli_common.h"
#include "replay/format/sgr_reader.h"
#include "replay/format/sgr_writer.h"
#include "replay/player.h"
#include "replay/recording.h"
#include "sim/state/byte_order.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {
namespace fs = std::filesystem;

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

std::string tinyRecording() { return test::sourcePath("tests/data/sgr/tiny.sgr"); }
std::string tinyScenario() { return test::sourcePath("tests/data/sgr/tiny.json"); }

/// A chunk of a sound recording: its type and payload (framed again, with a fresh checksum, by
/// assemble()).
struct Chunk {
  sgr::ChunkType type;
  std::vector<uint8_t> payload;
};

std::vector<Chunk> chunksOf(const std::vector<uint8_t>& bytes) {
  std::vector<Chunk> out;
  size_t at = sgr::kPreambleBytes;
  while (at + sgr::kChunkHeaderBytes <= bytes.size()) {
    const uint32_t type = loadLE<uint32_t>(bytes.data() + at), length = loadLE<uint32_t>(bytes.data() + at + 4);
    const auto* p = bytes.data() + at + sgr::kChunkHeaderBytes;
    out.push_back({sgr::ChunkType(type), std::vector<uint8_t>(p, p + length)});
    at += sgr::kChunkHeaderBytes + length + sgr::kChunkTrailerBytes;
  }
  return out;
}

std::vector<uint8_t> assemble(const std::vector<Chunk>& chunks) {
  std::vector<uint8_t> out(std::begin(sgr::kMagic), std::end(sgr::kMagic));
  out.resize(sgr::kPreambleBytes);
  storeLE<uint32_t>(out.data() + 8, sgr::kFormatVersion);
  for (const Chunk& c : chunks) {
    const std::vector<uint8_t> framed = sgr::frameChunk(c.type, c.payload);
    out.insert(out.end(), framed.begin(), framed.end());
  }
  return out;
}

/// Byte offset of chunk `index`'s payload in assemble(chunks).
uint64_t payloadOffset(const std::vector<Chunk>& chunks, size_t index) {
  uint64_t at = sgr::kPreambleBytes;
  for (size_t i = 0; i < index; ++i) at += sgr::kChunkHeaderBytes + chunks[i].payload.size() + sgr::kChunkTrailerBytes;
  return at + sgr::kChunkHeaderBytes;
}

sgr::Header tinyHeader() { return sgr::parseRecording(readBytes(tinyRecording()), "tiny.sgr").header; }

/// tiny.sgr with only HEAD (changed by `edit`), its INPT chunks and an END of `endTick`: no hashes,
/// no snapshots.
std::vector<Chunk> withoutHashes(int64_t endTick, bool faulted = false) {
  sgr::Header h = tinyHeader();
  h.checkEvery = 0;
  h.snapshotEvery = 0;
  std::vector<Chunk> out{{sgr::ChunkType::Head, sgr::encodeHead(h)}};
  for (const Chunk& c : chunksOf(readBytes(tinyRecording())))
    if (c.type == sgr::ChunkType::Input) out.push_back(c);
  sgr::EndInfo e;
  e.tick = endTick;
  e.faulted = faulted;
  out.push_back({sgr::ChunkType::End, sgr::encodeEnd(e)});
  return out;
}

/// tiny.sgr with its HEAD payload replaced by `head`.
std::vector<uint8_t> withHead(const std::vector<uint8_t>& head) {
  std::vector<Chunk> chunks = chunksOf(readBytes(tinyRecording()));
  chunks[0].payload = head;
  return assemble(chunks);
}

/// tiny.sgr's HEAD without hashes or snapshots, and an INPT at tick 0 whose commands (the largest
/// value fx32 takes, 536,870,911 m/s, five times) overflow the ball's velocity in Q32.32 as they are
/// applied: a replay faults at once. (Each value alone is in range: a recording whose values are
/// not is refused when it is opened.)
std::vector<Chunk> faultingAtTickZero() {
  sgr::Header h = tinyHeader();
  h.checkEvery = 0;
  h.snapshotEvery = 0;
  std::vector<Chunk> chunks{{sgr::ChunkType::Head, sgr::encodeHead(h)}};
  TickInput blast;
  const int64_t largest = int64_t(536870911) << 32;
  for (int k = 0; k < 5; ++k)
    blast.bodies.push_back(BodyCommand{0, BodyCommandKind::AddVelocity, InputVec3{largest, largest, largest}});
  chunks.push_back({sgr::ChunkType::Input, sgr::encodeInput(0, blast, TickInput{})});
  return chunks;
}

/// The last tick the INPT chunks of tiny.sgr name.
int64_t lastInputTick() { return sgr::parseRecording(readBytes(tinyRecording()), "tiny.sgr").inputs.back().tick; }

/// The error parseRecording gives (empty when it reads).
sgr::RecordingError parseError(const std::vector<uint8_t>& bytes) {
  try {
    (void)sgr::parseRecording(bytes, "forged.sgr");
  } catch (const sgr::RecordingError& e) {
    return e;
  }
  return sgr::RecordingError("forged.sgr", 0, "(no error)");
}

/// Runs a shell script (sh -c) with stdout and stderr captured, under a 60 s timeout.
CliResult runShell(const std::string& script) {
  TempDir dir;
  const std::string out = dir.file("stdout"), err = dir.file("stderr");
  const std::string cmd = "timeout -k 5 60 sh -c " + quote(script) + " </dev/null >" + quote(out) + " 2>" + quote(err);
  const int status = std::system(cmd.c_str());
  CliResult r;
  if (WIFEXITED(status)) r.exitCode = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) r.exitCode = 128 + WTERMSIG(status);
  r.out = readFile(out);
  r.err = readFile(err);
  return r;
}

std::string cli() { return quote(SIMGRASS_CLI); }

/// Memory limits (ulimit -v) do not mix with AddressSanitizer's shadow memory.
bool sanitized() {
#if defined(SIMGRASS_TEST_ASAN)
  return true;
#else
  return test::slowBuild();
#endif
}

/// Files in `dir` other than those named.
std::vector<std::string> strayFiles(const fs::path& dir, const std::vector<std::string>& expected) {
  std::vector<std::string> out;
  for (const fs::directory_entry& f : fs::directory_iterator(dir)) {
    const std::string name = f.path().filename().string();
    if (std::find(expected.begin(), expected.end(), name) == expected.end()) out.push_back(name);
  }
  return out;
}

// ---- 1. the header is read before the rest -----------------------------------------------------

TEST(RecordingLimits, AHugeFileThatIsNoRecordingIsRefusedBeforeItIsRead) {
  if (sanitized()) GTEST_SKIP() << "ulimit -v and AddressSanitizer do not mix";
  TempDir dir;
  // 6 GiB (sparse): reading it whole before checking the magic needs 6 GiB of memory.
  const std::string notRecording = dir.file("big.sgr"), badHead = dir.file("big-head.sgr");
  for (const std::string& path : {notRecording, badHead}) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ASSERT_GE(fd, 0);
    if (path == badHead) {
      std::vector<uint8_t> head(std::begin(sgr::kMagic), std::end(sgr::kMagic));
      head.resize(20);
      storeLE<uint32_t>(head.data() + 8, sgr::kFormatVersion);
      storeLE<uint32_t>(head.data() + 12, uint32_t(sgr::ChunkType::Head));
      storeLE<uint32_t>(head.data() + 16, 0xFFFFFFF0u);
      ASSERT_EQ(::write(fd, head.data(), head.size()), ssize_t(head.size()));
    } else {
      ASSERT_EQ(::write(fd, "not a recording", 15), 15);
    }
    ASSERT_EQ(::ftruncate(fd, off_t(6) << 30), 0);
    ::close(fd);
  }
  const CliResult a = runShell("ulimit -v 2000000; exec " + cli() + " replay " + quote(notRecording) + " --info");
  EXPECT_EQ(a.exitCode, kExitBadInput) << a.describe();
  EXPECT_TRUE(isOneLine(a.err)) << a.describe();
  EXPECT_TRUE(contains(a.err, notRecording + ": byte 0: expected the .sgr magic")) << a.describe();
  const CliResult b = runShell("ulimit -v 2000000; exec " + cli() + " replay " + quote(badHead) + " --info");
  EXPECT_EQ(b.exitCode, kExitBadInput) << b.describe();
  EXPECT_TRUE(isOneLine(b.err)) << b.describe();
  EXPECT_TRUE(contains(b.err, badHead + ": byte 16: expected a HEAD payload of at most")) << b.describe();
}

TEST(RecordingLimits, AFifoOrADirectoryIsRefusedWithoutBlocking) {
  TempDir dir;
  const std::string fifo = dir.file("pipe.sgr");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  for (const std::string& path : {fifo, dir.path().string()}) {
    const CliResult r = runCli("replay " + quote(path) + " --info");
    EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_TRUE(contains(r.err, "expected a regular file")) << r.describe();
  }
}

TEST(RecordingLimits, TheFirstChunkMustBeAHeadBeforeTheRestIsRead) {
  TempDir dir;
  std::vector<Chunk> chunks = chunksOf(readBytes(tinyRecording()));
  chunks.erase(chunks.begin());  // INPT first
  const std::string path = dir.file("no-head.sgr");
  writeBytes(path, assemble(chunks));
  try {
    (void)sgr::readRecording(path);
    FAIL() << "a recording without HEAD was read";
  } catch (const sgr::RecordingError& e) {
    EXPECT_EQ(e.offset(), sgr::kPreambleBytes);
    EXPECT_TRUE(contains(e.what(), "the HEAD chunk first")) << e.what();
  }
}

// ---- 2. tick ranges are bounded by what the file holds ----------------------------------------

TEST(RecordingLimits, AnEndTickFarBeyondTheLastNamedTickIsDamageWithHashesOff) {
  const int64_t last = lastInputTick();
  // The last allowed final tick reads; one more, or a forged 2^40, does not.
  EXPECT_NO_THROW((void)sgr::parseRecording(assemble(withoutHashes(last + sgr::kMaxTickGap)), "ok.sgr"));
  for (const int64_t forged : {last + sgr::kMaxTickGap + 1, int64_t(1) << 40}) {
    const std::vector<Chunk> chunks = withoutHashes(forged);
    const sgr::RecordingError e = parseError(assemble(chunks));
    EXPECT_EQ(e.offset(), payloadOffset(chunks, chunks.size() - 1)) << e.what();
    EXPECT_TRUE(contains(e.what(), "a final tick from")) << e.what();
    EXPECT_TRUE(contains(e.what(), "at most " + std::to_string(sgr::kMaxTickGap) + " ticks after")) << e.what();
  }
}

TEST(RecordingLimits, AStartTickBeyondTheTickGapIsDamage) {
  for (const int64_t start : {sgr::kMaxTickGap + 1, int64_t(1) << 40}) {
    sgr::Header h = tinyHeader();
    h.startTick = start;
    std::vector<Chunk> chunks = chunksOf(readBytes(tinyRecording()));
    chunks[0].payload = sgr::encodeHead(h);
    const sgr::RecordingError e = parseError(assemble(chunks));
    EXPECT_EQ(e.offset(), sgr::kPreambleBytes + sgr::kChunkHeaderBytes + 28) << e.what();
    EXPECT_TRUE(contains(e.what(), "a start tick from 0 to " + std::to_string(sgr::kMaxTickGap))) << e.what();
  }
}

TEST(RecordingLimits, AnInputTickFarBeyondTheLastNamedTickIsDamage) {
  std::vector<Chunk> chunks = withoutHashes(0);
  chunks.pop_back();  // no END: a cut-off recording claims its last chunk's tick
  Chunk far = chunks.back();
  storeLE<int64_t>(far.payload.data(), lastInputTick() + sgr::kMaxTickGap + 1);
  chunks.push_back(far);
  const sgr::RecordingError e = parseError(assemble(chunks));
  EXPECT_EQ(e.offset(), payloadOffset(chunks, chunks.size() - 1)) << e.what();
  EXPECT_TRUE(contains(e.what(), "an input tick at most")) << e.what();
}

TEST(RecordingLimits, ReplayCompareAndDiffOfAForgedLongRecordingEndAtOnce) {
  TempDir dir;
  const std::string path = dir.file("forged-end.sgr");
  writeBytes(path, assemble(withoutHashes(int64_t(1) << 40)));
  for (const std::string& args :
       {"replay " + quote(path) + " --verify", "replay " + quote(path) + " --to 5",
        "compare " + quote(path) + " --variant interp=2", "diff " + quote(path) + " " + quote(path)}) {
    const CliResult r = runCli(args);
    SCOPED_TRACE(args);
    EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_TRUE(contains(r.err, path + ": byte ")) << r.describe();
    EXPECT_TRUE(contains(r.err, "a final tick from")) << r.describe();
  }
}

// ---- 3. diff allocates for the ticks it compares, not for those a file claims ------------------

TEST(RecordingLimits, DiffReservesNothingForTheTicksARecordingClaims) {
  if (sanitized()) GTEST_SKIP() << "ulimit -v and AddressSanitizer do not mix";
  // No hashes, an input every kMaxTickGap ticks up to ~2^26 ticks (all within the rules), and a
  // command at tick 0 that makes the ball's velocity overflow: both replays fault at once, so a
  // diff that reserved its series for every claimed tick (2^26 x 72 bytes) fails under 1 GB.
  std::vector<Chunk> chunks = faultingAtTickZero();
  TickInput camera;
  int64_t tick = 0;
  for (int i = 1; i <= 1024; ++i) {
    tick = int64_t(i) * sgr::kMaxTickGap;
    camera.hasCamera = true;
    camera.camera = InputVec3{i, 0, 0};
    TickInput previous = camera;
    previous.camera.x = i - 1;
    chunks.push_back({sgr::ChunkType::Input, sgr::encodeInput(tick, camera, previous)});
  }
  sgr::EndInfo e;
  e.tick = tick + 1;
  chunks.push_back({sgr::ChunkType::End, sgr::encodeEnd(e)});
  TempDir dir;
  const std::string path = dir.file("claims-long.sgr");
  writeBytes(path, assemble(chunks));
  ASSERT_EQ(sgr::readRecording(path).lastTick(), tick + 1);
  const CliResult r =
      runShell("ulimit -v 1000000; exec " + cli() + " diff " + quote(path) + " " + quote(path) + " --json");
  EXPECT_FALSE(contains(r.err, "internal error")) << r.describe();
  EXPECT_EQ(r.exitCode, kExitMismatch) << r.describe();  // the replays faulted where the recording did not
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_TRUE(contains(r.err, "faulted")) << r.describe();
}

// ---- 4. a snapshot is checked against the scenario's state size before it is decompressed -------

/// A zstd frame of `size` zero bytes made of RLE blocks (4 bytes per 128 KiB): 96 KB for 3 GiB.
std::vector<uint8_t> rleFrame(uint64_t size) {
  std::vector<uint8_t> f = {0x28, 0xb5, 0x2f, 0xfd, 0xe0};  // magic; single segment, 8-byte content size
  for (int i = 0; i < 8; ++i) f.push_back(uint8_t(size >> (8 * i)));
  const uint64_t block = uint64_t(128) << 10;
  for (uint64_t left = size; left > 0;) {
    const uint64_t n = std::min(left, block);
    left -= n;
    const uint32_t header = (left == 0 ? 1u : 0u) | 1u << 1 | uint32_t(n) << 3;
    f.push_back(uint8_t(header)), f.push_back(uint8_t(header >> 8)), f.push_back(uint8_t(header >> 16));
    f.push_back(0);
  }
  return f;
}

/// tiny.sgr with its first snapshot's frame replaced by a 3 GiB RLE bomb (size field to match).
std::vector<Chunk> snapshotBomb() {
  std::vector<Chunk> chunks = chunksOf(readBytes(tinyRecording()));
  for (Chunk& c : chunks)
    if (c.type == sgr::ChunkType::Snapshot) {
      const uint64_t size = uint64_t(3) << 30;
      std::vector<uint8_t> p(c.payload.begin(), c.payload.begin() + 24);
      storeLE<uint64_t>(p.data() + 16, size);
      const std::vector<uint8_t> frame = rleFrame(size);
      p.insert(p.end(), frame.begin(), frame.end());
      c.payload = std::move(p);
      break;
    }
  return chunks;
}

TEST(RecordingLimits, ASnapshotDeclaringMoreThanTheScenariosStateIsRefusedBeforeDecompressing) {
  const std::vector<Chunk> chunks = snapshotBomb();
  const std::vector<uint8_t> bytes = assemble(chunks);
  EXPECT_LT(bytes.size(), 120000u);
  const sgr::Recording r = sgr::parseRecording(bytes, "bomb.sgr");  // the framing is sound
  ASSERT_FALSE(r.snapshots.empty());
  const Player player(r);
  EXPECT_LT(player.largestStateBytes(), uint64_t(64) << 20);
  try {
    (void)r.snapshotState(r.snapshots[0], player.largestStateBytes());
    FAIL() << "a 3 GiB snapshot of a 6 x 6 meadow was decompressed";
  } catch (const sgr::RecordingError& e) {
    EXPECT_EQ(e.offset(), r.snapshots[0].offset - 8);
    EXPECT_TRUE(contains(e.what(), "the largest state this scenario can have")) << e.what();
  }
}

TEST(RecordingLimits, ReplayOfASnapshotBombIsOneLineUnderAMemoryLimit) {
  if (sanitized()) GTEST_SKIP() << "ulimit -v and AddressSanitizer do not mix";
  TempDir dir;
  const std::string path = dir.file("bomb.sgr");
  writeBytes(path, assemble(snapshotBomb()));
  for (const char* how : {" --verify", " --to 10"}) {
    const CliResult r = runShell("ulimit -v 1500000; exec " + cli() + " replay " + quote(path) + how);
    SCOPED_TRACE(how);
    EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_TRUE(contains(r.err, "the largest state this scenario can have")) << r.describe();
  }
}

TEST(RecordingLimits, TheLargestStateBoundHoldsEveryRealSnapshot) {
  // Real recordings (fx16 k=1 with bodies, double, the level of detail) never trip the bound,
  // whatever variant replays them.
  TempDir dir;
  struct Case {
    std::string scenario, variant;
  };
  for (const Case& c :
       {Case{test::sourcePath("scenarios/thesis-bodies.json"), "scalar=fx16"},
        Case{test::sourcePath("scenarios/thesis-bodies.json"), "scalar=double"}, Case{tinyScenario(), "interp=2"}}) {
    const std::string out = dir.file("real.sgr");
    const CliResult rec = runCli("record " + quote(c.scenario) + " -o " + quote(out) + " --ticks 40 --variant " +
                                 c.variant + " --snapshot-every 10");
    ASSERT_EQ(rec.exitCode, 0) << rec.describe();
    const sgr::Recording r = sgr::readRecording(out);
    ASSERT_FALSE(r.snapshots.empty());
    for (const VariantSettings& v : {VariantSettings{}, VariantSettings::parse("interp=4"),
                                     VariantSettings::parse("scalar=fx16"), VariantSettings::parse("lod=window")}) {
      const Player player(r, 1, v);
      for (const sgr::SnapshotInfo& s : r.snapshots)
        EXPECT_LE(s.rawBytes, player.largestStateBytes()) << c.scenario << " " << c.variant;
    }
  }
}

// ---- 5. every chunk a header promises must be there ---------------------------------------------

TEST(RecordingLimits, ARecordingStrippedOfItsSnapshotsIsDamaged) {
  std::vector<Chunk> chunks = chunksOf(readBytes(tinyRecording()));
  std::erase_if(chunks, [](const Chunk& c) { return c.type == sgr::ChunkType::Snapshot; });
  const sgr::RecordingError e = parseError(assemble(chunks));
  EXPECT_TRUE(contains(e.what(), "the SNAP chunk of tick 8 before the check of tick 8")) << e.what();
  // Cut off before END too: still damaged.
  chunks.pop_back();
  EXPECT_TRUE(contains(parseError(assemble(chunks)).what(), "the SNAP chunk of tick 8")) << e.what();

  TempDir dir;
  const std::string path = dir.file("no-snapshots.sgr");
  writeBytes(path, assemble(chunks));
  const CliResult r = runCli("replay " + quote(path) + " --verify");
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_TRUE(contains(r.err, "the SNAP chunk of tick 8")) << r.describe();
}

TEST(RecordingLimits, ARecordingMissingItsLastSnapshotOrItsChecksIsDamaged) {
  const std::vector<Chunk> all = chunksOf(readBytes(tinyRecording()));
  {  // the last SNAP (tick 24, the END tick) only
    std::vector<Chunk> chunks = all;
    auto last =
        std::find_if(chunks.rbegin(), chunks.rend(), [](const Chunk& c) { return c.type == sgr::ChunkType::Snapshot; });
    chunks.erase(std::next(last).base());
    const sgr::RecordingError e = parseError(assemble(chunks));
    EXPECT_TRUE(contains(e.what(), "the SNAP chunk of tick 24")) << e.what();
  }
  {  // every CHCK, the file cut before END
    std::vector<Chunk> chunks = all;
    std::erase_if(chunks, [](const Chunk& c) { return c.type == sgr::ChunkType::Check; });
    chunks.pop_back();
    const sgr::RecordingError e = parseError(assemble(chunks));
    EXPECT_TRUE(contains(e.what(), "the CHCK chunk of tick 1")) << e.what();
  }
}

TEST(RecordingLimits, ARecordingThatFaultedOnItsLastInputVerifies) {
  // The commands of tick 2 (each within the input range, so accepted at load) make the ball's
  // velocity overflow in the step from tick 2: END (faulted,
  // tick 2) follows the INPT of tick 2. Such a recording was refused as "a final tick from 3".
  TempDir dir;
  nlohmann::json s = nlohmann::json::parse(readFile(tinyScenario()));
  // Five commands of 5e8 m/s (each within the input range) add up beyond Q32.32's 2.1e9.
  s["script"] = nlohmann::json::array();
  for (int i = 0; i < 5; ++i)
    s["script"].push_back({{"tick", 2}, {"body", "ball"}, {"command", "addVelocity"}, {"value", {5e8, 5e8, 5e8}}});
  const std::string scenario = dir.write("fault.json", s.dump());
  const std::string out = dir.file("fault.sgr");
  const CliResult rec = runCli("record " + quote(scenario) + " -o " + quote(out) + " --ticks 20");
  ASSERT_EQ(rec.exitCode, kExitMismatch) << rec.describe();
  const sgr::Recording r = sgr::readRecording(out);
  ASSERT_TRUE(r.end && r.end->faulted);
  EXPECT_EQ(r.end->tick, 2);
  EXPECT_EQ(r.inputs.back().tick, 2);
  for (const char* how : {" --verify", " --verify --to 2", ""}) {
    const CliResult v = runCli("replay " + quote(out) + how);
    EXPECT_EQ(v.exitCode, kExitOk) << v.describe();
    EXPECT_EQ(v.err, "") << v.describe();
  }
}

// ---- 6. record refuses what replay would refuse -------------------------------------------------

TEST(RecordingLimits, TheWriterRefusesAHeaderOrAnInputTheReaderWouldRefuse) {
  TempDir dir;
  const std::string path = dir.file("refused.sgr");
  sgr::Header h = tinyHeader();
  h.scenarioSource = std::string(5000, 'x');
  EXPECT_THROW(sgr::Writer(path, h), std::runtime_error);
  EXPECT_FALSE(fs::exists(path)) << "the file was created before the header was checked";
  h = tinyHeader();
  h.files.resize(sgr::kMaxEmbeddedFiles + 1);
  EXPECT_THROW(sgr::Writer(path, h), std::runtime_error);
  EXPECT_FALSE(fs::exists(path));

  sgr::Writer w(path, tinyHeader());
  TickInput busy;
  busy.bodies.resize((sgr::kMaxInputPayload - sgr::inputPayloadBytes(0, true)) / 29 + 1);
  EXPECT_THROW(w.input(0, busy), std::runtime_error);
  busy.bodies.pop_back();
  EXPECT_TRUE(w.input(0, busy));  // the largest input that fits
  sgr::EndInfo e;
  e.tick = 1;
  e.faulted = true;
  e.message = std::string(10000, 'm');  // shortened, never a recording the reader refuses
  w.end(e);
  const sgr::Recording r = sgr::readRecording(path);
  EXPECT_EQ(r.inputs.at(0).input.bodies.size(), busy.bodies.size());
  EXPECT_EQ(r.end->message.size(), sgr::kMaxShortString);
}

TEST(RecordingLimits, TheWriterRefusesTheChunkThatWouldPassTheReadersLimit) {
  // The reader takes at most InputLimits::kRecordingBytes (16 GiB); a recording grown past it
  // would be refused at byte 0. The limit is lowered here so the test writes kilobytes.
  TempDir dir;
  const std::string path = dir.file("capped.sgr");
  uint64_t limit = 0;
  {
    sgr::Header h = tinyHeader();
    h.checkEvery = 1;
    h.snapshotEvery = 0;
    sgr::Writer w(path, h);
    limit = w.bytesWritten() + 4096;
    w.maxBytes = limit;
    bool refused = false;
    for (int64_t t = 0; t < 1000 && !refused; ++t) {
      try {
        w.check({t + 1, uint64_t(t)});
        w.flush();
      } catch (const std::runtime_error& e) {
        refused = true;
        EXPECT_TRUE(contains(e.what(), "at most " + std::to_string(limit) + " bytes")) << e.what();
      }
    }
    EXPECT_TRUE(refused) << "the writer went past its limit";
  }
  EXPECT_LE(fs::file_size(path), limit);
  const sgr::Recording r = sgr::readRecording(path);  // readable: cut off before END
  EXPECT_TRUE(r.truncated);
  EXPECT_FALSE(r.checks.empty());
}

TEST(RecordingLimits, AReplayThatFaultedBeforeItsTargetWritesNoState) {
  // No hashes and a command at tick 0 that makes the ball's velocity overflow: the replay faults
  // in the first step, long before --to 7; the state it stopped in is not tick 7's.
  std::vector<Chunk> chunks = faultingAtTickZero();
  sgr::EndInfo e;
  e.tick = 10;
  chunks.push_back({sgr::ChunkType::End, sgr::encodeEnd(e)});
  TempDir dir;
  const std::string recording = dir.file("faults.sgr");
  writeBytes(recording, assemble(chunks));
  for (const char* how : {"", " --verify"}) {
    for (const char* name : {"s.json", "s.bin"}) {
      const std::string state = dir.file(name);
      const CliResult r = runCli("replay " + quote(recording) + " --to 7" + how + " --export-state " + quote(state));
      EXPECT_EQ(r.exitCode, kExitMismatch) << r.describe();
      EXPECT_TRUE(isOneLine(r.err)) << r.describe();
      EXPECT_TRUE(contains(r.err, "no state written to " + state)) << r.describe();
      EXPECT_FALSE(fs::exists(state)) << "a state was written for a replay that faulted" << r.describe();
    }
    // The fault line names the recording, with or without a state to write.
    const CliResult r = runCli("replay " + quote(recording) + how);
    EXPECT_EQ(r.exitCode, kExitMismatch) << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_TRUE(contains(r.err, "simgrass replay: " + recording + ": ")) << r.describe();
  }
}

TEST(RecordingLimits, RecordRefusesAnInputLargerThanAnInptChunkBeforeWriting) {
  TempDir dir;
  nlohmann::json s = nlohmann::json::parse(readFile(tinyScenario()));
  nlohmann::json script = nlohmann::json::array();
  for (int i = 0; i < 40000; ++i)
    script.push_back({{"tick", 2}, {"body", "ball"}, {"command", "addVelocity"}, {"value", {0, 0.001, 0}}});
  s["script"] = script;
  const std::string scenario = dir.write("busy.json", s.dump());
  const std::string out = dir.file("busy.sgr");
  const CliResult r = runCli("record " + quote(scenario) + " -o " + quote(out) + " --ticks 5");
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_TRUE(contains(r.err, "tick 2: expected at most")) << r.describe();
  EXPECT_FALSE(fs::exists(out)) << "a recording replay would refuse was written";
}

TEST(RecordingLimits, RecordRefusesALongRecordingWithoutHashesOrSnapshots) {
  TempDir dir;
  const std::string out = dir.file("long.sgr");
  const CliResult r = runCli("record " + quote(tinyScenario()) + " -o " + quote(out) +
                             " --check-every 0 --snapshot-every 0 --ticks " + std::to_string(sgr::kMaxTickGap + 1));
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_TRUE(contains(r.err, "--ticks: expected at most")) << r.describe();
  EXPECT_FALSE(fs::exists(out));
}

TEST(RecordingLimits, TheRecorderRefusesAStepTheReaderCouldNotReach) {
  // Through the public facade: no hashes, no snapshots, so only the script's inputs (ticks 3 and
  // 13) name ticks; the step that would end kMaxTickGap + 1 ticks after tick 13 is refused, and
  // what was recorded still reads and verifies.
  TempDir dir;
  const std::string out = dir.file("sparse.sgr");
  RecordingSettings settings;
  settings.checkEvery = 0;
  settings.snapshotEvery = 0;
  RecordingSession session = RecordingSession::fromScenarioFile(tinyScenario(), out, settings);
  EXPECT_TRUE(session.stepScripted(13 + sgr::kMaxTickGap));
  EXPECT_THROW(session.stepScripted(1), std::runtime_error);
  EXPECT_EQ(session.finish().ticks, 13 + sgr::kMaxTickGap);
  const VerifyResult v = verifyRecording(out);
  EXPECT_TRUE(v.ok) << v.error;
  EXPECT_EQ(v.ticks, 13 + sgr::kMaxTickGap);
}

// ---- 7. outputs: complete or absent, every write checked ---------------------------------------

TEST(RecordingLimits, AFullDiskIsOneLineForEveryOutputAndLeavesNoPartialFile) {
  TempDir dir;
  const std::string a = dir.file("a.sgr");
  ASSERT_EQ(runCli("record " + quote(tinyScenario()) + " -o " + quote(a) + " --ticks 120").exitCode, 0);
  // ulimit -f 1: writes past 512 bytes (1 KiB in some shells) fail with EFBIG (SIGXFSZ is ignored,
  // not fatal); every output here is larger.
  struct Case {
    std::string args, output;
  };
  const std::vector<Case> cases = {
      {"replay " + quote(a) + " --export-state " + quote(dir.file("state.bin")), "state.bin"},
      {"replay " + quote(a) + " --export-state " + quote(dir.file("state.json")), "state.json"},
      {"diff " + quote(a) + " " + quote(a) + " --heatmap " + quote(dir.file("heat.png")), "heat.png"},
      {"diff " + quote(a) + " " + quote(a) + " --csv " + quote(dir.file("diff.csv")), "diff.csv"},
      {"compare " + quote(a) + " --variant interp=2 --series " + quote(dir.file("series.csv")), "series.csv"},
  };
  for (const Case& c : cases) {
    const CliResult r = runShell("ulimit -f 1; exec " + cli() + " " + c.args);
    SCOPED_TRACE(c.args);
    EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_TRUE(contains(r.err, c.output + ": cannot write")) << r.describe();
    EXPECT_EQ(strayFiles(dir.path(), {"a.sgr"}), std::vector<std::string>{}) << "a partial or temporary file";
  }
}

TEST(RecordingLimits, SweepOnAFullDiskIsOneLineAndLeavesNoPartialFile) {
  TempDir dir;
  const std::string scenario = dir.write("tiny.json", readFile(tinyScenario()));
  const std::string sweep = cli() + " sweep --scenarios " + quote(scenario) +
                            " --seconds 0.1 --scalars fx32 --k 1 --dt 1/60 --lod off --repeats 1 --out ";
  const std::string out = dir.file("out");
  // ulimit -f 8: the reference recording (in TMPDIR) and the CSV fit, the 30 KB plots do not.
  const CliResult r =
      runShell("export TMPDIR=" + quote(dir.path().string()) + "; ulimit -f 8; exec " + sweep + quote(out));
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_TRUE(contains(r.err, ".png: cannot write")) << r.describe();
  for (const fs::directory_entry& f : fs::directory_iterator(out))
    EXPECT_FALSE(contains(f.path().filename().string(), ".tmp-")) << f.path();
  for (const fs::directory_entry& f : fs::directory_iterator(dir.path()))  // the reference recording went
    EXPECT_FALSE(contains(f.path().filename().string(), "simgrass-sweep-")) << f.path();
  // The scenario itself as an output (sweep.json in --out) is refused before anything runs.
  const std::string inOut = dir.write("out/sweep.json", readFile(tinyScenario()));
  const CliResult c = runCli("sweep --scenarios " + quote(inOut) +
                             " --seconds 0.1 --scalars fx32 --k 1 --dt 1/60 --lod off --repeats 1 --out " + quote(out));
  EXPECT_EQ(c.exitCode, kExitBadInput) << c.describe();
  EXPECT_TRUE(contains(c.err, "expected an output file other than the input")) << c.describe();
  EXPECT_EQ(readFile(inOut), readFile(tinyScenario()));
}

TEST(RecordingLimits, ARecordingCutByAFullDiskIsOneLineAndReadsUpToTheCut) {
  TempDir dir;
  const std::string out = dir.file("full.sgr");
  const CliResult r = runShell("ulimit -f 8; exec " + cli() + " record " + quote(tinyScenario()) + " -o " + quote(out) +
                               " --ticks 600");
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_TRUE(contains(r.err, out + ": cannot write the recording")) << r.describe();
  const sgr::Recording rec = sgr::readRecording(out);  // everything before the failed write
  EXPECT_TRUE(rec.truncated);
  EXPECT_GT(rec.checks.size(), 10u);
  EXPECT_TRUE(Player(rec).verify().ok);
}

TEST(RecordingLimits, AStandardOutputThatCannotBeWrittenIsAFailedCommand) {
  const CliResult r = runShell("exec " + cli() + " replay " + quote(tinyRecording()) + " --info --json >/dev/full");
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_TRUE(contains(r.err, "simgrass replay: standard output: cannot write")) << r.describe();
}

TEST(RecordingLimits, RecordToAFifoIsRefusedWithoutWaitingForAReader) {
  TempDir dir;
  const std::string fifo = dir.file("out.sgr");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const CliResult r = runCli("record " + quote(tinyScenario()) + " -o " + quote(fifo) + " --ticks 2");
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_TRUE(contains(r.err, fifo + ": cannot create the recording")) << r.describe();
}

TEST(RecordingLimits, TwoOutputsOfOneCommandMayNotBeTheSameFile) {
  TempDir dir;
  const std::string a = dir.file("a.sgr"), out = dir.file("out.csv");
  ASSERT_EQ(runCli("record " + quote(tinyScenario()) + " -o " + quote(a) + " --ticks 4").exitCode, 0);
  for (const std::string& args :
       {"diff " + quote(a) + " " + quote(a) + " --csv " + quote(out) + " --heatmap " + quote(out),
        "compare " + quote(a) + " --variant interp=2 --csv " + quote(out) + " --series " + quote(out)}) {
    const CliResult r = runCli(args);
    SCOPED_TRACE(args);
    EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_TRUE(contains(r.err, "expected a file other than the")) << r.describe();
  }
}

TEST(RecordingLimits, AScenarioTextLargerThanAScenarioFileMayBeIsRefused) {
  sgr::Header h = tinyHeader();
  h.scenarioText = std::string(InputLimits::kScenarioBytes + 1, ' ');
  h.scenarioHash = XXH3_64bits(h.scenarioText.data(), h.scenarioText.size());
  EXPECT_NE(sgr::headerProblem(h), "");
  std::vector<Chunk> chunks = chunksOf(readBytes(tinyRecording()));
  chunks[0].payload = sgr::encodeHead(h);
  EXPECT_TRUE(contains(parseError(assemble(chunks)).what(), "the scenario text length that fits")) << "read";
}

// ---- 8. no command overwrites its own input -----------------------------------------------------

TEST(RecordingLimits, NoCommandOverwritesOneOfItsInputs) {
  TempDir dir;
  const std::string scenario = dir.write("x.json", readFile(tinyScenario()));
  const std::string a = dir.file("a.sgr"), b = dir.file("b.sgr");
  ASSERT_EQ(runCli("record " + quote(scenario) + " -o " + quote(a) + " --ticks 10").exitCode, 0);
  ASSERT_EQ(runCli("record " + quote(scenario) + " -o " + quote(b) + " --ticks 10").exitCode, 0);
  ASSERT_EQ(::link(a.c_str(), dir.file("a-link.sgr").c_str()), 0);
  const std::string track =
      dir.write("track.json", R"({"format": "simgrass-input-track/1", "camera": [], "commands": []})");
  const std::vector<std::string> inputs = {scenario, a, b, track};
  std::vector<std::string> before;
  for (const std::string& f : inputs) before.push_back(readFile(f));
  const std::string aDotted = (dir.path() / "." / "a.sgr").string();
  for (const std::string& args : {
           "record " + quote(scenario) + " -o " + quote(scenario),
           "record " + quote(scenario) + " --input " + quote(track) + " -o " + quote(track),
           "replay " + quote(a) + " --export-state " + quote(a),
           "replay " + quote(a) + " --export-state " + quote(dir.file("a-link.sgr")),
           "replay " + quote(a) + " --export-state " + quote(aDotted),
           "diff " + quote(a) + " " + quote(b) + " --csv " + quote(b),
           "diff " + quote(a) + " " + quote(b) + " --heatmap " + quote(a),
           "compare " + quote(a) + " --variant interp=2 --csv " + quote(a),
           "compare " + quote(a) + " --variant interp=2 --series " + quote(a),
       }) {
    const CliResult r = runCli(args);
    SCOPED_TRACE(args);
    EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_TRUE(contains(r.err, "expected an output file other than the input")) << r.describe();
  }
  for (size_t i = 0; i < inputs.size(); ++i) EXPECT_EQ(readFile(inputs[i]), before[i]) << inputs[i] << " changed";
}

TEST(RecordingLimits, TheFacadeDoesNotRecordOverItsScenario) {
  TempDir dir;
  const std::string scenario = dir.write("x.json", readFile(tinyScenario()));
  EXPECT_THROW((void)RecordingSession::fromScenarioFile(scenario, scenario), std::runtime_error);
  EXPECT_EQ(readFile(scenario), readFile(tinyScenario()));
}

TEST(RecordingLimits, ReplayChecksTheExportFolderBeforeReplaying) {
  const std::string target = (fs::temp_directory_path() / "h2-no-such-folder" / "state.bin").string();
  const CliResult r = runCli("replay " + quote(tinyRecording()) + " --export-state " + quote(target));
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_EQ(r.out, "") << "it replayed before finding out it could not write";
}

TEST(RecordingLimits, RecordDoesNotOverwriteTheHeightmapItEmbeds) {
  TempDir dir;
  const std::string png = dir.write("h.png", readFile(test::sourcePath("scenarios/hills.png")));
  nlohmann::json s = nlohmann::json::parse(readFile(tinyScenario()));
  s["terrain"] = {{"type", "heightmap"}, {"file", "h.png"}, {"cellSize", 0.5}, {"maxHeight", 1}, {"center", {0, 0}}};
  const std::string scenario = dir.write("h.json", s.dump());
  const std::string before = readFile(png);
  const CliResult r = runCli("record " + quote(scenario) + " -o " + quote(png) + " --ticks 2");
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(contains(r.err, "expected an output file other than the input")) << r.describe();
  EXPECT_EQ(readFile(png), before);
}

// ---- 9. one line, always ------------------------------------------------------------------------

TEST(RecordingLimits, AFileNameWithANewlineStaysOnOneLine) {
  TempDir dir;
  const std::string path = dir.file("bad\nname.sgr");
  writeBytes(path, {'n', 'o', 'p', 'e', 0, 0, 0, 0, 0, 0, 0, 0, 0});
  for (const std::string& args : {"replay " + quote(path) + " --verify", "diff " + quote(path) + " " + quote(path),
                                  "compare " + quote(path) + " --variant interp=2",
                                  "record " + quote(path) + " -o " + quote(dir.file("x.sgr"))}) {
    const CliResult r = runCli(args);
    SCOPED_TRACE(args);
    EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << r.describe();
    EXPECT_TRUE(contains(r.err, "bad\\nname.sgr")) << r.describe();
  }
}

TEST(RecordingLimits, AFileNameThatIsNotUtf8StillGivesJson) {
  TempDir dir;
  const std::string path = dir.file("caf\xe9.sgr");
  writeBytes(path, readBytes(tinyRecording()));
  const CliResult r = runCli("replay " + quote(path) + " --info --json");
  EXPECT_EQ(r.exitCode, kExitOk) << r.describe();
  EXPECT_TRUE(parseJson(r).is_object()) << r.describe();
}

TEST(RecordingLimits, RunningOutOfMemoryIsOneLineNotAnAbort) {
  if (sanitized()) GTEST_SKIP() << "ulimit -v and AddressSanitizer do not mix";
  // A 2048 x 2048 meadow fits the machine (the scenario check) but not a 400 MB address space.
  TempDir dir;
  const std::string scenario =
      dir.write("wide.json", R"({"name": "wide", "field": {"patchesX": 2048, "patchesZ": 2048}})");
  const CliResult r = runShell("ulimit -v 400000; exec " + cli() + " record " + quote(scenario) + " -o " +
                               quote(dir.file("wide.sgr")) + " --ticks 1");
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  // (On a machine with too little memory for the meadow, the scenario check refuses it first.)
  EXPECT_TRUE(contains(r.err, "simgrass record: internal error: out of memory") ||
              contains(r.err, "simgrass record: " + scenario + ": $"))
      << r.describe();
}

TEST(RecordingLimits, AnOptionValueIsEchoedShortened) {
  const std::string longValue(500, '7');
  const CliResult r =
      runCli("diff " + quote(tinyRecording()) + " " + quote(tinyRecording()) + " --heatmap " +
             quote((fs::temp_directory_path() / "h2-never.png").string()) + " --heatmap-tick " + longValue);
  EXPECT_EQ(r.exitCode, kExitBadInput) << r.describe();
  EXPECT_TRUE(isOneLine(r.err)) << r.describe();
  EXPECT_TRUE(contains(r.err, std::string(60, '7') + "...")) << r.describe();
  EXPECT_FALSE(contains(r.err, std::string(61, '7'))) << r.describe();
}

TEST(RecordingLimits, EscapeControlKeepsTextOnOneLine) {
  EXPECT_EQ(escapeControl("a\nb\rc\td\x01\x7f"), "a\\nb\\rc\\td\\x01\\x7f");
  EXPECT_EQ(escapeControl("caf\xc3\xa9"), "caf\xc3\xa9");  // UTF-8 passes through
}

// A later format that used the reserved bytes was read as this one; a second file of the same
// name was ignored, so the recording did not say what it replays.
TEST(RecordingHead, ReservedBytesMustBeZeroAndEmbeddedNamesUnique) {
  const uint64_t head = payloadOffset(chunksOf(readBytes(tinyRecording())), 0);
  for (size_t byte : {1, 2, 3}) {
    std::vector<uint8_t> payload = sgr::encodeHead(tinyHeader());
    payload[byte] = 0x01;
    const sgr::RecordingError e = parseError(withHead(payload));
    EXPECT_EQ(e.offset(), head + 1) << e.what();
    EXPECT_TRUE(contains(e.what(), "expected reserved bytes 0")) << e.what();
  }
  sgr::Header h = tinyHeader();
  h.files = {{"hill.png", {1, 2, 3}}, {"hill.png", {4, 5}}};
  const sgr::RecordingError e = parseError(withHead(sgr::encodeHead(h)));
  EXPECT_TRUE(contains(e.what(), "expected each embedded file name once")) << e.what();
  EXPECT_GT(e.offset(), head);
  // record refuses beforehand what replay would refuse.
  EXPECT_TRUE(contains(sgr::headerProblem(h), "each embedded file name once (hill.png is given twice)"));
  h.files[1].name = "other.png";
  EXPECT_EQ(sgr::headerProblem(h), "");
  EXPECT_TRUE(contains(parseError(withHead(sgr::encodeHead(h))).what(), "(no error)"));
}

}  // namespace
}  // namespace sg
