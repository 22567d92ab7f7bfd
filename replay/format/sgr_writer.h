// Writes a `.sgr` recording as a stream: every chunk is complete in the kernel's page cache when
// flush() returns, so a recorder killed by SIGKILL leaves a file that reads up to its last chunk.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "replay/format/sgr_format.h"

namespace sg::sgr {

/// Why the reader would refuse a recording with this header ("the scenario text of at most ...
/// bytes, got ..."), or empty when it fits the limits in sgr_format.h.
std::string headerProblem(const Header& header);
/// Why the reader would refuse the INPT chunk of this tick's input, or empty.
std::string inputProblem(const TickInput& input);

/// Encodes chunk payloads (shared by the writer, the tests and the damaged-file corpus).
std::vector<uint8_t> encodeHead(const Header& header);
std::vector<uint8_t> encodeInput(int64_t tick, const TickInput& input, const TickInput& previous);
std::vector<uint8_t> encodeCheck(const Check& check);
/// Compresses `state` with zstd at `level`.
std::vector<uint8_t> encodeSnapshot(int64_t tick, uint64_t hash, std::span<const uint8_t> state, int level);
std::vector<uint8_t> encodeEnd(const EndInfo& end);
/// type | length | payload | XXH3-64 checksum.
std::vector<uint8_t> frameChunk(ChunkType type, std::span<const uint8_t> payload);

class Writer {
 public:
  /// Creates (truncates) `path` and writes the preamble and HEAD. Throws std::runtime_error with
  /// "path: why" when the file cannot be written or the header does not fit the format's limits
  /// (checked before the file is touched).
  Writer(const std::string& path, const Header& header);
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  /// Queues the input of tick `tick` (the step from tick to tick + 1); writes an INPT chunk only
  /// when it differs from the previous tick's camera with no commands. Throws std::runtime_error
  /// (nothing queued) when the input is larger than an INPT chunk may be.
  /// Returns true when it wrote (queued) an INPT chunk.
  bool input(int64_t tick, const TickInput& input);
  void check(const Check& check);
  void snapshot(int64_t tick, uint64_t hash, std::span<const uint8_t> state);
  /// Writes END and closes the file (fsync'd). Further calls are errors.
  void end(const EndInfo& end);
  /// Hands everything queued to the kernel (one write(2)).
  void flush();

  uint64_t bytesWritten() const { return written_; }
  const std::string& path() const { return path_; }
  int zstdLevel = 3;
  /// The largest file this writer produces: the reader's limit (InputLimits::kRecordingBytes), so
  /// that no recording grows into one that replay refuses at byte 0. A chunk that would cross it
  /// is refused (std::runtime_error); the file so far stays readable. Lowered by the tests.
  uint64_t maxBytes;

 private:
  void append(ChunkType type, std::span<const uint8_t> payload);
  std::string path_;
  int fd_ = -1;
  std::vector<uint8_t> pending_;
  uint64_t written_ = 0;
  bool failed_ = false;  ///< a write failed: nothing more is written
  TickInput previous_;   ///< carried camera, for the delta
};

}  // namespace sg::sgr
