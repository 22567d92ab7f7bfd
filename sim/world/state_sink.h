// Where the canonical state serialisation goes: a byte buffer (save) or a running hash.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <xxhash.h>

namespace sg {

class StateSink {
 public:
  virtual ~StateSink() = default;
  virtual void write(const void* data, size_t bytes) = 0;
};

class ByteSink final : public StateSink {
 public:
  std::vector<uint8_t> bytes;
  void write(const void* data, size_t n) override {
    const auto* p = static_cast<const uint8_t*>(data);
    bytes.insert(bytes.end(), p, p + n);
  }
};

/// xxHash3-64 over everything written, streamed (no copy of the state).
class HashSink final : public StateSink {
 public:
  HashSink() : state_(XXH3_createState()) { XXH3_64bits_reset(state_); }
  ~HashSink() override { XXH3_freeState(state_); }
  HashSink(const HashSink&) = delete;
  HashSink& operator=(const HashSink&) = delete;
  void write(const void* data, size_t n) override { XXH3_64bits_update(state_, data, n); }
  uint64_t digest() const { return XXH3_64bits_digest(state_); }
 private:
  XXH3_state_t* state_;
};

}  // namespace sg
