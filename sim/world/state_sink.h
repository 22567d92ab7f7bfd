// Where the canonical state serialisation goes: a byte buffer (save) or a running hash.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <xxhash.h>
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

/// xxHash3-64 over everything written, streamed (no copy of the state). On x86 it calls the
/// library's dispatching entry point, which picks the widest vector unit at run time: the digest
/// is defined by the XXH3 spec and identical on every path, but AVX2 hashes the thesis meadow's
/// 1.1 MB state in ~25 us instead of ~57 us (the SSE2 default), i.e. ~2.5% of a tick instead of
/// ~6% when recording a CHECK every tick.
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
