// World<S>::runParticleRows: runs a row kernel over the particle rows in fixed chunks (parallel,
// chunk boundaries independent of the thread count) and turns the first fault, in chunk order,
// into the world's failure. Included by the files whose stages loop over particle rows.
#pragma once

#include "sim/world/world.h"

namespace sg {

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
    failure_.what = faultBits[size_t(c)] ? fixedFaultName(faultBits[size_t(c)]) : "non-finite value";
    return false;
  }
  return true;
}

}  // namespace sg
