// Reads and validates a `.sgr` recording. Every chunk is checked (length bound, checksum, field
// ranges, tick order) before anything is allocated from its contents; problems are reported as
// RecordingError naming the byte offset. A file that ends inside a chunk (a recorder killed
// mid-write) is accepted up to its last complete chunk and marked `truncated`.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "replay/format/sgr_format.h"

namespace sg::sgr {

struct Recording {
  std::string file;            ///< for messages
  std::vector<uint8_t> bytes;  ///< the whole file (snapshots decompress from here)
  Header header;
  std::vector<InputRecord> inputs;      ///< sorted by tick; camera already carried forward
  std::vector<Check> checks;            ///< sorted by tick
  std::vector<SnapshotInfo> snapshots;  ///< sorted by tick
  std::optional<EndInfo> end;
  /// The file ended inside a chunk (or before END): what was there and where it stopped.
  bool truncated = false;
  uint64_t truncatedAt = 0;
  std::string truncatedExpected;

  /// The ticks whose state the recording names by a hash: the start tick (the header's initial
  /// hash), every CHCK, SNAP and a clean END, each tick counted once. What `replay --info`,
  /// `replay --verify` and the viewer's playback panel all count as "hashed ticks".
  int64_t hashedTicks() const;
  /// Last tick the recording covers: END's tick, else the last tick any chunk names.
  int64_t lastTick() const;
  /// The input for the step from `tick` to `tick + 1` (camera carried, commands of that tick).
  TickInput inputAt(int64_t tick) const;
  /// Latest snapshot at or before `tick`, or nullptr.
  const SnapshotInfo* snapshotAtOrBefore(int64_t tick) const;
  /// Decompresses a snapshot. Throws RecordingError (offset of the frame) when it is damaged, and
  /// (offset of its size field) before anything is allocated when it declares more than
  /// `maxRawBytes` (the Player passes the largest state its scenario can have).
  std::vector<uint8_t> snapshotState(const SnapshotInfo& snapshot, uint64_t maxRawBytes = kMaxSnapshotRawBytes) const;
};

/// Parses recording bytes. `file` names them in errors.
Recording parseRecording(std::vector<uint8_t> bytes, const std::string& file);
/// Reads and parses a file through InputFile (regular files only, never blocking): the preamble and
/// the first chunk's header are checked before the rest is read. Refuses files larger than
/// `maxBytes` (0 or more than InputLimits::kRecordingBytes: that limit).
Recording readRecording(const std::string& path, uint64_t maxBytes = 0);

/// Whether `path` is a regular file that starts with the recording magic (read through InputFile:
/// a FIFO, a directory or a device is not a recording, and probing it never blocks). How the
/// viewer and `simgrass render` tell a recording from a scenario.
bool hasRecordingMagic(const std::string& path);

}  // namespace sg::sgr
