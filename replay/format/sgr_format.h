// The `.sgr` recording format, version 2 (docs/replay-format.md is the normative description).
// Version 2 (2026-11-28) has version 1's layout; its state hashes (HEAD's initial hash, CHCK, SNAP,
// END) are of row-group digests (sim/state/state_hash.h), and a version 1 file is refused with that
// reason.
//
// A recording is an 8-byte magic and a u32 format version, then a stream of chunks:
//   u32 type (four ASCII letters) | u32 payload length | payload | u64 XXH3-64 of type, length
//   and payload.
// All integers are little-endian. The first chunk is HEAD; then, tick by tick, INPT (only for
// ticks whose input differs from "same camera, no commands"), CHCK every checkEvery ticks, SNAP
// every snapshotEvery ticks; END closes a complete recording. Each tick's chunks reach the kernel
// before the next tick starts, so a recording killed mid-way ends in at most one partial chunk.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/math/scalar.h"
#include "sim/world/tick_input.h"

namespace sg::sgr {

inline constexpr uint8_t kMagic[8] = {0x89, 'S', 'G', 'R', '\r', '\n', 0x1a, '\n'};
inline constexpr uint32_t kFormatVersion = 2;
inline constexpr size_t kPreambleBytes = 12;     ///< magic + version
inline constexpr size_t kChunkHeaderBytes = 8;   ///< type + length
inline constexpr size_t kChunkTrailerBytes = 8;  ///< checksum

constexpr uint32_t fourCC(char a, char b, char c, char d) {
  return uint32_t(uint8_t(a)) | uint32_t(uint8_t(b)) << 8 | uint32_t(uint8_t(c)) << 16 | uint32_t(uint8_t(d)) << 24;
}
enum class ChunkType : uint32_t {
  Head = fourCC('H', 'E', 'A', 'D'),
  Input = fourCC('I', 'N', 'P', 'T'),
  Check = fourCC('C', 'H', 'C', 'K'),
  Snapshot = fourCC('S', 'N', 'A', 'P'),
  End = fourCC('E', 'N', 'D', ' '),
};
const char* chunkTypeName(ChunkType type);

/// Limits shared by the writer and the reader (docs/replay-format.md, "Limits a reader
/// enforces"): the writer refuses, before writing, anything the reader would refuse, so a
/// recording that `simgrass record` finishes always replays.
///
/// Largest payload per chunk type (a bit flip in a length cannot make the reader allocate more;
/// a SNAP holds at most the compressed state of a 4096 x 4096 meadow in double).
inline constexpr uint64_t kMaxHeadPayload = uint64_t(256) << 20;
inline constexpr uint64_t kMaxInputPayload = uint64_t(1) << 20;
inline constexpr uint64_t kMaxCheckPayload = 16;
inline constexpr uint64_t kMaxSnapshotPayload = uint64_t(1) << 31;
inline constexpr uint64_t kMaxSnapshotRawBytes = uint64_t(1) << 32;
/// Short strings: the variant, the scenario file name, embedded file names, the build id and
/// END's fault message (which the writer shortens to fit).
inline constexpr uint64_t kMaxShortString = 4096;
inline constexpr uint64_t kMaxEndPayload = 8 + 8 + 1 + 4 + kMaxShortString;
inline constexpr uint32_t kMaxEmbeddedFiles = 16;
/// Most ticks between two ticks the file itself names (tick 0, the start tick, every INPT, CHCK
/// and SNAP tick, the END tick): a forged tick cannot make a replay run for ever, since the ticks
/// a file can claim grow with its size, at most 65536 ticks per chunk (4.5 minutes at 240 Hz; a
/// recording with a hash or a snapshot at least that often, as by default, is never near it).
inline constexpr int64_t kMaxTickGap = int64_t(1) << 16;

/// Bytes of an INPT payload for `input` (the writer checks it against kMaxInputPayload).
inline constexpr uint64_t inputPayloadBytes(size_t commands, bool cameraChanged) {
  return 8 + 1 + (cameraChanged ? 1 + 24 : 0) + 4 + uint64_t(commands) * (4 + 1 + 24);
}

/// A file the scenario named (the heightmap), embedded so that the recording is self-contained.
struct EmbeddedFile {
  std::string name;  ///< as written in the scenario
  std::vector<uint8_t> bytes;
};

struct Header {
  ScalarKind scalar = ScalarKind::Fx32;
  uint32_t checkEvery = 1;        ///< ticks between CHCK chunks (0: none)
  uint32_t snapshotEvery = 300;   ///< ticks between SNAP chunks (0: none)
  uint64_t scenarioHash = 0;      ///< XXH3-64 of scenarioText
  uint64_t initialStateHash = 0;  ///< state hash at startTick, before any input
  int64_t startTick = 0;
  std::string variant;         ///< resolved settings, "scalar=fx32 interp=1 ..." (replay/variant.h)
  std::string scenarioSource;  ///< the scenario file name when it was recorded
  std::string scenarioText;    ///< the scenario JSON, verbatim
  std::vector<EmbeddedFile> files;
  std::string buildId;  ///< "simgrass 0.4.0 gcc 12.2 Release" (informational)
};

struct Check {
  int64_t tick = 0;  ///< state after this many ticks
  uint64_t hash = 0;
};

struct SnapshotInfo {
  int64_t tick = 0;
  uint64_t hash = 0;      ///< stateHash() of the state it holds
  uint64_t rawBytes = 0;  ///< size of the state once decompressed
  uint64_t offset = 0;    ///< file offset of the zstd frame
  uint64_t compressedBytes = 0;
};

struct EndInfo {
  int64_t tick = 0;
  uint64_t hash = 0;
  bool faulted = false;  ///< the simulation stopped with an error at `tick`
  std::string message;   ///< the error, when faulted
};

/// One tick's recorded input (the camera is carried forward from earlier ticks).
struct InputRecord {
  int64_t tick = 0;
  uint64_t offset = 0;  ///< file offset of its INPT payload (for messages)
  TickInput input;
};

/// A damaged or unreadable recording: the file, the byte offset and what was expected there.
class RecordingError : public std::runtime_error {
 public:
  RecordingError(const std::string& file, uint64_t offset, const std::string& expected);
  const std::string& file() const { return file_; }
  uint64_t offset() const { return offset_; }
  const std::string& expected() const { return expected_; }

 private:
  std::string file_;
  uint64_t offset_;
  std::string expected_;
};

}  // namespace sg::sgr
