// The patch stage's loops (patch_state.h) for Fx32 and Fx16 in AVX2, with the unchecked loops'
// exact bits (which are Fixed's bits, wrapping included):
//   * blendRowsAvx2: a[i] + round((b[i] - a[i]) q / 4), q = 1, 2, 3 (the blend of two particle
//     rows for a patch row between them; k = 2 is q = 2);
//   * interpolateHalvesAvx2, interpolateQuartersAvx2: k = 2 and 4 along x, a particle's value
//     and the blends towards the next, interleaved into patch order;
//   * writePatchesAvx2: PatchWriter::writeFast over a run of patches (tip offsets, topY, tilt).
// Fx32 four values per instruction, Fx16 eight. Everything here is integer arithmetic that
// wraps like the scalar code, so there is nothing to verify and no fallback per block; the
// callers keep the scalar loops for the constants and weights these do not handle.
#include <cstring>
#include <type_traits>

#include "sim/patches/patch_state.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace sg {

#if defined(__x86_64__)

namespace {

#define SG_AVX2 __attribute__((target("avx2"), always_inline)) inline

/// Lane operations of one format: Fx32 in 64-bit lanes (4), Fx16 in 32-bit lanes (8).
template <class S>
struct Lanes;

template <>
struct Lanes<Fx32> {
  static constexpr int kCount = 4;
  static constexpr int kBits = 64;
  SG_AVX2 static __m256i all(int64_t v) { return _mm256_set1_epi64x(v); }
  SG_AVX2 static __m256i add(__m256i a, __m256i b) { return _mm256_add_epi64(a, b); }
  SG_AVX2 static __m256i sub(__m256i a, __m256i b) { return _mm256_sub_epi64(a, b); }
  SG_AVX2 static __m256i greater(__m256i a, __m256i b) { return _mm256_cmpgt_epi64(a, b); }
  SG_AVX2 static __m256i shiftRight(__m256i a, int m) { return _mm256_srli_epi64(a, m); }
  SG_AVX2 static __m256i shiftLeft(__m256i a, int m) { return _mm256_slli_epi64(a, m); }
  /// cut flags of 4 patches (0 or 1 bytes) as lanes of 0 or -1.
  SG_AVX2 static __m256i cutMask(const uint8_t* c) {
    int32_t bytes;
    std::memcpy(&bytes, c, 4);
    const __m256i v = _mm256_cvtepu8_epi64(_mm_cvtsi32_si128(bytes));
    return _mm256_xor_si256(_mm256_cmpeq_epi64(v, _mm256_setzero_si256()), _mm256_set1_epi64x(-1));
  }
  /// Lanes holding 0..3 as 4 bytes.
  SG_AVX2 static void storeBytes(uint8_t* out, __m256i v) {
    const __m256i picked =
        _mm256_shuffle_epi8(v, _mm256_setr_epi8(0, 8, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 0, 8, -1,
                                                -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1));
    const int32_t lo = _mm_cvtsi128_si32(_mm256_castsi256_si128(picked));
    const int32_t hi = _mm_cvtsi128_si32(_mm256_extracti128_si256(picked, 1));
    const int32_t bytes = (lo & 0xFFFF) | (hi << 16);
    std::memcpy(out, &bytes, 4);
  }
};

template <>
struct Lanes<Fx16> {
  static constexpr int kCount = 8;
  static constexpr int kBits = 32;
  SG_AVX2 static __m256i all(int32_t v) { return _mm256_set1_epi32(v); }
  SG_AVX2 static __m256i add(__m256i a, __m256i b) { return _mm256_add_epi32(a, b); }
  SG_AVX2 static __m256i sub(__m256i a, __m256i b) { return _mm256_sub_epi32(a, b); }
  SG_AVX2 static __m256i greater(__m256i a, __m256i b) { return _mm256_cmpgt_epi32(a, b); }
  SG_AVX2 static __m256i shiftRight(__m256i a, int m) { return _mm256_srli_epi32(a, m); }
  SG_AVX2 static __m256i shiftLeft(__m256i a, int m) { return _mm256_slli_epi32(a, m); }
  SG_AVX2 static __m256i cutMask(const uint8_t* c) {
    const __m256i v = _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(c)));
    return _mm256_xor_si256(_mm256_cmpeq_epi32(v, _mm256_setzero_si256()), _mm256_set1_epi32(-1));
  }
  SG_AVX2 static void storeBytes(uint8_t* out, __m256i v) {
    const __m128i words = _mm_packs_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out), _mm_packus_epi16(words, words));
  }
};

template <class S>
SG_AVX2 __m256i load(const S* p) {
  return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
}
template <class S>
SG_AVX2 void store(S* p, __m256i v) {
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v);
}
SG_AVX2 __m256i select(__m256i mask, __m256i ifSet, __m256i ifClear) {
  return _mm256_blendv_epi8(ifClear, ifSet, mask);
}

/// unchecked::shiftRound<Raw, M>(d): round(d / 2^M), ties away from zero. x = d + 2^(M-1) - [d < 0]
/// (modular); for d >= 0 the scalar code shifts x as unsigned, for d < 0 arithmetically (AVX2
/// has no 64-bit arithmetic shift: the sign is filled in by hand).
template <class S, int M>
SG_AVX2 __m256i shiftRound(__m256i d) {
  using L = Lanes<S>;
  const __m256i zero = _mm256_setzero_si256();
  const __m256i negative = L::greater(zero, d);
  const __m256i x = L::add(L::add(d, L::all(1 << (M - 1))), negative);
  const __m256i fill = L::shiftLeft(_mm256_and_si256(negative, L::greater(zero, x)), L::kBits - M);
  return _mm256_or_si256(L::shiftRight(x, M), fill);
}

/// Fixed's d * (3/4): round(3 d / 4), ties away from zero, computed on |d| = 4 m + r without
/// the wide product: 3 m + (3 r + 2) / 4 (r = 0..3 gives 0, 1, 2, 2), then the sign. 3 m stays
/// below 3 * 2^61 (and the result is within the format: |3 d / 4| < 2^63).
template <class S>
SG_AVX2 __m256i threeQuarters(__m256i d) {
  using L = Lanes<S>;
  __m256i negative, magnitude;
  if constexpr (L::kBits == 64) {
    negative = L::greater(_mm256_setzero_si256(), d);
    magnitude = L::sub(_mm256_xor_si256(d, negative), negative);  // INT64_MIN: 2^63 as unsigned
  } else {
    magnitude = _mm256_abs_epi32(d);
  }
  const __m256i m = L::shiftRight(magnitude, 2);
  const __m256i r = _mm256_and_si256(magnitude, L::all(3));
  const __m256i rounded = L::shiftRight(L::add(L::add(r, L::shiftLeft(r, 1)), L::all(2)), 2);
  const __m256i result = L::add(L::add(m, L::shiftLeft(m, 1)), rounded);
  if constexpr (L::kBits == 64)
    return L::sub(_mm256_xor_si256(result, negative), negative);
  else
    return _mm256_sign_epi32(result, d);  // d = 0 gives 0, which the product is
}

/// round((b - a) q / 4) for q = 1, 2, 3 quarters, as unchecked::lerpByFraction<S, 4> scales.
template <class S, int Quarters>
SG_AVX2 __m256i scaleByQuarters(__m256i d) {
  if constexpr (Quarters == 1)
    return shiftRound<S, 2>(d);
  else if constexpr (Quarters == 2)
    return shiftRound<S, 1>(d);
  else
    return threeQuarters<S>(d);
}

template <class S, int Quarters>
__attribute__((target("avx2"))) void blendRows(const S* a, const S* b, S* out, int64_t n) {
  using L = Lanes<S>;
  int64_t i = 0;
  for (; i + L::kCount <= n; i += L::kCount) {
    const __m256i va = load(a + i);
    store(out + i, L::add(va, scaleByQuarters<S, Quarters>(L::sub(load(b + i), va))));
  }
  for (; i < n; ++i) out[i] = unchecked::lerpByFraction<S, 4>(a[i], b[i], Quarters);
}

/// out[2u] = r[u], out[2u + 1] = blend(r[u], r[u + 1]) with weight 1/2, u in [0, pairs).
template <class S>
__attribute__((target("avx2"))) void interpolateHalves(const S* r, S* out, int64_t pairs) {
  using L = Lanes<S>;
  int64_t u = 0;
  for (; u + L::kCount <= pairs; u += L::kCount) {
    const __m256i even = load(r + u);
    const __m256i odd = L::add(even, shiftRound<S, 1>(L::sub(load(r + u + 1), even)));
    // Interleave: unpack within each 128-bit half, then put the halves in order.
    __m256i lo, hi;
    if constexpr (L::kBits == 64) {
      lo = _mm256_unpacklo_epi64(even, odd);
      hi = _mm256_unpackhi_epi64(even, odd);
    } else {
      lo = _mm256_unpacklo_epi32(even, odd);
      hi = _mm256_unpackhi_epi32(even, odd);
    }
    store(out + 2 * u, _mm256_permute2x128_si256(lo, hi, 0x20));
    store(out + 2 * u + L::kCount, _mm256_permute2x128_si256(lo, hi, 0x31));
  }
  for (; u < pairs; ++u) {
    out[2 * u] = r[u];
    out[2 * u + 1] = unchecked::lerpByFraction<S, 2>(r[u], r[u + 1], 1);
  }
}

/// out[4u + t] = blend(r[u], r[u + 1]) with weight t / 4, t = 0..3, u in [0, quads).
template <class S>
__attribute__((target("avx2"))) void interpolateQuarters(const S* r, S* out, int64_t quads) {
  using L = Lanes<S>;
  int64_t u = 0;
  for (; u + L::kCount <= quads; u += L::kCount) {
    const __m256i e0 = load(r + u);
    const __m256i d = L::sub(load(r + u + 1), e0);
    const __m256i e1 = L::add(e0, scaleByQuarters<S, 1>(d));
    const __m256i e2 = L::add(e0, scaleByQuarters<S, 2>(d));
    const __m256i e3 = L::add(e0, scaleByQuarters<S, 3>(d));
    // Transpose: each particle's four patches side by side.
    S* o = out + 4 * u;
    if constexpr (L::kBits == 64) {
      const __m256i t0 = _mm256_unpacklo_epi64(e0, e1), t1 = _mm256_unpackhi_epi64(e0, e1);
      const __m256i t2 = _mm256_unpacklo_epi64(e2, e3), t3 = _mm256_unpackhi_epi64(e2, e3);
      store(o, _mm256_permute2x128_si256(t0, t2, 0x20));
      store(o + 4, _mm256_permute2x128_si256(t1, t3, 0x20));
      store(o + 8, _mm256_permute2x128_si256(t0, t2, 0x31));
      store(o + 12, _mm256_permute2x128_si256(t1, t3, 0x31));
    } else {
      const __m256i t0 = _mm256_unpacklo_epi32(e0, e1), t1 = _mm256_unpackhi_epi32(e0, e1);
      const __m256i t2 = _mm256_unpacklo_epi32(e2, e3), t3 = _mm256_unpackhi_epi32(e2, e3);
      const __m256i u0 = _mm256_unpacklo_epi64(t0, t2), u1 = _mm256_unpackhi_epi64(t0, t2);
      const __m256i u2 = _mm256_unpacklo_epi64(t1, t3), u3 = _mm256_unpackhi_epi64(t1, t3);
      store(o, _mm256_permute2x128_si256(u0, u1, 0x20));
      store(o + 8, _mm256_permute2x128_si256(u2, u3, 0x20));
      store(o + 16, _mm256_permute2x128_si256(u0, u1, 0x31));
      store(o + 24, _mm256_permute2x128_si256(u2, u3, 0x31));
    }
  }
  for (; u < quads; ++u) {
    out[4 * u] = r[u];
    for (int t = 1; t < 4; ++t) out[4 * u + t] = unchecked::lerpByFraction<S, 4>(r[u], r[u + 1], t);
  }
}

template <class S>
__attribute__((target("avx2"))) int64_t writePatches(const PatchWriter<S>& w, size_t first, const S* dx, const S* dy,
                                                     const S* dz, int64_t count) {
  using L = Lanes<S>;
  const __m256i zero = _mm256_setzero_si256();
  const __m256i halfRod = L::all(w.halfRod.raw()), scaleY = L::all(w.scaleY.raw());
  const __m256i cutReduction = L::all(w.cutReduction.raw()), minimumTop = L::all(w.minimumTop.raw());
  const __m256i drop0 = L::all(w.drop0.raw()), drop1 = L::all(w.drop1.raw()), drop2 = L::all(w.drop2.raw());
  int64_t q = 0;
  for (; q + L::kCount <= count; q += L::kCount) {
    const size_t p = first + size_t(q);
    store(w.tipOffsetX + p, load(dx + q));
    store(w.tipOffsetZ + p, load(dz + q));
    const __m256i sink = L::sub(zero, load(dy + q));
    // smaller = sink < 0 ? 0 : min(sink, halfRod); top = scaleY - smaller - (cut ? reduction : 0)
    const __m256i smaller =
        _mm256_andnot_si256(L::greater(zero, sink), select(L::greater(sink, halfRod), halfRod, sink));
    const __m256i top = L::sub(L::sub(scaleY, smaller), _mm256_and_si256(L::cutMask(w.cut + p), cutReduction));
    store(w.topY + p, L::add(load(w.rootY + p), select(L::greater(minimumTop, top), minimumTop, top)));
    // tilt = [sink > drop0] + [sink > drop1] + [sink > drop2]: the scalar if-chain when the drops rise
    const __m256i minusTilt = L::add(L::add(L::greater(sink, drop0), L::greater(sink, drop1)), L::greater(sink, drop2));
    L::storeBytes(w.tiltLevel + p, L::sub(zero, minusTilt));
  }
  return q;
}

}  // namespace

template <class S>
void blendRowsAvx2(const S* a, const S* b, S* out, int64_t n, int quarters) {
  if (quarters == 1)
    blendRows<S, 1>(a, b, out, n);
  else if (quarters == 2)
    blendRows<S, 2>(a, b, out, n);
  else
    blendRows<S, 3>(a, b, out, n);
}

template <class S>
void interpolateHalvesAvx2(const S* r, S* out, int64_t pairs) {
  interpolateHalves(r, out, pairs);
}

template <class S>
void interpolateQuartersAvx2(const S* r, S* out, int64_t quads) {
  interpolateQuarters(r, out, quads);
}

template <class S>
void writePatchesAvx2(const PatchWriter<S>& w, size_t first, const S* dx, const S* dy, const S* dz, int64_t count) {
  int64_t q = 0;
  // The vector tilt is the scalar if-chain only for rising drops (the scenario's; checked anyway).
  if (w.drop0 <= w.drop1 && w.drop1 <= w.drop2) q = writePatches(w, first, dx, dy, dz, count);
  for (; q < count; ++q) w.writeFast(first + size_t(q), dx[q], dy[q], dz[q]);
}

#else

template <class S>
void blendRowsAvx2(const S* a, const S* b, S* out, int64_t n, int quarters) {
  for (int64_t i = 0; i < n; ++i) out[i] = unchecked::lerpByFraction<S, 4>(a[i], b[i], quarters);
}
template <class S>
void interpolateQuartersAvx2(const S* r, S* out, int64_t quads) {
  for (int64_t u = 0; u < quads; ++u) {
    out[4 * u] = r[u];
    for (int t = 1; t < 4; ++t) out[4 * u + t] = unchecked::lerpByFraction<S, 4>(r[u], r[u + 1], t);
  }
}
template <class S>
void interpolateHalvesAvx2(const S* r, S* out, int64_t pairs) {
  for (int64_t u = 0; u < pairs; ++u) {
    out[2 * u] = r[u];
    out[2 * u + 1] = unchecked::lerpByFraction<S, 2>(r[u], r[u + 1], 1);
  }
}
template <class S>
void writePatchesAvx2(const PatchWriter<S>& w, size_t first, const S* dx, const S* dy, const S* dz, int64_t count) {
  for (int64_t q = 0; q < count; ++q) w.writeFast(first + size_t(q), dx[q], dy[q], dz[q]);
}

#endif

template void blendRowsAvx2<Fx32>(const Fx32*, const Fx32*, Fx32*, int64_t, int);
template void blendRowsAvx2<Fx16>(const Fx16*, const Fx16*, Fx16*, int64_t, int);
template void interpolateHalvesAvx2<Fx32>(const Fx32*, Fx32*, int64_t);
template void interpolateHalvesAvx2<Fx16>(const Fx16*, Fx16*, int64_t);
template void interpolateQuartersAvx2<Fx32>(const Fx32*, Fx32*, int64_t);
template void interpolateQuartersAvx2<Fx16>(const Fx16*, Fx16*, int64_t);
template void writePatchesAvx2<Fx32>(const PatchWriter<Fx32>&, size_t, const Fx32*, const Fx32*, const Fx32*, int64_t);
template void writePatchesAvx2<Fx16>(const PatchWriter<Fx16>&, size_t, const Fx16*, const Fx16*, const Fx16*, int64_t);

}  // namespace sg
