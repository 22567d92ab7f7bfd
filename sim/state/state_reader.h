// Reads a saved state (state_format.h) section by section. Every read is bounds-checked before
// it happens and a failure throws StateError with the byte offset and what was expected.
#pragma once

#include <cstdint>
#include <cstring>
#include <span>
#include <string>

#include "sim/state/byte_order.h"
#include "sim/state/state_format.h"
#include "sim/world/sim_world.h"

namespace sg::state {

/// A cursor over one section's payload (or the whole state), reporting offsets in the whole state.
class Cursor {
 public:
  Cursor(std::span<const uint8_t> bytes, uint64_t offset, uint64_t end) : bytes_(bytes), at_(offset), end_(end) {}

  uint64_t offset() const { return at_; }
  uint64_t remaining() const { return end_ - at_; }

  /// Throws unless `count` more bytes are there; `what` says what they should hold.
  void need(uint64_t count, const std::string& what) const {
    if (remaining() < count)
      throw StateError(end_, what + " (" + std::to_string(count) + " bytes from byte " + std::to_string(at_) +
                                 ", the section ends early)");
  }
  template <class T>
  T read(const std::string& what) {
    need(sizeof(T), what);
    const T v = loadLE<T>(bytes_.data() + at_);
    at_ += sizeof(T);
    return v;
  }
  /// Reads a value that must equal `expected`.
  template <class T>
  void expect(T expected, const std::string& what) {
    const uint64_t at = at_;
    if (read<T>(what) != expected) throw StateError(at, what);
  }
  /// n values into out (little-endian on every host).
  template <class T>
  void readArray(T* out, uint64_t n, const std::string& what) {
    need(n * sizeof(T), what);
    const uint8_t* p = bytes_.data() + at_;
    if constexpr (kHostIsLittleEndian) {
      if (n) std::memcpy(out, p, size_t(n) * sizeof(T));
    } else {
      for (uint64_t i = 0; i < n; ++i) out[i] = loadLE<T>(p + i * sizeof(T));
    }
    at_ += n * sizeof(T);
  }
  /// Throws unless the section's payload was read to its end.
  void expectEnd(const std::string& section) const {
    if (at_ != end_)
      throw StateError(at_, "the end of section '" + section + "' (" + std::to_string(end_ - at_) + " bytes left)");
  }

 private:
  std::span<const uint8_t> bytes_;
  uint64_t at_, end_;
};

/// Walks the sections of a state in their fixed order.
class StateReader {
 public:
  explicit StateReader(std::span<const uint8_t> bytes) : bytes_(bytes) {
    if (bytes.size() < sizeof kMagic)
      throw StateError(bytes.size(), "the 8-byte state magic 'SGSTATE2' (the data ends early)");
    if (std::memcmp(bytes.data(), "SGSTATE", 7) == 0 && bytes[7] != uint8_t(kMagic[7]))
      throw StateError(7, std::string("state format version 2 ('SGSTATE2'), got a version '") + char(bytes[7]) +
                              "' state (made by another release: re-record it)");
    if (std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) throw StateError(0, "the state magic 'SGSTATE2'");
    at_ = sizeof kMagic;
  }

  /// The next section, which must be `section`; `payloadBytes` (when not -1) is its exact size.
  Cursor next(Section section, int64_t payloadBytes = -1) {
    const char* tag = kSectionTags[int(section)];
    if (bytes_.size() - at_ < kSectionHeaderBytes)
      throw StateError(bytes_.size(), std::string("section '") + tag + "' (the data ends early)");
    if (std::memcmp(bytes_.data() + at_, tag, 4) != 0)
      throw StateError(at_, std::string("section '") + tag + "', got '" + printable(bytes_.data() + at_) + "'");
    const uint64_t length = loadLE<uint64_t>(bytes_.data() + at_ + 4);
    const uint64_t start = at_ + kSectionHeaderBytes;
    if (length > bytes_.size() - start)
      throw StateError(at_ + 4, std::string("a length for section '") + tag + "' within the data (" +
                                    std::to_string(bytes_.size() - start) + " bytes left), got " +
                                    std::to_string(length));
    if (payloadBytes >= 0 && length != uint64_t(payloadBytes))
      throw StateError(at_ + 4, std::string("section '") + tag + "' of " + std::to_string(payloadBytes) +
                                    " bytes, got " + std::to_string(length));
    at_ = start + length;
    return Cursor(bytes_, start, at_);
  }
  /// Throws unless every byte was read.
  void expectEnd() const {
    if (at_ != bytes_.size())
      throw StateError(at_, "the end of the state (" + std::to_string(bytes_.size() - at_) + " more bytes)");
  }

 private:
  static std::string printable(const uint8_t* tag) {
    std::string s;
    for (int i = 0; i < 4; ++i) s += (tag[i] >= 0x20 && tag[i] < 0x7f) ? char(tag[i]) : '?';
    return s;
  }
  std::span<const uint8_t> bytes_;
  uint64_t at_ = 0;
};

}  // namespace sg::state
