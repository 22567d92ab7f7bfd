// Reading an input file without trusting it: the one way every reader in replay/ and viewer/ opens
// a file a user named (scenario, heightmap, input track, recording, mesh, viewer script).
//
// Invariants a caller can rely on:
//  - only regular files are read: a directory, FIFO, socket or device is refused with a clear
//    error, and opening never blocks (O_NONBLOCK, then fstat on the open descriptor, so the check
//    and the read see the same file);
//  - the size is compared with the caller's limit before a single byte is read or allocated, so
//    /dev/zero or a 100 GiB file costs nothing;
//  - a short read (the file shrank, an I/O error) is an error, never a silently truncated input.
// Errors are the "expected ..." half of a one-line message; the caller's error type adds the file
// name and the place (ScenarioError, RecordingError, the viewer's status line).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace sg {

/// The documented input limits (docs/robustness.md lists them; change both together).
struct InputLimits {
  static constexpr uint64_t kScenarioBytes = uint64_t(16) << 20;   ///< scenario JSON
  static constexpr uint64_t kHeightmapBytes = uint64_t(64) << 20;  ///< heightmap PNG
  static constexpr uint64_t kInputTrackBytes = uint64_t(16)
                                               << 20;          ///< input-track JSON (nlohmann peaks at ~25x the text)
  static constexpr uint64_t kMeshBytes = uint64_t(64) << 20;   ///< OBJ mesh
  static constexpr uint64_t kScriptBytes = uint64_t(4) << 20;  ///< viewer script
  static constexpr uint64_t kRecordingBytes = uint64_t(16) << 30;  ///< .sgr recording
};

/// An open, regular, bounded input file. Move-only; closes on destruction.
class InputFile {
 public:
  InputFile() = default;
  InputFile(InputFile&& other) noexcept;
  InputFile& operator=(InputFile&& other) noexcept;
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;
  ~InputFile();

  /// Opens `path` for reading. Returns false with *expected set ("an existing file (not found)",
  /// "a regular file, not a FIFO", "a file of at most 16777216 bytes, got 17000000") when it is
  /// missing, unreadable, not a regular file or larger than `maxBytes`.
  bool open(const std::string& path, uint64_t maxBytes, std::string* expected);

  uint64_t size() const { return size_; }
  bool isOpen() const { return fd_ >= 0; }

  /// Reads exactly out.size() bytes at `offset`. Returns false with *expected set when the file
  /// ends early or the read fails.
  bool readAt(uint64_t offset, std::span<uint8_t> out, std::string* expected) const;

  /// Reads the whole file (size() bytes).
  bool readAll(std::vector<uint8_t>* out, std::string* expected) const;

 private:
  int fd_ = -1;
  uint64_t size_ = 0;
};

/// Opens and reads a whole input file of at most `maxBytes` bytes (see InputFile::open).
bool readInputFile(const std::string& path, uint64_t maxBytes, std::vector<uint8_t>* out, std::string* expected);
bool readInputFile(const std::string& path, uint64_t maxBytes, std::string* out, std::string* expected);

/// True when `a` and `b` name the same existing file (same device and inode), so that a command
/// can refuse to write an output over one of its own inputs (hard links and `./x` included).
bool sameFile(const std::string& a, const std::string& b);

}  // namespace sg
