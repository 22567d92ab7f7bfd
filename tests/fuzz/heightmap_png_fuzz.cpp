// libFuzzer target for heightmap PNGs (decodeHeightmapPng, libspng): any bytes give a Heightmap
// of width*height samples within 2..16384 a side, or an error of one line; never a crash, a hang
// or a huge allocation. Each input is decoded twice: as it is, and with every chunk's CRC
// recomputed, because a random mutation almost never keeps a CRC right and the fuzzer would
// otherwise meet only the CRC check.
#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "sim/terrain/heightmap.h"

namespace {

void decode(const std::vector<uint8_t>& bytes) {
  sg::Heightmap hm;
  std::string error;
  if (sg::decodeHeightmapPng(bytes, &hm, &error)) {
    if (hm.width < 2 || hm.height < 2 || hm.width > 16384 || hm.height > 16384 ||
        hm.samples.size() != size_t(hm.width) * size_t(hm.height))
      std::abort();
  } else if (error.empty() || error.find('\n') != std::string::npos) {
    std::abort();
  }
}

uint32_t load32(const std::vector<uint8_t>& b, size_t at) {
  return uint32_t(b[at]) << 24 | uint32_t(b[at + 1]) << 16 | uint32_t(b[at + 2]) << 8 | b[at + 3];
}

/// Recomputes every complete chunk's CRC; false when nothing changed.
bool repairCrcs(std::vector<uint8_t>& b) {
  bool changed = false;
  for (size_t at = 8; b.size() >= at + 12;) {
    const uint32_t length = load32(b, at);
    if (length > b.size() - at - 12) break;
    const uint32_t crc = uint32_t(crc32(0, b.data() + at + 4, uInt(length) + 4));
    const size_t c = at + 8 + length;
    if (load32(b, c) != crc) {
      for (int k = 0; k < 4; ++k) b[c + size_t(k)] = uint8_t(crc >> (24 - 8 * k));
      changed = true;
    }
    at = c + 4;
  }
  return changed;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  decode(bytes);
  if (repairCrcs(bytes)) decode(bytes);
  return 0;
}
