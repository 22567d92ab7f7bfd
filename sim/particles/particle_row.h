// Stages 3 and 4 of the step fused per particle row: integration (integrate.h), the rod
// constraint (rod_constraint.h) and the tip displacement the patch stage reads
// (patches/patch_state.h), one row after the other.
//
// Why fused: the three are pointwise, so running them row by row gives bit-identical results
// to three whole-array passes, but a row's nine arrays (501 particles * 9 * 8 B = 36 KB at
// 1,000,000 patches, k = 2) stay in L1/L2 between them instead of streaming the whole particle
// state (18 MB there) through memory three times (docs/performance.md, "Fused particle pass").
//
// Two implementations give the same bits: the scalar reference below, and an AVX2 kernel
// (particle_row_avx2.cpp) that runs four (Fx32, double) or eight (Fx16, float) particles per
// instruction and hands any block it cannot prove exact to the reference (docs/performance.md,
// "Vector kernels").
#pragma once

#include <cstdint>
#include <vector>

#include "sim/particles/integrate.h"
#include "sim/particles/particle_kernel.h"
#include "sim/particles/rod_constraint.h"
#include "sim/patches/patch_state.h"
#include "sim/world/stage.h"

namespace sg {

/// Where a row kernel faulted: the first faulting particle (-1: none) and the stage it was in.
struct RowFault {
  int64_t particle = -1;
  Stage stage = Stage::Integrate;
};

/// The reference: integrates, projects and measures particles [begin, end) of one row;
/// (dvx, dvy, dvz) is the row's (a + F/m) dt. Writes the tip displacement p - anchor - (0, L, 0)
/// into (dx, dy, dz). A fault stops the row at the faulting particle, in the stage that raised
/// it; an integration fault anywhere in the row is reported before any projection fault.
template <class S, bool Pbd>
inline RowFault advanceParticleRowScalar(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy, S dvz,
                                         const ParticleConstants<S>& c, std::vector<S>& dx, std::vector<S>& dy,
                                         std::vector<S>& dz) {
  if (const int64_t at = integrateParticleRow<S, Pbd>(p, begin, end, dvx, dvy, dvz, c); at >= 0)
    return {at, Stage::Integrate};
  if (const int64_t at = projectRodRow<S, Pbd>(p, begin, end, c); at >= 0) return {at, Stage::Constraints};
  particleDisplacement(p, begin, end, c.rodLength, dx, dy, dz);
  return {};
}

/// The AVX2 kernel (every scalar; particle_row_avx2.cpp). Same contract and bits as
/// advanceParticleRowScalar. Call only when avx2KernelAvailable().
template <class S, bool Pbd>
RowFault advanceParticleRowAvx2(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy, S dvz,
                                const ParticleConstants<S>& c, std::vector<S>& dx, std::vector<S>& dy,
                                std::vector<S>& dz);

/// The fused pass with the chosen kernel.
template <class S, bool Pbd>
inline RowFault advanceParticleRow(ParticleKernel kernel, ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx,
                                   S dvy, S dvz, const ParticleConstants<S>& c, std::vector<S>& dx, std::vector<S>& dy,
                                   std::vector<S>& dz) {
  if (kernel == ParticleKernel::Avx2)
    return advanceParticleRowAvx2<S, Pbd>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
  return advanceParticleRowScalar<S, Pbd>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
}

}  // namespace sg
