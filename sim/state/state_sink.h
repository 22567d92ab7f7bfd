// Where the canonical state serialisation goes: a byte buffer (save) or a running hash. Every
// multi-byte value goes out little-endian (byte_order.h), whatever the host.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <xxhash.h>

#include "sim/state/byte_order.h"
#if defined(__x86_64__)
// The package's runtime AVX2/AVX-512 selection (same digests). x86-64 only: the dispatcher lives
// in libxxhash's x86-64 build, and 32-bit x86 builds (i686) link no such library.
#include <xxh_x86dispatch.h>
#define SG_XXH3_UPDATE XXH3_64bits_update_dispatch
#else
#define SG_XXH3_UPDATE XXH3_64bits_update
#endif

namespace sg {

class StateSink {
 public:
  virtual ~StateSink() = default;
  /// Raw bytes, in the order given.
  virtual void write(const void* data, size_t bytes) = 0;

  /// One integer or float/double, little-endian.
  template <class T>
  void put(T v) {
    uint8_t bytes[sizeof(T)];
    storeLE(bytes, v);
    write(bytes, sizeof bytes);
  }
  /// n values, little-endian: one call on little-endian hosts, converted in 4 KiB blocks elsewhere.
  template <class T>
  void putArray(const T* values, size_t n) {
    if constexpr (kHostIsLittleEndian) {
      write(values, n * sizeof(T));
    } else {
      std::array<uint8_t, 4096> block;
      constexpr size_t perBlock = block.size() / sizeof(T);
      for (size_t i = 0; i < n; i += perBlock) {
        const size_t m = n - i < perBlock ? n - i : perBlock;
        for (size_t k = 0; k < m; ++k) storeLE(block.data() + k * sizeof(T), values[i + k]);
        write(block.data(), m * sizeof(T));
      }
    }
  }
};

class ByteSink final : public StateSink {
 public:
  std::vector<uint8_t> bytes;
  void write(const void* data, size_t n) override {
    const auto* p = static_cast<const uint8_t*>(data);
    bytes.insert(bytes.end(), p, p + n);
  }
};

/// Counts the bytes written (sections record their payload length before the payload).
class CountingSink final : public StateSink {
 public:
  uint64_t bytes = 0;
  void write(const void*, size_t n) override { bytes += n; }
};

/// xxHash3-64 over everything written, streamed (no copy of the state). On x86-64 it calls the
/// library's dispatching entry point, which picks the widest vector unit at run time: the digest
/// is defined by the XXH3 spec and identical on every path, but AVX2 hashes the thesis meadow's
/// 1.1 MB state in ~25 us instead of ~57 us (the SSE2 default).
class HashSink final : public StateSink {
 public:
  HashSink() : state_(XXH3_createState()) { XXH3_64bits_reset(state_); }
  ~HashSink() override { XXH3_freeState(state_); }
  HashSink(const HashSink&) = delete;
  HashSink& operator=(const HashSink&) = delete;
  void write(const void* data, size_t n) override { SG_XXH3_UPDATE(state_, data, n); }
  uint64_t digest() const { return XXH3_64bits_digest(state_); }

 private:
  XXH3_state_t* state_;
};

}  // namespace sg
