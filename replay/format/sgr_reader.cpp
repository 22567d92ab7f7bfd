#include "replay/format/sgr_reader.h"
#include "sim/state/byte_order.h"

#include <xxhash.h>
#include <zstd.h>
#include <algorithm>
#include <array>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <new>

#include "replay/input_file.h"

namespace sg::sgr {

RecordingError::RecordingError(const std::string& file, uint64_t offset, const std::string& expected)
    : std::runtime_error(file + ": byte " + std::to_string(offset) + ": expected " + expected),
      file_(file),
      offset_(offset),
      expected_(expected) {}

const char* chunkTypeName(ChunkType type) {
  switch (type) {
    case ChunkType::Head:
      return "HEAD";
    case ChunkType::Input:
      return "INPT";
    case ChunkType::Check:
      return "CHCK";
    case ChunkType::Snapshot:
      return "SNAP";
    case ChunkType::End:
      return "END";
  }
  return "unknown";
}

namespace {
/// Reads little-endian fields from one chunk's payload; every read is bounds-checked and a short
/// payload is an error at the offset where the field should have been.
class Cursor {
 public:
  Cursor(const Recording& r, uint64_t base, std::span<const uint8_t> payload, const char* chunk)
      : r_(r), base_(base), p_(payload), chunk_(chunk) {}
  uint64_t offset() const { return base_ + at_; }
  size_t remaining() const { return p_.size() - at_; }
  template <class T>
  T get(const char* what) {
    need(sizeof(T), what);
    const T v = loadLE<T>(p_.data() + at_);
    at_ += sizeof(T);
    return v;
  }
  std::string string(const char* what, size_t maxBytes) {
    const uint64_t at = offset();
    const uint32_t n = get<uint32_t>(what);
    if (n > remaining() || n > maxBytes)
      fail(at, std::string(what) + " length that fits the " + chunk_ + " chunk, got " + std::to_string(n));
    std::string s(reinterpret_cast<const char*>(p_.data() + at_), n);
    at_ += n;
    return s;
  }
  std::vector<uint8_t> bytes(const char* what) {
    const uint64_t at = offset();
    const uint32_t n = get<uint32_t>(what);
    if (n > remaining())
      fail(at, std::string(what) + " length that fits the " + chunk_ + " chunk, got " + std::to_string(n));
    std::vector<uint8_t> b(p_.begin() + ptrdiff_t(at_), p_.begin() + ptrdiff_t(at_ + n));
    at_ += n;
    return b;
  }
  InputVec3 vec3(const char* what) {
    InputVec3 v;
    v.x = get<int64_t>(what);
    v.y = get<int64_t>(what);
    v.z = get<int64_t>(what);
    return v;
  }
  void finished() {
    if (remaining() != 0)
      fail(offset(),
           std::string("the end of the ") + chunk_ + " chunk, got " + std::to_string(remaining()) + " extra bytes");
  }
  [[noreturn]] void fail(uint64_t at, const std::string& expected) const {
    throw RecordingError(r_.file, at, expected);
  }

 private:
  void need(size_t n, const char* what) const {
    if (remaining() < n)
      fail(offset(), std::string(what) + " (" + std::to_string(n) + " bytes), but the " + chunk_ + " chunk ends");
  }
  const Recording& r_;
  uint64_t base_;
  std::span<const uint8_t> p_;
  const char* chunk_;
  size_t at_ = 0;
};

/// The next tick on the grid startTick + n * every after `last` (-1: none yet).
int64_t nextOnGrid(int64_t last, int64_t startTick, uint32_t every) {
  const int64_t from = last < 0 ? startTick : last;
  return every == 0 || from > std::numeric_limits<int64_t>::max() - int64_t(every) ? std::numeric_limits<int64_t>::max()
                                                                                   : from + int64_t(every);
}

/// CHCK and SNAP chunks sit exactly every `every` ticks from the start: a missing or stray one is
/// damage, not a shorter recording.
void expectOnGrid(const Cursor& c, uint64_t at, int64_t tick, int64_t last, int64_t startTick, uint32_t every,
                  const char* chunk, const char* headerField, const char* noun) {
  if (every == 0) c.fail(at, std::string("no ") + chunk + " chunk (HEAD says " + headerField + " = 0)");
  const int64_t want = nextOnGrid(last, startTick, every);
  if (tick != want)
    c.fail(at, std::string("the ") + noun + " of tick " + std::to_string(want) + ", got tick " + std::to_string(tick));
}

uint64_t maxPayload(ChunkType t) {
  switch (t) {
    case ChunkType::Head:
      return kMaxHeadPayload;
    case ChunkType::Input:
      return kMaxInputPayload;
    case ChunkType::Check:
      return kMaxCheckPayload;
    case ChunkType::Snapshot:
      return kMaxSnapshotPayload;
    case ChunkType::End:
      return kMaxEndPayload;
  }
  return 0;
}

bool knownType(uint32_t t) {
  for (ChunkType k : {ChunkType::Head, ChunkType::Input, ChunkType::Check, ChunkType::Snapshot, ChunkType::End})
    if (t == uint32_t(k)) return true;
  return false;
}

std::string typeText(uint32_t t) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = char((t >> (8 * i)) & 0xff);
    s += (c >= 0x20 && c < 0x7f) ? c : '?';
  }
  return "'" + s + "'";
}

/// Tick bookkeeping shared by the chunk parsers: the last tick the file named and the grid
/// positions of CHCK and SNAP chunks seen so far.
struct Ticks {
  int64_t lastNamed = 0;  ///< tick 0 is where every replay starts
  int64_t lastCheck = -1, lastSnapshot = -1;
};

/// A tick the file names must lie at most kMaxTickGap ticks after the last one it named: the
/// ticks a recording can claim grow with its size, so a forged tick cannot make a replay (or the
/// `diff` series, or a viewer seek) run for ever.
void expectReachable(const Cursor& c, uint64_t at, int64_t tick, Ticks& ticks, const char* what) {
  if (tick > ticks.lastNamed && tick - ticks.lastNamed > kMaxTickGap)
    c.fail(at, std::string(what) + " at most " + std::to_string(kMaxTickGap) + " ticks after tick " +
                   std::to_string(ticks.lastNamed) + " (the last tick the file names before it), got tick " +
                   std::to_string(tick));
  ticks.lastNamed = std::max(ticks.lastNamed, tick);
}

/// The next CHCK (SNAP) tick the header promises, or INT64_MAX when it promises none.
int64_t nextCheckTick(const Recording& r, const Ticks& t) {
  return nextOnGrid(t.lastCheck, r.header.startTick, r.header.checkEvery);
}
int64_t nextSnapshotTick(const Recording& r, const Ticks& t) {
  return nextOnGrid(t.lastSnapshot, r.header.startTick, r.header.snapshotEvery);
}

/// The recorder writes, for each tick t, SNAP t and CHCK t (when due) before INPT t and before
/// anything of a later tick: a chunk of tick `tick` means every CHCK and SNAP the header promises
/// up to `tick` (before it, with `strictlyBefore`) is present. A recording stripped of its
/// snapshots or checks is damaged, not merely shorter.
void expectPromisedBefore(const Recording& r, const Cursor& c, uint64_t at, int64_t tick, const Ticks& t,
                          bool checksToo, bool snapshotsToo, bool strictlyBefore, const char* what) {
  auto missing = [&](int64_t due) { return strictlyBefore ? due < tick : due <= tick; };
  const int64_t check = nextCheckTick(r, t), snapshot = nextSnapshotTick(r, t);
  if (checksToo && missing(check))
    c.fail(at, "the CHCK chunk of tick " + std::to_string(check) + " before " + what + " of tick " +
                   std::to_string(tick) + " (HEAD says checkEvery = " + std::to_string(r.header.checkEvery) + ")");
  if (snapshotsToo && missing(snapshot))
    c.fail(at, "the SNAP chunk of tick " + std::to_string(snapshot) + " before " + what + " of tick " +
                   std::to_string(tick) + " (HEAD says snapshotEvery = " + std::to_string(r.header.snapshotEvery) +
                   ")");
}

void parseHead(Recording& r, Cursor& c) {
  Header& h = r.header;
  const uint64_t scalarAt = c.offset();
  const uint8_t scalar = c.get<uint8_t>("the scalar type");
  if (scalar > uint8_t(ScalarKind::Double)) c.fail(scalarAt, "a scalar type 0..3, got " + std::to_string(scalar));
  h.scalar = ScalarKind(scalar);
  // Reserved bytes are 0: a later format that uses them must not be read as this one.
  const uint64_t reservedAt = c.offset();
  if (c.get<uint8_t>("reserved") != 0 || c.get<uint16_t>("reserved") != 0)
    c.fail(reservedAt, "reserved bytes 0 (3 bytes after the scalar type)");
  h.checkEvery = c.get<uint32_t>("the check interval");
  h.snapshotEvery = c.get<uint32_t>("the snapshot interval");
  h.scenarioHash = c.get<uint64_t>("the scenario hash");
  h.initialStateHash = c.get<uint64_t>("the initial state hash");
  const uint64_t startAt = c.offset();
  h.startTick = c.get<int64_t>("the start tick");
  // Every replay starts from tick 0 (a fresh world): the start tick must be reachable from there.
  if (h.startTick < 0 || h.startTick > kMaxTickGap)
    c.fail(startAt, "a start tick from 0 to " + std::to_string(kMaxTickGap) + ", got " + std::to_string(h.startTick));
  h.variant = c.string("the variant settings", kMaxShortString);
  h.scenarioSource = c.string("the scenario file name", kMaxShortString);
  const uint64_t textAt = c.offset();
  h.scenarioText = c.string("the scenario text", InputLimits::kScenarioBytes);  // as a scenario file
  if (XXH3_64bits(h.scenarioText.data(), h.scenarioText.size()) != h.scenarioHash)
    c.fail(textAt, "scenario text matching its hash");
  const uint64_t countAt = c.offset();
  const uint32_t files = c.get<uint32_t>("the embedded file count");
  if (files > kMaxEmbeddedFiles)
    c.fail(countAt, "at most " + std::to_string(kMaxEmbeddedFiles) + " embedded files, got " + std::to_string(files));
  for (uint32_t f = 0; f < files; ++f) {
    EmbeddedFile e;
    const uint64_t nameAt = c.offset();
    e.name = c.string("an embedded file name", kMaxShortString);
    // Names are looked up by the scenario's file names: one name, one file (a second would be
    // ignored, so the recording would not say what it replays).
    for (const EmbeddedFile& before : h.files)
      if (before.name == e.name) c.fail(nameAt, "each embedded file name once (this one is given twice)");
    e.bytes = c.bytes("an embedded file");
    h.files.push_back(std::move(e));
  }
  h.buildId = c.string("the build id", kMaxShortString);
  c.finished();
}

void parseInput(Recording& r, Cursor& c, TickInput& camera, Ticks& ticks) {
  const uint64_t tickAt = c.offset();
  InputRecord rec;
  rec.offset = tickAt;
  rec.tick = c.get<int64_t>("the input tick");
  const int64_t after = r.inputs.empty() ? r.header.startTick - 1 : r.inputs.back().tick;
  if (rec.tick <= after)  // the first: at or after the start tick (not "after -1, got -1")
    c.fail(tickAt, (r.inputs.empty() ? "an input tick from the start tick " + std::to_string(r.header.startTick)
                                     : "an input tick after " + std::to_string(after)) +
                       ", got " + std::to_string(rec.tick));
  expectReachable(c, tickAt, rec.tick, ticks, "an input tick");
  expectPromisedBefore(r, c, tickAt, rec.tick, ticks, true, true, false, "the input");
  const uint64_t flagsAt = c.offset();
  const uint8_t flags = c.get<uint8_t>("the input flags");
  if (flags > 1) c.fail(flagsAt, "input flags 0 or 1, got " + std::to_string(flags));
  if (flags & 1) {
    const uint64_t hasAt = c.offset();
    const uint8_t has = c.get<uint8_t>("the camera flag");
    if (has > 1) c.fail(hasAt, "a camera flag 0 or 1, got " + std::to_string(has));
    camera.hasCamera = has == 1;
    camera.camera = c.vec3("the camera position");
  }
  rec.input.hasCamera = camera.hasCamera;
  rec.input.camera = camera.camera;
  const uint64_t countAt = c.offset();
  const uint32_t count = c.get<uint32_t>("the command count");
  constexpr size_t kCommandBytes = 4 + 1 + 24;
  if (count > c.remaining() / kCommandBytes)
    c.fail(countAt, "a command count that fits the INPT chunk, got " + std::to_string(count));
  for (uint32_t i = 0; i < count; ++i) {
    BodyCommand cmd;
    const uint64_t bodyAt = c.offset();
    cmd.body = c.get<int32_t>("a body index");
    if (cmd.body < 0) c.fail(bodyAt, "a body index >= 0, got " + std::to_string(cmd.body));
    const uint64_t kindAt = c.offset();
    const uint8_t kind = c.get<uint8_t>("a command kind");
    if (kind > uint8_t(BodyCommandKind::DragTo))
      c.fail(kindAt,
             "a command kind 0.." + std::to_string(int(BodyCommandKind::DragTo)) + ", got " + std::to_string(kind));
    cmd.kind = BodyCommandKind(kind);
    cmd.value = c.vec3("a command value");
    rec.input.bodies.push_back(cmd);
  }
  c.finished();
  r.inputs.push_back(std::move(rec));
}
}  // namespace

namespace {
/// A state hash as the tools print it: 16 hex digits.
std::string hashText(uint64_t h) {
  char text[17];
  std::snprintf(text, sizeof text, "%016" PRIx64, h);
  return text;
}

/// The magic and the version: the same errors whether the whole file or only its first bytes
/// are at hand (readRecording checks them before reading the rest).
void checkPreamble(std::span<const uint8_t> all, uint64_t fileSize, const std::string& file) {
  if (all.size() < kPreambleBytes || std::memcmp(all.data(), kMagic, sizeof kMagic) != 0) {
    if (all.size() >= sizeof kMagic && std::memcmp(all.data(), kMagic, sizeof kMagic) != 0)
      throw RecordingError(file, 0, "the .sgr magic \\x89SGR\\r\\n\\x1a\\n (not a SimGrass recording)");
    throw RecordingError(file, fileSize, "the 12-byte .sgr preamble (the file ends early)");
  }
  const uint32_t version = loadLE<uint32_t>(all.data() + 8);
  if (version == 1)  // the same layout; its hashes are one XXH3 stream over a state (state_hash.h)
    throw RecordingError(file, 8,
                         "format version " + std::to_string(kFormatVersion) +
                             ", got 1 (recorded before 2026-11-28, when state hashes became hashes of row-group "
                             "digests: record it again with this build)");
  if (version != kFormatVersion)
    throw RecordingError(file, 8,
                         "format version " + std::to_string(kFormatVersion) + ", got " + std::to_string(version));
}

/// A chunk header's type and length, checked before anything is read or allocated by them.
ChunkType checkChunkHeader(uint32_t type, uint32_t length, uint64_t at, const std::string& file) {
  if (!knownType(type))
    throw RecordingError(file, at, "a chunk type HEAD, INPT, CHCK, SNAP or END, got " + typeText(type));
  const ChunkType t = ChunkType(type);
  if (length > maxPayload(t))
    throw RecordingError(file, at + 4,
                         std::string("a ") + chunkTypeName(t) + " payload of at most " + std::to_string(maxPayload(t)) +
                             " bytes, got " + std::to_string(length));
  return t;
}
}  // namespace

Recording parseRecording(std::vector<uint8_t> bytes, const std::string& file) {
  Recording r;
  r.file = file;
  r.bytes = std::move(bytes);
  const std::span<const uint8_t> all(r.bytes);
  checkPreamble(all, all.size(), file);

  uint64_t at = kPreambleBytes;
  bool haveHead = false;
  Ticks ticks;
  TickInput camera;
  auto truncate = [&](uint64_t where, const std::string& expected) {
    r.truncated = true;
    r.truncatedAt = where;
    r.truncatedExpected = expected;
  };
  while (at < all.size()) {
    if (r.end) throw RecordingError(file, at, "the end of the file after the END chunk");
    if (all.size() - at < kChunkHeaderBytes) {
      truncate(at, "an 8-byte chunk header");
      break;
    }
    const uint32_t length = loadLE<uint32_t>(all.data() + at + 4);
    const ChunkType t = checkChunkHeader(loadLE<uint32_t>(all.data() + at), length, at, file);
    const uint64_t total = kChunkHeaderBytes + uint64_t(length) + kChunkTrailerBytes;
    if (all.size() - at < total) {
      truncate(at, std::string("a ") + chunkTypeName(t) + " chunk of " + std::to_string(total) + " bytes, " +
                       std::to_string(all.size() - at) + " left");
      break;
    }
    const uint64_t stored = loadLE<uint64_t>(all.data() + at + kChunkHeaderBytes + length);
    if (XXH3_64bits(all.data() + at, kChunkHeaderBytes + length) != stored)
      throw RecordingError(file, at + kChunkHeaderBytes + length,
                           std::string("the ") + chunkTypeName(t) + " chunk's checksum (the chunk at byte " +
                               std::to_string(at) + " is damaged)");
    if (!haveHead && t != ChunkType::Head) throw RecordingError(file, at, "the HEAD chunk first");
    if (haveHead && t == ChunkType::Head) throw RecordingError(file, at, "one HEAD chunk only");
    Cursor c(r, at + kChunkHeaderBytes, all.subspan(size_t(at + kChunkHeaderBytes), length), chunkTypeName(t));
    switch (t) {
      case ChunkType::Head:
        parseHead(r, c);
        ticks.lastNamed = r.header.startTick;
        haveHead = true;
        break;
      case ChunkType::Input:
        parseInput(r, c, camera, ticks);
        break;
      case ChunkType::Check: {
        Check k;
        k.tick = c.get<int64_t>("the check tick");
        k.hash = c.get<uint64_t>("the check hash");
        // CHCK chunks come exactly every checkEvery ticks: a missing or stray one is damage.
        expectOnGrid(c, at + kChunkHeaderBytes, k.tick, ticks.lastCheck, r.header.startTick, r.header.checkEvery,
                     "CHCK", "checkEvery", "check");
        expectPromisedBefore(r, c, at + kChunkHeaderBytes, k.tick, ticks, false, true, false, "the check");
        expectReachable(c, at + kChunkHeaderBytes, k.tick, ticks, "a check");
        ticks.lastCheck = k.tick;
        r.checks.push_back(k);
        c.finished();
        break;
      }
      case ChunkType::Snapshot: {
        SnapshotInfo s;
        s.tick = c.get<int64_t>("the snapshot tick");
        s.hash = c.get<uint64_t>("the snapshot hash");
        const uint64_t rawAt = c.offset();
        s.rawBytes = c.get<uint64_t>("the snapshot size");
        expectOnGrid(c, at + kChunkHeaderBytes, s.tick, ticks.lastSnapshot, r.header.startTick, r.header.snapshotEvery,
                     "SNAP", "snapshotEvery", "snapshot");
        expectPromisedBefore(r, c, at + kChunkHeaderBytes, s.tick, ticks, true, false, true, "the snapshot");
        expectReachable(c, at + kChunkHeaderBytes, s.tick, ticks, "a snapshot");
        if (s.rawBytes == 0 || s.rawBytes > kMaxSnapshotRawBytes)
          c.fail(rawAt, "a snapshot size between 1 and " + std::to_string(kMaxSnapshotRawBytes) + " bytes, got " +
                            std::to_string(s.rawBytes));
        s.offset = c.offset();
        s.compressedBytes = c.remaining();
        // zstd cannot expand more than this (each block has a 3-byte header and holds at most
        // 128 KiB): a larger size would make snapshotState allocate for a state that is not there.
        const uint64_t canHold = (s.compressedBytes / 3 + 1) * (uint64_t(128) << 10);
        if (s.rawBytes > canHold)
          c.fail(rawAt, "a snapshot size that " + std::to_string(s.compressedBytes) +
                            " compressed bytes can hold (at most " + std::to_string(canHold) + "), got " +
                            std::to_string(s.rawBytes));
        ticks.lastSnapshot = s.tick;
        r.snapshots.push_back(s);
        break;
      }
      case ChunkType::End: {
        EndInfo e;
        e.tick = c.get<int64_t>("the final tick");
        e.hash = c.get<uint64_t>("the final hash");
        const uint64_t faultAt = c.offset();
        const uint8_t faulted = c.get<uint8_t>("the fault flag");
        if (faulted > 1) c.fail(faultAt, "a fault flag 0 or 1, got " + std::to_string(faulted));
        e.faulted = faulted == 1;
        e.message = c.string("the fault message", kMaxShortString);
        c.finished();
        constexpr int64_t kMaxTick = std::numeric_limits<int64_t>::max();
        // An input of tick t is the step from t: a complete recording went past it, a faulted
        // one may have stopped in that very step (the input that made it fault).
        const int64_t afterInputs =
            r.inputs.empty() ? int64_t(0) : std::min(r.inputs.back().tick, kMaxTick - 1) + (e.faulted ? 0 : 1);
        const int64_t covered = std::max({r.header.startTick, ticks.lastCheck, ticks.lastSnapshot, afterInputs});
        // Bounded above too: a recording hashes at least every checkEvery ticks (and snapshots
        // every snapshotEvery), so a final tick at or beyond the next one due would have had it;
        // and no tick lies more than kMaxTickGap after the last one the file names (a replay of
        // a forged final tick would run for ever).
        const int64_t nextDue = std::min(nextCheckTick(r, ticks), nextSnapshotTick(r, ticks));
        // (A faulted END is replayed one step further: its tick must leave room for that step.)
        const int64_t reachable =
            ticks.lastNamed > kMaxTick - 1 - kMaxTickGap ? kMaxTick - 1 : ticks.lastNamed + kMaxTickGap;
        const int64_t lastAllowed = std::min({e.faulted ? nextDue : nextDue - 1, kMaxTick - 1, reachable});
        // No final tick fits when the file names a tick (an input whose step was taken) at or past
        // the next check or snapshot due, which is missing: "a final tick from 31 to 30" said it
        // backwards (an independent pass).
        if (covered > lastAllowed && lastAllowed == nextDue - 1)
          c.fail(at + kChunkHeaderBytes, "the check or snapshot due at tick " + std::to_string(nextDue) +
                                             " before this END (the chunks before it take the recording to tick " +
                                             std::to_string(covered) + " at least)");
        if (e.tick < covered || e.tick > lastAllowed)
          c.fail(at + kChunkHeaderBytes,
                 "a final tick from " + std::to_string(covered) + " to " + std::to_string(lastAllowed) +
                     (lastAllowed == reachable
                          ? " (at most " + std::to_string(kMaxTickGap) + " ticks after the last tick the file names)"
                          : " (before the next check or snapshot, due at tick " + std::to_string(nextDue) + ")") +
                     ", got " + std::to_string(e.tick));
        r.end = e;
        break;
      }
    }
    at += total;
  }
  if (!haveHead) throw RecordingError(file, at, "the HEAD chunk (the file ends early)");
  if (!r.end && !r.truncated) truncate(at, "the END chunk (the recording was not finished)");
  // A snapshot and a check of the same tick hash the same state. A snapshot spliced in from
  // another run (its own hash and checksum intact) drew that run's state in `render` with exit 0,
  // and `replay --verify` reported the mismatch and then "matches" (an independent pass).
  for (size_t k = 0, s = 0; s < r.snapshots.size(); ++s) {
    while (k < r.checks.size() && r.checks[k].tick < r.snapshots[s].tick) ++k;
    if (k < r.checks.size() && r.checks[k].tick == r.snapshots[s].tick && r.checks[k].hash != r.snapshots[s].hash)
      throw RecordingError(file, r.snapshots[s].offset,
                           "a snapshot whose hash is its tick's check hash (" + hashText(r.checks[k].hash) +
                               " at tick " + std::to_string(r.snapshots[s].tick) + "), got " +
                               hashText(r.snapshots[s].hash));
  }
  return r;
}

Recording readRecording(const std::string& path, uint64_t maxBytes) {
  if (maxBytes == 0 || maxBytes > InputLimits::kRecordingBytes) maxBytes = InputLimits::kRecordingBytes;
  InputFile in;
  std::string expected;
  if (!in.open(path, maxBytes, &expected)) throw RecordingError(path, 0, expected);
  // The preamble and the HEAD chunk's header first: a file that is no recording (or whose first
  // chunk is not a HEAD of a sane size) is refused before the rest of it is read.
  std::array<uint8_t, kPreambleBytes + kChunkHeaderBytes> first{};
  const size_t firstBytes = size_t(std::min<uint64_t>(in.size(), first.size()));
  if (!in.readAt(0, std::span<uint8_t>(first.data(), firstBytes), &expected)) throw RecordingError(path, 0, expected);
  checkPreamble(std::span<const uint8_t>(first.data(), firstBytes), in.size(), path);
  if (firstBytes == first.size()) {
    const uint32_t type = loadLE<uint32_t>(first.data() + kPreambleBytes);
    const ChunkType t =
        checkChunkHeader(type, loadLE<uint32_t>(first.data() + kPreambleBytes + 4), kPreambleBytes, path);
    if (t != ChunkType::Head) throw RecordingError(path, kPreambleBytes, "the HEAD chunk first");
  }
  try {
    std::vector<uint8_t> bytes;
    if (!in.readAll(&bytes, &expected)) throw RecordingError(path, 0, expected);
    return parseRecording(std::move(bytes), path);
  } catch (const std::bad_alloc&) {
    // Below kRecordingBytes, but more than this process may allocate (ulimit -v, a small machine).
    throw RecordingError(path, 0, "a recording that fits in memory (" + std::to_string(in.size()) + " bytes)");
  }
}

bool hasRecordingMagic(const std::string& path) {
  InputFile in;
  std::string expected;
  uint8_t magic[sizeof kMagic] = {};
  return in.open(path, InputLimits::kRecordingBytes, &expected) && in.size() >= sizeof magic &&
         in.readAt(0, magic, &expected) && std::memcmp(magic, kMagic, sizeof magic) == 0;
}

int64_t Recording::hashedTicks() const {
  std::vector<int64_t> ticks;
  ticks.reserve(checks.size() + snapshots.size() + 2);
  ticks.push_back(header.startTick);
  for (const Check& c : checks) ticks.push_back(c.tick);
  for (const SnapshotInfo& s : snapshots) ticks.push_back(s.tick);
  if (end && !end->faulted) ticks.push_back(end->tick);
  std::sort(ticks.begin(), ticks.end());
  return int64_t(std::unique(ticks.begin(), ticks.end()) - ticks.begin());
}

int64_t Recording::lastTick() const {
  if (end) return end->tick;
  int64_t t = header.startTick;
  if (!checks.empty()) t = std::max(t, checks.back().tick);
  if (!snapshots.empty()) t = std::max(t, snapshots.back().tick);
  return t;
}

TickInput Recording::inputAt(int64_t tick) const {
  auto it =
      std::upper_bound(inputs.begin(), inputs.end(), tick, [](int64_t t, const InputRecord& r) { return t < r.tick; });
  if (it == inputs.begin()) return {};
  --it;
  if (it->tick == tick) return it->input;
  TickInput carried;  // an earlier tick's camera, no commands
  carried.hasCamera = it->input.hasCamera;
  carried.camera = it->input.camera;
  return carried;
}

const SnapshotInfo* Recording::snapshotAtOrBefore(int64_t tick) const {
  auto it = std::upper_bound(snapshots.begin(), snapshots.end(), tick,
                             [](int64_t t, const SnapshotInfo& s) { return t < s.tick; });
  return it == snapshots.begin() ? nullptr : &*(it - 1);
}

std::vector<uint8_t> Recording::snapshotState(const SnapshotInfo& s, uint64_t maxRawBytes) const {
  // The declared size is compared with what the caller can use (the largest state of the
  // scenario) before a byte is allocated or decompressed: a 96 KB frame of RLE blocks can expand
  // to gigabytes.
  const uint64_t sizeAt = s.offset >= 8 ? s.offset - 8 : s.offset;
  if (s.rawBytes > maxRawBytes)
    throw RecordingError(file, sizeAt,
                         "a snapshot of at most " + std::to_string(maxRawBytes) +
                             " bytes (the largest state this scenario can have), got " + std::to_string(s.rawBytes));
  if (s.offset > bytes.size() || s.compressedBytes > bytes.size() - s.offset)
    throw RecordingError(file, s.offset, "a snapshot frame inside the file");
  const uint8_t* frame = bytes.data() + s.offset;
  const unsigned long long declared = ZSTD_getFrameContentSize(frame, size_t(s.compressedBytes));
  if (declared == ZSTD_CONTENTSIZE_ERROR || declared == ZSTD_CONTENTSIZE_UNKNOWN || declared != s.rawBytes)
    throw RecordingError(file, s.offset, "a zstd frame of " + std::to_string(s.rawBytes) + " bytes");
  // Streaming, into exactly rawBytes of output and with a bounded window: a frame that holds more
  // than it declares (or asks for a huge window) is an error, never a larger allocation.
  std::unique_ptr<ZSTD_DCtx, size_t (*)(ZSTD_DCtx*)> dctx(ZSTD_createDCtx(), ZSTD_freeDCtx);
  if (!dctx) throw std::bad_alloc();
  ZSTD_DCtx_setParameter(dctx.get(), ZSTD_d_windowLogMax, 27);
  std::vector<uint8_t> state(size_t(s.rawBytes));
  ZSTD_inBuffer input{frame, size_t(s.compressedBytes), 0};
  ZSTD_outBuffer output{state.data(), state.size(), 0};
  size_t left = 1;
  while (left != 0) {
    const size_t before = output.pos + input.pos;
    left = ZSTD_decompressStream(dctx.get(), &output, &input);
    if (ZSTD_isError(left))
      throw RecordingError(file, s.offset, std::string("a valid zstd frame (") + ZSTD_getErrorName(left) + ")");
    if (left != 0 && output.pos + input.pos == before)  // no progress: the frame is cut or overlong
      throw RecordingError(file, s.offset, "a valid zstd frame (short)");
  }
  if (output.pos != state.size() || input.pos != input.size)
    throw RecordingError(file, s.offset, "a valid zstd frame (short)");
  return state;
}

}  // namespace sg::sgr
