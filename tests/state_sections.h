// Finds the sections of a saved state (sim/state/state_format.h) so tests can damage one field
// by its documented position instead of by a hard-coded byte offset.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

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

}  // namespace sg::test
