// Stage 5 of the step: derived patch state, what the renderer draws (thesis §9.2.6, §9.3).
//
// Each patch takes the displacement of its tuft tip from rest, d = p - anchor - (0, L, 0),
// interpolated bilinearly from the particles around it (interpolation k): first along z between
// two particle rows, then along x, with weights t/k. A patch that owns a particle (i and j
// multiples of k) gets that particle's displacement exactly. From d:
//     tipOffset = (d.x, d.z)                      top vertices follow the particle
//     smaller   = clamp(-d.y, 0, L/2)             the quad never gets shorter than scaleY - L/2
//     topY      = rootY + scaleY - smaller
//     tilt      = 3 if d.y < -drop[2], 2 if < -drop[1], 1 if < -drop[0], else 0
#pragma once

#include <cstdint>
#include <vector>

#include "sim/field/grass_field.h"
#include "sim/particles/particles.h"

namespace sg {

template <class S>
struct PatchStateConstants {
  int k = 1;
  std::vector<S> weight;  ///< weight[t] = t / k, t = 0..k-1
  S rodLength{}, halfRod{}, scaleY{};
  S cutReduction{};  ///< scaleYMinus of a mown tuft: scaleY - mowerCutHeight (>= 0)
  S minimumTop{};    ///< a tuft never gets shorter than this (m)
  S drop[3]{};
};

/// Tip displacement of particles [begin, end).
template <class S>
inline void particleDisplacement(const ParticleArrays<S>& p, int64_t begin, int64_t end, S rod,
                                 std::vector<S>& dx, std::vector<S>& dy, std::vector<S>& dz) {
  for (int64_t i = begin; i < end; ++i) {
    dx[size_t(i)] = p.px[size_t(i)] - p.anchorX[size_t(i)];
    dy[size_t(i)] = p.py[size_t(i)] - p.anchorY[size_t(i)] - rod;
    dz[size_t(i)] = p.pz[size_t(i)] - p.anchorZ[size_t(i)];
  }
}

/// Writes one patch's derived state from its tip displacement (ddx, ddy, ddz).
template <class S>
inline void writePatch(PatchArrays<S>& patches, size_t p, S ddx, S ddy, S ddz, const PatchStateConstants<S>& c) {
  const S zero(0);
  patches.tipOffsetX[p] = ddx;
  patches.tipOffsetZ[p] = ddz;
  const S sink = zero - ddy;
  const S smaller = sink < zero ? zero : (sink > c.halfRod ? c.halfRod : sink);
  // Thesis: top = root + scaleY - scaleYMinus - smaller; scaleYMinus is set by the mower.
  const S top = c.scaleY - smaller - (patches.cut[p] ? c.cutReduction : zero);
  patches.topY[p] = patches.rootY[p] + (top < c.minimumTop ? c.minimumTop : top);
  patches.tiltLevel[p] = uint8_t(sink > c.drop[2] ? 3 : sink > c.drop[1] ? 2 : sink > c.drop[0] ? 1 : 0);
}

/// Derived state of patch row j. `scratch` holds 3 * grid.countX values.
template <class S>
inline void updatePatchRow(PatchArrays<S>& patches, int64_t patchesX, int64_t j, const ParticleGrid& grid,
                           const std::vector<S>& dx, const std::vector<S>& dy, const std::vector<S>& dz,
                           const PatchStateConstants<S>& c, S* scratch) {
  const int k = c.k;
  const int64_t b0 = j / k, tz = j % k;
  const int64_t nx = grid.countX;
  // Row of displacements at this patch row's z: particle row b0, or a blend of b0 and b0+1.
  const S* rx = dx.data() + b0 * nx;
  const S* ry = dy.data() + b0 * nx;
  const S* rz = dz.data() + b0 * nx;
  if (tz != 0) {
    const S w = c.weight[size_t(tz)];
    S* bx = scratch;
    S* by = scratch + nx;
    S* bz = scratch + 2 * nx;
    for (int64_t a = 0; a < nx; ++a) {
      bx[a] = lerp(rx[a], rx[a + nx], w);
      by[a] = lerp(ry[a], ry[a + nx], w);
      bz[a] = lerp(rz[a], rz[a + nx], w);
    }
    rx = bx;
    ry = by;
    rz = bz;
  }
  const int64_t row = j * patchesX;
  if (k == 1) {  // every patch owns its particle
    for (int64_t i = 0; i < patchesX; ++i) writePatch(patches, size_t(row + i), rx[i], ry[i], rz[i], c);
    return;
  }
  // Walk particle columns a and the k patches after each (i = a k + t): no division per patch.
  for (int64_t a = 0, i = 0; i < patchesX; ++a) {
    for (int t = 0; t < k && i < patchesX; ++t, ++i) {
      S ddx = rx[a], ddy = ry[a], ddz = rz[a];
      if (t != 0) {
        const S w = c.weight[size_t(t)];
        ddx = lerp(ddx, rx[a + 1], w);
        ddy = lerp(ddy, ry[a + 1], w);
        ddz = lerp(ddz, rz[a + 1], w);
      }
      writePatch(patches, size_t(row + i), ddx, ddy, ddz, c);
    }
  }
}

}  // namespace sg
