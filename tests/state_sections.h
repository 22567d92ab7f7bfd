// Finds the sections of a saved state (sim/state/state_format.h) so tests can damage one field
// by its documented position instead of by a hard-coded byte offset; and the state hash written
// out from a saved state's bytes (sim/state/state_hash.h).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <xxhash.h>

#include "sim/state/byte_order.h"

namespace sg::test {

struct StateSection {
  size_t tagAt = 0;      ///< byte offset of the 4-byte tag
  size_t payloadAt = 0;  ///< byte offset of the payload
  uint64_t length = 0;   ///< payload bytes
};

/// The section with this tag (fails the test when the state has none).
inline StateSection findSection(const std::vector<uint8_t>& state, const char* tag) {
  size_t at = 8;  // after the magic
  while (at + 12 <= state.size()) {
    const uint64_t length = loadLE<uint64_t>(state.data() + at + 4);
    if (std::memcmp(state.data() + at, tag, 4) == 0) return {at, at + 12, length};
    at += 12 + size_t(length);
  }
  ADD_FAILURE() << "the state has no section " << tag;
  return {};
}

/// The documented hash of a saved state whose particle rows are `width` wide
/// (sim/state/state_hash.h): the bytes as saved, with each particle array's payload (PART's six
/// arrays, TRMP's one) replaced by the XXH3-64 digests of its groups of 4096 / width whole rows
/// (at least one row), little-endian; then XXH3-64 of the lot.
inline uint64_t documentedStateHash(const std::vector<uint8_t>& saved, size_t scalarBytes, size_t width) {
  const size_t rowsPerGroup = width >= 4096 ? 1 : 4096 / width;
  std::vector<uint8_t> stream;
  size_t at = 8;
  stream.insert(stream.end(), saved.begin(), saved.begin() + 8);  // the magic
  while (at + 12 <= saved.size()) {
    const uint64_t length = loadLE<uint64_t>(saved.data() + at + 4);
    stream.insert(stream.end(), saved.begin() + long(at), saved.begin() + long(at + 12));  // tag, length as saved
    const uint8_t* payload = saved.data() + at + 12;
    if (std::memcmp(saved.data() + at, "PART", 4) == 0 || std::memcmp(saved.data() + at, "TRMP", 4) == 0) {
      const size_t rowBytes = width * scalarBytes, arrays = std::memcmp(saved.data() + at, "PART", 4) == 0 ? 6 : 1;
      const size_t arrayBytes = size_t(length) / arrays, groupBytes = rowsPerGroup * rowBytes;
      for (size_t a = 0; a < arrays; ++a)
        for (size_t g = 0; g * groupBytes < arrayBytes; ++g) {
          const size_t begin = a * arrayBytes + g * groupBytes, n = std::min(groupBytes, arrayBytes - g * groupBytes);
          uint8_t le[8];
          storeLE<uint64_t>(le, XXH3_64bits(payload + begin, n));
          stream.insert(stream.end(), le, le + 8);
        }
    } else {
      stream.insert(stream.end(), payload, payload + length);
    }
    at += 12 + size_t(length);
  }
  EXPECT_EQ(at, saved.size());
  return XXH3_64bits(stream.data(), stream.size());
}

}  // namespace sg::test
