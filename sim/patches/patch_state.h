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

/// Derived state of patch row j (a lattice row of `patchWindow`) for interpolation k > 1 (with
/// k = 1 patch and particle storage coincide and writePatch runs straight over them).
/// `particles` is the particle window (toroidal, sim/lod/lattice_window.h); the patch window
/// covers patch columns [k originI, k (originI + sizeI - 1)] at most, so every patch lies between
/// two held particles. `scratch` holds 3 * particles.sizeI values.
template <class S>
inline void updatePatchRow(PatchArrays<S>& patches, const LatticeWindow& patchWindow, int64_t j,
                           const LatticeWindow& particles, const std::vector<S>& dx, const std::vector<S>& dy,
                           const std::vector<S>& dz, const PatchStateConstants<S>& c, S* scratch) {
  const int k = c.k;
  const int64_t b0 = j / k, tz = j % k;
  const int64_t nx = particles.sizeI;
  // Row of displacements at this patch row's z: particle row b0, or a blend of b0 and b0+1, in
  // storage column order (the blend is per column, so no remapping is needed yet).
  const int64_t r0 = particles.storageRow(b0) * nx;
  const S* rx = dx.data() + r0;
  const S* ry = dy.data() + r0;
  const S* rz = dz.data() + r0;
  if (tz != 0) {
    const int64_t r1 = particles.storageRow(b0 + 1) * nx;
    const S w = c.weight[size_t(tz)];
    S* bx = scratch;
    S* by = scratch + nx;
    S* bz = scratch + 2 * nx;
    for (int64_t a = 0; a < nx; ++a) {
      bx[a] = lerp(rx[a], dx[size_t(r1 + a)], w);
      by[a] = lerp(ry[a], dy[size_t(r1 + a)], w);
      bz[a] = lerp(rz[a], dz[size_t(r1 + a)], w);
    }
    rx = bx;
    ry = by;
    rz = bz;
  }
  // Walk particle columns (storage column sa, wrapping) and the k patches after each
  // (i = k a + t): no division per patch. Patch storage columns wrap the same way.
  const int64_t rowBase = patchWindow.storageRow(j) * patchWindow.sizeI;
  int64_t sa = particles.storageColumn(patchWindow.originI / k);
  int64_t sp = patchWindow.storageColumn(patchWindow.originI);
  for (int64_t i = patchWindow.originI; i < patchWindow.endI();) {
    const int64_t sb = sa + 1 == nx ? 0 : sa + 1;
    for (int t = 0; t < k && i < patchWindow.endI(); ++t, ++i) {
      S ddx = rx[sa], ddy = ry[sa], ddz = rz[sa];
      if (t != 0) {
        const S w = c.weight[size_t(t)];
        ddx = lerp(ddx, rx[sb], w);
        ddy = lerp(ddy, ry[sb], w);
        ddz = lerp(ddz, rz[sb], w);
      }
      writePatch(patches, size_t(rowBase + sp), ddx, ddy, ddz, c);
      sp = sp + 1 == patchWindow.sizeI ? 0 : sp + 1;
    }
    sa = sb;
  }
}

}  // namespace sg
