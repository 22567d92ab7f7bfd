// World<S>::runParticleRows: runs a row kernel over the particle rows in fixed chunks (parallel,
// chunk boundaries independent of the thread count) and turns the first fault, in chunk order,
// into the world's failure. Included by the files whose stages loop over particle rows.
#pragma once

#include <algorithm>
#include <vector>

#include "sim/world/world.h"

namespace sg {

/// Storage columns [begin, end) of one particle row under wind run `run`.
struct WindPiece {
  int64_t begin = 0, end = 0;
  size_t run = 0;
};

/// One row's wind runs (lattice columns, computeRowWind) as pieces in storage order: a run that
/// wraps round the window's toroidal storage is split in two (a window wraps its columns at most
/// once). The CPU pass advances the pieces in this order and the device path uploads them in it,
/// so both meet a row's faults in the same order. Replaces *out.
template <class S>
void windPiecesInStorageOrder(const LatticeWindow& window, int64_t countX, const std::vector<WindRun<S>>& runs,
                              std::vector<WindPiece>* out) {
  out->clear();
  for (size_t k = 0; k < runs.size(); ++k) {
    const int64_t first = window.storageColumn(runs[k].begin), length = runs[k].end - runs[k].begin;
    out->push_back({first, std::min(first + length, countX), k});
    if (first + length > countX) out->push_back({0, first + length - countX, k});  // the part past the wrap
  }
  std::sort(out->begin(), out->end(), [](const WindPiece& a, const WindPiece& b) {
    return a.begin != b.begin ? a.begin < b.begin : a.run < b.run;
  });
}

template <class S>
template <class Fn>
bool World<S>::runParticleRows(Stage stage, Fn&& rowKernel) {
  const int64_t chunks = (grid_.countZ + rowsPerChunk_ - 1) / rowsPerChunk_;
  std::vector<RowFault> faultAt(static_cast<size_t>(chunks));
  std::vector<uint32_t> faultBits(size_t(chunks), 0);
  pool_->run(chunks, [&](int64_t c, int) {
    takeFixedFaults();
    const int64_t b1 = std::min(grid_.countZ, (c + 1) * rowsPerChunk_);
    for (int64_t b = c * rowsPerChunk_; b < b1; ++b) {
      RowFault fault{-1, stage};
      // A kernel returns the faulting particle (-1: none), or a RowFault when it spans stages.
      if constexpr (std::is_same_v<decltype(rowKernel(b, b, b)), RowFault>)
        fault = rowKernel(b, b * grid_.countX, (b + 1) * grid_.countX);
      else
        fault.particle = rowKernel(b, b * grid_.countX, (b + 1) * grid_.countX);
      if (fault.particle >= 0) {
        faultAt[size_t(c)] = fault;
        faultBits[size_t(c)] = takeFixedFaults();
        return;
      }
    }
  });
  // The first faulting chunk in index order: the same report for any thread count.
  for (int64_t c = 0; c < chunks; ++c) {
    if (faultAt[size_t(c)].particle < 0) continue;
    const int64_t q = faultAt[size_t(c)].particle;
    failed_ = true;
    failure_.tick = tick_;
    failure_.stage = faultAt[size_t(c)].stage;
    failure_.particle = q;
    failure_.latticeI = grid_.window.latticeColumn(q % grid_.countX) * grid_.k;
    failure_.latticeJ = grid_.window.latticeRow(q / grid_.countX) * grid_.k;
    failure_.what = faultBits[size_t(c)] ? fixedFaultName(faultBits[size_t(c)])
                                         : "a value that is not finite or beyond +-2^48 (a saved state's range)";
    return false;
  }
  return true;
}

}  // namespace sg
