// The state hash (docs/state-format.md, "The state hash"): what stateHash() returns, and what a
// recording's CHCK, SNAP and END chunks hold (.sgr format version 2).
//
//   XXH3-64 (seed 0) of the canonical serialisation (state_format.h) in which the payload of each
//   particle array (PART's px, py, pz, vx, vy, vz, then TRMP's trample levels) is replaced by the
//   digests of its row groups: the rows in storage order, taken stateHashRowsPerGroup(row width)
//   at a time (the last group may be shorter), each group's values (their little-endian bytes)
//   hashed with XXH3-64 (seed 0) and written as a little-endian u64. Everything else (the magic,
//   the section headers with their real payload lengths, HEAD, BODY, SPWN, CONT, CUTS, LODW) is
//   hashed as saved.
//
// Why groups of rows: one XXH3 stream over the whole state ran on one thread after the tick, with
// the state gone cold in the cache, while the other threads waited: +21 % of a two-thread tick
// when a recording checks every tick (about +30 % measured side by side; docs/performance.md,
// "Recording, seeking, snapshots"). A group is exactly one chunk of the particle pass
// (World::rowsPerChunk_ is stateHashRowsPerGroup), so the pass takes its digests right after it
// moved the chunk, on whichever thread moved it, with the rows in that core's cache
// (World::requestStateHash). A digest depends on its rows' values alone, so the hash
// is the same for any thread count and machine; it is also what a world computes afresh (after a
// restore, for a final hash) when no pass took the digests. Whole groups rather than single rows:
// a digest per row cost 55 instructions of set-up each (906 a tick on the thesis meadow), which
// made a one-thread recording 4 % slower than the single stream.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "sim/state/byte_order.h"
#include "sim/state/state_sink.h"  // XXH3 (on x86-64 the dispatching entry points)

namespace sg {

/// Particles per digest, about: a group is this many particles' worth of whole rows.
inline constexpr int64_t kStateHashGroupElements = 4096;
/// Rows per digest group for rows of `rowWidth` particles (at least 1).
inline int64_t stateHashRowsPerGroup(int64_t rowWidth) {
  return rowWidth >= kStateHashGroupElements ? 1 : kStateHashGroupElements / rowWidth;
}

/// XXH3-64 of n values as their little-endian bytes (a row group's digest).
template <class T>
uint64_t rowDigest(const T* values, size_t n) {
  if constexpr (kHostIsLittleEndian) {
    return XXH3_64bits(values, n * sizeof(T));
  } else {
    thread_local std::vector<uint8_t> bytes;
    bytes.resize(n * sizeof(T));
    for (size_t i = 0; i < n; ++i) storeLE(bytes.data() + i * sizeof(T), values[i]);
    return XXH3_64bits(bytes.data(), bytes.size());
  }
}

}  // namespace sg
