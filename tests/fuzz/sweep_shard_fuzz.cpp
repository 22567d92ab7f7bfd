// libFuzzer target for sweep shards (docs/scale-out.md): any bytes, given the checksum they need
// (the harness appends the xxHash3 of the input, so the fuzzer reaches the lengths, the JSON
// header, the zstd payload and the reference payload behind them, not only the checksum test),
// must parse or throw std::runtime_error: never a crash, a hang, another exception or an
// allocation beyond the payload bound.
#include <xxhash.h>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "replay/cli/sweep_shard_format.h"
#include "sim/state/byte_order.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  bytes.resize(size + 8);
  sg::storeLE<uint64_t>(bytes.data() + size, XXH3_64bits(data, size));
  try {
    const sg::sweep::Shard s = sg::sweep::parseShard(bytes, "fuzz.sgs", uint64_t(64) << 20, true);
    std::unique_ptr<sg::sgr::Recording> recording;
    std::vector<sg::Observation> observed;
    if (!s.payload.empty()) sg::sweep::readReferencePayload(s.payload, "fuzz.sgs", &recording, &observed);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
