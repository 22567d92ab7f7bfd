#include "replay/format/sgr_reader.h"
#include "sim/state/byte_order.h"

#include <xxhash.h>
#include <zstd.h>
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

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
      return 16;
    case ChunkType::Snapshot:
      return kMaxSnapshotPayload;
    case ChunkType::End:
      return 8 + 8 + 1 + 4 + 4096;
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

void parseHead(Recording& r, Cursor& c) {
  Header& h = r.header;
  const uint64_t scalarAt = c.offset();
  const uint8_t scalar = c.get<uint8_t>("the scalar type");
  if (scalar > uint8_t(ScalarKind::Double)) c.fail(scalarAt, "a scalar type 0..3, got " + std::to_string(scalar));
  h.scalar = ScalarKind(scalar);
  c.get<uint8_t>("reserved");
  c.get<uint16_t>("reserved");
  h.checkEvery = c.get<uint32_t>("the check interval");
  h.snapshotEvery = c.get<uint32_t>("the snapshot interval");
  h.scenarioHash = c.get<uint64_t>("the scenario hash");
  h.initialStateHash = c.get<uint64_t>("the initial state hash");
  const uint64_t startAt = c.offset();
  h.startTick = c.get<int64_t>("the start tick");
  if (h.startTick < 0) c.fail(startAt, "a non-negative start tick");
  h.variant = c.string("the variant settings", 4096);
  h.scenarioSource = c.string("the scenario file name", 4096);
  const uint64_t textAt = c.offset();
  h.scenarioText = c.string("the scenario text", kMaxHeadPayload);
  if (XXH3_64bits(h.scenarioText.data(), h.scenarioText.size()) != h.scenarioHash)
    c.fail(textAt, "scenario text matching its hash");
  const uint64_t countAt = c.offset();
  const uint32_t files = c.get<uint32_t>("the embedded file count");
  if (files > 16) c.fail(countAt, "at most 16 embedded files, got " + std::to_string(files));
  for (uint32_t f = 0; f < files; ++f) {
    EmbeddedFile e;
    e.name = c.string("an embedded file name", 4096);
    e.bytes = c.bytes("an embedded file");
    h.files.push_back(std::move(e));
  }
  h.buildId = c.string("the build id", 4096);
  c.finished();
}

void parseInput(Recording& r, Cursor& c, TickInput& camera) {
  const uint64_t tickAt = c.offset();
  InputRecord rec;
  rec.offset = tickAt;
  rec.tick = c.get<int64_t>("the input tick");
  const int64_t after = r.inputs.empty() ? r.header.startTick - 1 : r.inputs.back().tick;
  if (rec.tick <= after)
    c.fail(tickAt, "an input tick after " + std::to_string(after) + ", got " + std::to_string(rec.tick));
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
    if (kind > uint8_t(BodyCommandKind::MowerOff))
      c.fail(kindAt,
             "a command kind 0.." + std::to_string(int(BodyCommandKind::MowerOff)) + ", got " + std::to_string(kind));
    cmd.kind = BodyCommandKind(kind);
    cmd.value = c.vec3("a command value");
    rec.input.bodies.push_back(cmd);
  }
  c.finished();
  r.inputs.push_back(std::move(rec));
}
}  // namespace

Recording parseRecording(std::vector<uint8_t> bytes, const std::string& file) {
  Recording r;
  r.file = file;
  r.bytes = std::move(bytes);
  const std::span<const uint8_t> all(r.bytes);
  if (all.size() < kPreambleBytes || std::memcmp(all.data(), kMagic, sizeof kMagic) != 0) {
    if (all.size() >= sizeof kMagic && std::memcmp(all.data(), kMagic, sizeof kMagic) != 0)
      throw RecordingError(file, 0, "the .sgr magic \\x89SGR\\r\\n\\x1a\\n (not a SimGrass recording)");
    throw RecordingError(file, all.size(), "the 12-byte .sgr preamble (the file ends early)");
  }
  const uint32_t version = loadLE<uint32_t>(all.data() + 8);
  if (version != kFormatVersion)
    throw RecordingError(file, 8,
                         "format version " + std::to_string(kFormatVersion) + ", got " + std::to_string(version));

  uint64_t at = kPreambleBytes;
  bool haveHead = false;
  int64_t lastCheck = -1, lastSnapshot = -1;
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
    const uint32_t type = loadLE<uint32_t>(all.data() + at);
    const uint32_t length = loadLE<uint32_t>(all.data() + at + 4);
    if (!knownType(type))
      throw RecordingError(file, at, "a chunk type HEAD, INPT, CHCK, SNAP or END, got " + typeText(type));
    const ChunkType t = ChunkType(type);
    if (length > maxPayload(t))
      throw RecordingError(file, at + 4,
                           std::string("a ") + chunkTypeName(t) + " payload of at most " +
                               std::to_string(maxPayload(t)) + " bytes, got " + std::to_string(length));
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
        haveHead = true;
        break;
      case ChunkType::Input:
        parseInput(r, c, camera);
        break;
      case ChunkType::Check: {
        Check k;
        k.tick = c.get<int64_t>("the check tick");
        k.hash = c.get<uint64_t>("the check hash");
        // CHCK chunks come exactly every checkEvery ticks: a missing or stray one is damage.
        expectOnGrid(c, at + kChunkHeaderBytes, k.tick, lastCheck, r.header.startTick, r.header.checkEvery, "CHCK",
                     "checkEvery", "check");
        lastCheck = k.tick;
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
        expectOnGrid(c, at + kChunkHeaderBytes, s.tick, lastSnapshot, r.header.startTick, r.header.snapshotEvery,
                     "SNAP", "snapshotEvery", "snapshot");
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
        lastSnapshot = s.tick;
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
        e.message = c.string("the fault message", 4096);
        c.finished();
        constexpr int64_t kMaxTick = std::numeric_limits<int64_t>::max();
        const int64_t covered =
            std::max({r.header.startTick, lastCheck, lastSnapshot,
                      r.inputs.empty() ? int64_t(0) : std::min(r.inputs.back().tick, kMaxTick - 1) + 1});
        // Bounded above too: a recording hashes at least every checkEvery ticks, so a final tick
        // beyond the next check would have had one (and would make a replay run for ever).
        const int64_t nextCheck = r.header.checkEvery ? nextOnGrid(lastCheck, r.header.startTick, r.header.checkEvery)
                                                      : std::numeric_limits<int64_t>::max();
        // (A faulted END is replayed one step further: its tick must leave room for that step.)
        const int64_t lastAllowed = std::min(e.faulted ? nextCheck : nextCheck - 1, kMaxTick - 1);
        if (e.tick < covered || e.tick > lastAllowed)
          c.fail(at + kChunkHeaderBytes, "a final tick from " + std::to_string(covered) +
                                             " to before the next check at " + std::to_string(nextCheck) + ", got " +
                                             std::to_string(e.tick));
        r.end = e;
        break;
      }
    }
    at += total;
  }
  if (!haveHead) throw RecordingError(file, at, "the HEAD chunk (the file ends early)");
  if (!r.end && !r.truncated) truncate(at, "the END chunk (the recording was not finished)");
  return r;
}

Recording readRecording(const std::string& path, uint64_t maxBytes) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw RecordingError(path, 0, "an existing file (not found)");
  if (std::filesystem::is_directory(path, ec)) throw RecordingError(path, 0, "a file, not a directory");
  const uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) throw RecordingError(path, 0, "a readable file (" + ec.message() + ")");
  if (maxBytes == 0) maxBytes = uint64_t(1) << 34;
  if (size > maxBytes) throw RecordingError(path, 0, "a recording of at most " + std::to_string(maxBytes) + " bytes");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw RecordingError(path, 0, "a readable file");
  std::vector<uint8_t> bytes(size);
  in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size));
  if (uint64_t(in.gcount()) != size)
    throw RecordingError(path, uint64_t(in.gcount()), "the rest of the file (read failed)");
  return parseRecording(std::move(bytes), path);
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

std::vector<uint8_t> Recording::snapshotState(const SnapshotInfo& s) const {
  const uint8_t* frame = bytes.data() + s.offset;
  const unsigned long long declared = ZSTD_getFrameContentSize(frame, size_t(s.compressedBytes));
  if (declared == ZSTD_CONTENTSIZE_ERROR || declared == ZSTD_CONTENTSIZE_UNKNOWN || declared != s.rawBytes)
    throw RecordingError(file, s.offset, "a zstd frame of " + std::to_string(s.rawBytes) + " bytes");
  std::vector<uint8_t> state(size_t(s.rawBytes));
  const size_t n = ZSTD_decompress(state.data(), state.size(), frame, size_t(s.compressedBytes));
  if (ZSTD_isError(n) || n != state.size())
    throw RecordingError(
        file, s.offset, std::string("a valid zstd frame (") + (ZSTD_isError(n) ? ZSTD_getErrorName(n) : "short") + ")");
  return state;
}

}  // namespace sg::sgr
