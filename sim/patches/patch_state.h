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

#include <algorithm>
#include <bit>
#include <cstdint>
#include <type_traits>
#include <utility>
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

// ---- unchecked fixed-point arithmetic for the patch stage ------------------------------------
// The patch stage is derived output: its fault bits are never collected (the next step starts by
// clearing them), so a result that does not fit simply wraps, as Fixed's own operators return it.
// These helpers compute exactly Fixed's bits (wrapping add/sub, round-half-away product, modular
// narrowing) without the fault bookkeeping, which lets the compiler keep the loops branch-light.
// tests/interpolation_test.cpp checks them against Fixed's operators on edge and random values.
namespace unchecked {

template <class Raw>
inline Raw add(Raw a, Raw b) {
  using U = std::make_unsigned_t<Raw>;
  return Raw(U(a) + U(b));
}
template <class Raw>
inline Raw sub(Raw a, Raw b) {
  using U = std::make_unsigned_t<Raw>;
  return Raw(U(a) - U(b));
}

/// Fixed's a * b for b = 2^(Frac - m), 1 <= m <= Frac, as a shift: round(d / 2^m), ties away
/// from zero. Fixed computes (d 2^(Frac-m) + 2^(Frac-1) + sign) >> Frac in the wide type; for
/// d >= 0 that is (d + 2^(m-1)) >> m; for d < 0 the sign's -1, divided by 2^(Frac-m), lies in
/// (0, 1], so the floor is that of (d + 2^(m-1) - 1) / 2^m. Neither sum overflows as written.
template <class Raw, int M>
inline Raw shiftRound(Raw d) {
  using U = std::make_unsigned_t<Raw>;
  if (d >= 0) return Raw((U(d) + (U(1) << (M - 1))) >> M);
  return Raw(d + ((Raw(1) << (M - 1)) - 1)) >> M;
}

/// Fixed's lerp(a, b, w) = a + (b - a) * w with the weight t/K (K a power of two).
template <class S, int K>
inline S lerpByFraction(S a, S b, int t) {
  using Raw = typename S::RawType;
  using Wide = typename S::WideType;
  constexpr int kRawBits = int(sizeof(Raw) * 8);
  constexpr int kLogK = std::countr_zero(unsigned(K));
  const Raw d = sub(b.raw(), a.raw());
  Raw scaled;
  if constexpr (K == 2) {
    scaled = shiftRound<Raw, 1>(d);  // t == 1
  } else {
    static_assert(K == 4);
    if (t == 2) {
      scaled = shiftRound<Raw, 1>(d);
    } else if (t == 1) {
      scaled = shiftRound<Raw, 2>(d);
    } else {  // t = 3: weight 3 * 2^(Frac - 2), the general product
      const Wide p = Wide(d) * Wide(Raw(t) << (S::kFracBits - kLogK));
      scaled = Raw((p + (Wide(1) << (S::kFracBits - 1)) + (p >> (2 * kRawBits - 1))) >> S::kFracBits);
    }
  }
  return S::fromRaw(add(a.raw(), scaled));
}

}  // namespace unchecked

/// Tip displacement p - anchor - (0, L, 0) of particles [begin, end). Patch-stage data, so the
/// fixed types compute it unchecked (the same bits): inside the fused particle pass
/// (particle_row.h) it must not leave a fault bit for the next row's integration to misreport.
template <class S>
inline void particleDisplacement(const ParticleArrays<S>& p, int64_t begin, int64_t end, S rod, std::vector<S>& dx,
                                 std::vector<S>& dy, std::vector<S>& dz) {
  const S* px = p.px.data();
  const S* py = p.py.data();
  const S* pz = p.pz.data();
  const S* ax = p.anchorX.data();
  const S* ay = p.anchorY.data();
  const S* az = p.anchorZ.data();
  S* ox = dx.data();
  S* oy = dy.data();
  S* oz = dz.data();
  for (int64_t i = begin; i < end; ++i) {
    if constexpr (ScalarTraits<S>::isFixed) {
      ox[i] = S::fromRaw(unchecked::sub(px[i].raw(), ax[i].raw()));
      oy[i] = S::fromRaw(unchecked::sub(unchecked::sub(py[i].raw(), ay[i].raw()), rod.raw()));
      oz[i] = S::fromRaw(unchecked::sub(pz[i].raw(), az[i].raw()));
    } else {
      ox[i] = px[i] - ax[i];
      oy[i] = py[i] - ay[i] - rod;
      oz[i] = pz[i] - az[i];
    }
  }
}

/// Writes patches' derived state from their tip displacement. Holds raw pointers and the
/// constants by value: a tilt store (uint8_t) may alias anything, so code indexing the vectors
/// through PatchArrays would reload every data pointer and constant after each patch.
template <class S>
struct PatchWriter {
  S* tipOffsetX;
  S* tipOffsetZ;
  S* topY;
  uint8_t* tiltLevel;
  const S* rootY;
  const uint8_t* cut;
  S halfRod, scaleY, cutReduction, minimumTop, drop0, drop1, drop2;

  PatchWriter(PatchArrays<S>& patches, const PatchStateConstants<S>& c)
      : tipOffsetX(patches.tipOffsetX.data()),
        tipOffsetZ(patches.tipOffsetZ.data()),
        topY(patches.topY.data()),
        tiltLevel(patches.tiltLevel.data()),
        rootY(patches.rootY.data()),
        cut(patches.cut.data()),
        halfRod(c.halfRod),
        scaleY(c.scaleY),
        cutReduction(c.cutReduction),
        minimumTop(c.minimumTop),
        drop0(c.drop[0]),
        drop1(c.drop[1]),
        drop2(c.drop[2]) {}

  /// write() without the fault bookkeeping for the fixed types (the same bits: see `unchecked`).
  void writeFast(size_t p, S ddx, S ddy, S ddz) const {
    if constexpr (!ScalarTraits<S>::isFixed) {
      write(p, ddx, ddy, ddz);
    } else {
      using Raw = typename S::RawType;
      tipOffsetX[p] = ddx;
      tipOffsetZ[p] = ddz;
      const Raw sink = unchecked::sub(Raw(0), ddy.raw());
      const Raw smaller = sink < 0 ? Raw(0) : (sink > halfRod.raw() ? halfRod.raw() : sink);
      const Raw top = unchecked::sub(unchecked::sub(scaleY.raw(), smaller), cut[p] ? cutReduction.raw() : Raw(0));
      topY[p] = S::fromRaw(unchecked::add(rootY[p].raw(), top < minimumTop.raw() ? minimumTop.raw() : top));
      tiltLevel[p] = uint8_t(sink > drop2.raw() ? 3 : sink > drop1.raw() ? 2 : sink > drop0.raw() ? 1 : 0);
    }
  }

  /// Writes patch p from its tip displacement (ddx, ddy, ddz).
  void write(size_t p, S ddx, S ddy, S ddz) const {
    const S zero(0);
    tipOffsetX[p] = ddx;
    tipOffsetZ[p] = ddz;
    const S sink = zero - ddy;
    const S smaller = sink < zero ? zero : (sink > halfRod ? halfRod : sink);
    // Thesis: top = root + scaleY - scaleYMinus - smaller; scaleYMinus is set by the mower.
    const S top = scaleY - smaller - (cut[p] ? cutReduction : zero);
    topY[p] = rootY[p] + (top < minimumTop ? minimumTop : top);
    tiltLevel[p] = uint8_t(sink > drop2 ? 3 : sink > drop1 ? 2 : sink > drop0 ? 1 : 0);
  }
};

/// AVX2 versions of the loops below, for Fx32 and Fx16 (patch_row_avx2.cpp), with
/// the same bits; call them only where the CPU has AVX2 (avx2KernelAvailable()).
/// out[i] = unchecked::lerpByFraction<S, 4>(a[i], b[i], quarters), quarters = 1, 2, 3 (the
/// weight 1/2 of k = 2 is 2 quarters).
template <class S>
void blendRowsAvx2(const S* a, const S* b, S* out, int64_t n, int quarters);
/// out[2u] = r[u], out[2u + 1] = lerpByFraction<S, 2>(r[u], r[u + 1], 1) for u in [0, pairs)
/// (reads r[pairs]).
template <class S>
void interpolateHalvesAvx2(const S* r, S* out, int64_t pairs);
/// out[4u + t] = lerpByFraction<S, 4>(r[u], r[u + 1], t) (t = 0: r[u]) for u in [0, quads)
/// (reads r[quads]).
template <class S>
void interpolateQuartersAvx2(const S* r, S* out, int64_t quads);
/// w.writeFast(first + q, dx[q], dy[q], dz[q]) for q in [0, count).
template <class S>
void writePatchesAvx2(const PatchWriter<S>& w, size_t first, const S* dx, const S* dy, const S* dz, int64_t count);
/// w.write(first + q, ...) for float and double (patch_write_ieee_avx2.cpp): IEEE lanes, the
/// reference's operations and ordered comparisons, so its bits (NaN and signed zeros included).
void writePatchesAvx2(const PatchWriter<float>& w, size_t first, const float* dx, const float* dy, const float* dz,
                      int64_t count);
void writePatchesAvx2(const PatchWriter<double>& w, size_t first, const double* dx, const double* dy, const double* dz,
                      int64_t count);

/// t / K as a constant, for K a power of two: exact in every scalar (the runtime weight
/// c.weight[t] holds the same value; rowWeightsAreExact checks), so the compiler turns the
/// multiplications by it into shifts and unrolls the patches between two particles.
template <class S, int K>
inline S powerOfTwoWeight(int t) {
  static_assert(K > 1 && (K & (K - 1)) == 0, "K must be a power of two");
  if constexpr (ScalarTraits<S>::isFixed) {
    return S::fromRaw(typename S::RawType(t) << (S::kFracBits - std::countr_zero(unsigned(K))));
  } else {
    return S(t) / S(K);
  }
}

/// True when c.k is 2 or 4 and every c.weight[t] equals powerOfTwoWeight (then updatePatchRow
/// may run with K = c.k and give the same bits as K = 0).
template <class S>
inline bool rowWeightsAreExact(const PatchStateConstants<S>& c) {
  auto check = [&]<int K>() {
    for (int t = 0; t < K; ++t)
      if (!(c.weight[size_t(t)] == powerOfTwoWeight<S, K>(t))) return false;
    return true;
  };
  return c.k == 2 ? check.template operator()<2>() : c.k == 4 ? check.template operator()<4>() : false;
}

/// Derived state of patch row j (a lattice row of `patchWindow`) for interpolation k > 1 (with
/// k = 1 patch and particle storage coincide and PatchWriter runs straight over them).
/// `particles` is the particle window (toroidal, sim/lod/lattice_window.h); the patch window
/// covers patch columns [k originI, k (originI + sizeI - 1)] at most, so every patch lies between
/// two held particles. `scratch` holds 3 * (particles.sizeI + patchWindow.sizeI) values. K = 0 takes k and the weights
/// from `c`; K = c.k (2 or 4, when rowWeightsAreExact) uses constant weights: the same bits,
/// about a third fewer instructions. `vector` (K = 2, 4 and the fixed types only) runs the row
/// blend, the interpolation along x and the patch writes with the AVX2 loops: the same bits again.
template <class S, int K = 0>
inline void updatePatchRow(PatchArrays<S>& patches, const LatticeWindow& patchWindow, int64_t j,
                           const LatticeWindow& particles, const std::vector<S>& dx, const std::vector<S>& dy,
                           const std::vector<S>& dz, const PatchStateConstants<S>& c, S* scratch, bool vector = false) {
  const int k = K != 0 ? K : c.k;
  const S* weight = c.weight.data();
  auto weightOf = [&](int t) {  // [&]: `weight` is unused when K != 0 (a named capture warns)
    if constexpr (K != 0)
      return powerOfTwoWeight<S, K>(t);
    else
      return weight[t];
  };
  // K = 0 is the reference: Fixed's checked operators. K = 2, 4 compute the same bits unchecked.
  constexpr bool kFast = K != 0 && ScalarTraits<S>::isFixed;
  auto blend = [&](S a, S b, int t) {
    if constexpr (kFast)
      return unchecked::lerpByFraction<S, K>(a, b, t);
    else
      return lerp(a, b, weightOf(t));
  };
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
    const S* sx = dx.data() + r1;
    const S* sy = dy.data() + r1;
    const S* sz = dz.data() + r1;
    const int t = int(tz);
    S* bx = scratch;
    S* by = scratch + nx;
    S* bz = scratch + 2 * nx;
    bool blended = false;
    if constexpr (kFast) {
      if (vector) {
        const int quarters = K == 2 ? 2 : t;  // the weight t / K in quarters
        blendRowsAvx2(rx, sx, bx, nx, quarters);
        blendRowsAvx2(ry, sy, by, nx, quarters);
        blendRowsAvx2(rz, sz, bz, nx, quarters);
        blended = true;
      }
    }
    if (!blended) {
      for (int64_t a = 0; a < nx; ++a) {
        bx[a] = blend(rx[a], sx[a], t);
        by[a] = blend(ry[a], sy[a], t);
        bz[a] = blend(rz[a], sz[a], t);
      }
    }
    rx = bx;
    ry = by;
    rz = bz;
  }
  // Along x, into the patch row's displacements in patch storage order: walk particle columns
  // (storage column sa, wrapping) and the k patches after each (i = k a + t), no division per
  // patch; patch storage columns wrap the same way. Then the derived state in one contiguous
  // pass. (Two short loops keep few values live: one loop doing both spills to the stack.)
  const int64_t rowSize = patchWindow.sizeI, endI = patchWindow.endI();
  S* qx = scratch + 3 * nx;
  S* qy = qx + rowSize;
  S* qz = qy + rowSize;
  int64_t sa = particles.storageColumn(patchWindow.originI / k);
  int64_t sp = patchWindow.storageColumn(patchWindow.originI);
  for (int64_t i = patchWindow.originI; i < endI;) {
    if constexpr (kFast) {
      // The run of whole particle steps up to the next wrap of either storage row, vectorised
      // (all of it with the level of detail off); the scalar steps below cross the wrap.
      const int64_t steps = std::min({nx - 1 - sa, (rowSize - sp) / K, (endI - i) / K});
      if (vector && steps > 0) {
        for (auto [r, q] : {std::pair{rx, qx}, std::pair{ry, qy}, std::pair{rz, qz}}) {
          if constexpr (K == 2)
            interpolateHalvesAvx2(r + sa, q + sp, steps);
          else
            interpolateQuartersAvx2(r + sa, q + sp, steps);
        }
        sa += steps;
        sp += K * steps;
        i += K * steps;
        if (sp == rowSize) sp = 0;
        if (i >= endI) break;
      }
    }
    const int64_t sb = sa + 1 == nx ? 0 : sa + 1;
    for (int t = 0; t < k && i < endI; ++t, ++i) {
      S ddx = rx[sa], ddy = ry[sa], ddz = rz[sa];
      if (t != 0) {
        ddx = blend(ddx, rx[sb], t);
        ddy = blend(ddy, ry[sb], t);
        ddz = blend(ddz, rz[sb], t);
      }
      qx[sp] = ddx;
      qy[sp] = ddy;
      qz[sp] = ddz;
      sp = sp + 1 == rowSize ? 0 : sp + 1;
    }
    sa = sb;
  }
  const PatchWriter<S> out(patches, c);
  const size_t rowBase = size_t(patchWindow.storageRow(j) * rowSize);
  if constexpr (kFast || !ScalarTraits<S>::isFixed)
    if (vector) return writePatchesAvx2(out, rowBase, qx, qy, qz, rowSize);
  for (int64_t q = 0; q < rowSize; ++q) {
    if constexpr (kFast)
      out.writeFast(rowBase + size_t(q), qx[q], qy[q], qz[q]);
    else
      out.write(rowBase + size_t(q), qx[q], qy[q], qz[q]);
  }
}

}  // namespace sg
