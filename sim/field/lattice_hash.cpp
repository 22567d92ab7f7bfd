#include "sim/field/lattice_hash.h"

#include <xxhash.h>

namespace sg {
uint64_t latticeHash(int64_t i, int64_t j, uint64_t seed, LatticeSalt salt) {
  // Explicit little-endian packing, so the stream is the same on any host byte order.
  unsigned char key[20];
  const uint64_t ui = uint64_t(i), uj = uint64_t(j);
  const uint32_t us = uint32_t(salt);
  for (int b = 0; b < 8; ++b) key[b] = static_cast<unsigned char>(ui >> (8 * b));
  for (int b = 0; b < 8; ++b) key[8 + b] = static_cast<unsigned char>(uj >> (8 * b));
  for (int b = 0; b < 4; ++b) key[16 + b] = static_cast<unsigned char>(us >> (8 * b));
  return XXH3_64bits_withSeed(key, sizeof key, seed);
}
}  // namespace sg
