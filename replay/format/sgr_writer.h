// Writes a `.sgr` recording as a stream: every chunk is complete in the kernel's page cache when
// flush() returns, so a recorder killed by SIGKILL leaves a file that reads up to its last chunk.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "replay/format/sgr_format.h"

namespace sg::sgr {

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
  /// "path: why" when the file cannot be written.
  Writer(const std::string& path, const Header& header);
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  /// Queues the input of tick `tick` (the step from tick to tick + 1); writes an INPT chunk only
  /// when it differs from the previous tick's camera with no commands.
  void input(int64_t tick, const TickInput& input);
  void check(const Check& check);
  void snapshot(int64_t tick, uint64_t hash, std::span<const uint8_t> state);
  /// Writes END and closes the file (fsync'd). Further calls are errors.
  void end(const EndInfo& end);
  /// Hands everything queued to the kernel (one write(2)).
  void flush();

  uint64_t bytesWritten() const { return written_; }
  const std::string& path() const { return path_; }
  int zstdLevel = 3;

 private:
  void append(ChunkType type, std::span<const uint8_t> payload);
  std::string path_;
  int fd_ = -1;
  std::vector<uint8_t> pending_;
  uint64_t written_ = 0;
  TickInput previous_;  ///< carried camera, for the delta
};

}  // namespace sg::sgr
