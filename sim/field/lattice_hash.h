// Counter-based randomness for the infinite grass lattice: every per-patch attribute is a pure
// function of (i, j, seed, salt). Regenerating a patch anywhere, any time, in any order, gives
// the same patch; there is no stateful random generator anywhere in the core.
#pragma once

#include <cstdint>

namespace sg {

/// Attribute streams drawn from the lattice hash.
enum class LatticeSalt : uint32_t { Jitter = 0, Appearance = 1, Marking = 2 };

/// XXH3-64 of the little-endian bytes (i, j, salt) with the scenario seed.
uint64_t latticeHash(int64_t i, int64_t j, uint64_t seed, LatticeSalt salt);

}  // namespace sg
