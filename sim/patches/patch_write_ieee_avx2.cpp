// The patch writes (PatchWriter::write, patch_state.h) for float and double in AVX2: eight or
// four patches per instruction, with the reference's bits. Each lane computes the reference's
// operations in its order (IEEE lanes: sim/particles/avx2_ieee.h), and every ternary becomes a
// blend on the same ordered comparison, which is false for NaN as the scalar `<` and `>` are: a NaN
// displacement gives the reference's NaN top and tilt 0, and signed zeros come out as they do
// there. Called only where the CPU has AVX2 (the world's kernel choice).
#include <cstring>

#include "sim/particles/avx2_ieee.h"
#include "sim/patches/patch_state.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace sg {

#if defined(__x86_64__)

namespace {

#define SG_AVX2_LANE __attribute__((target("avx2"), always_inline)) inline

/// The patch arrays' bytes in lanes of the scalar's width.
template <class F>
struct ByteLanes;
template <>
struct ByteLanes<float> {
  /// All ones in the lanes whose cut byte is set.
  SG_AVX2_LANE static __m256 cutMask(const uint8_t* cut) {
    const __m256i bytes = _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(cut)));
    return _mm256_castsi256_ps(_mm256_cmpgt_epi32(bytes, _mm256_setzero_si256()));
  }
  /// The tilt levels (0..3 in each lane, as integers) as one byte per patch.
  SG_AVX2_LANE static void storeTilt(uint8_t* out, __m256i tilt) {
    const __m128i words = _mm_packus_epi32(_mm256_castsi256_si128(tilt), _mm256_extracti128_si256(tilt, 1));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out), _mm_packus_epi16(words, words));
  }
};
template <>
struct ByteLanes<double> {
  SG_AVX2_LANE static __m256d cutMask(const uint8_t* cut) {
    int32_t four;
    std::memcpy(&four, cut, 4);
    const __m256i bytes = _mm256_cvtepu8_epi64(_mm_cvtsi32_si128(four));
    return _mm256_castsi256_pd(_mm256_cmpgt_epi64(bytes, _mm256_setzero_si256()));
  }
  SG_AVX2_LANE static void storeTilt(uint8_t* out, __m256i tilt) {
    // The four 64-bit lanes' low halves, then down to bytes.
    const __m256i low = _mm256_permutevar8x32_epi32(tilt, _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6));
    const __m128i words = _mm_packus_epi32(_mm256_castsi256_si128(low), _mm256_castsi256_si128(low));
    const int32_t four = _mm_cvtsi128_si32(_mm_packus_epi16(words, words));
    std::memcpy(out, &four, 4);
  }
};

template <class F>
__attribute__((target("avx2"))) int64_t writePatches(const PatchWriter<F>& w, size_t first, const F* dx, const F* dy,
                                                     const F* dz, int64_t count) {
  using L = avx2::IeeeLanes<F>;
  using B = ByteLanes<F>;
  using V = typename L::V;
  const V zero = L::all(F(0)), halfRod = L::all(w.halfRod), scaleY = L::all(w.scaleY);
  const V cutReduction = L::all(w.cutReduction), minimumTop = L::all(w.minimumTop);
  const V drop0 = L::all(w.drop0), drop1 = L::all(w.drop1), drop2 = L::all(w.drop2);
  const __m256i one = L::level(1), two = L::level(2), three = L::level(3);
  int64_t q = 0;
  for (; q + L::kCount <= count; q += L::kCount) {
    const size_t p = first + size_t(q);
    L::store(w.tipOffsetX + p, L::load(dx + q));
    L::store(w.tipOffsetZ + p, L::load(dz + q));
    const V sink = L::sub(zero, L::load(dy + q));
    // smaller = sink < 0 ? 0 : (sink > halfRod ? halfRod : sink)
    const V smaller = L::select(L::less(sink, zero), zero, L::select(L::greater(sink, halfRod), halfRod, sink));
    // top = scaleY - smaller - (cut ? cutReduction : 0); topY = rootY + (top < minimumTop ? minimumTop : top)
    const V top = L::sub(L::sub(scaleY, smaller), L::select(B::cutMask(w.cut + p), cutReduction, zero));
    L::store(w.topY + p, L::add(L::load(w.rootY + p), L::select(L::less(top, minimumTop), minimumTop, top)));
    // tilt = sink > drop2 ? 3 : sink > drop1 ? 2 : sink > drop0 ? 1 : 0, for any order of the drops
    __m256i tilt = _mm256_and_si256(L::bits(L::greater(sink, drop0)), one);
    tilt = _mm256_blendv_epi8(tilt, two, L::bits(L::greater(sink, drop1)));
    tilt = _mm256_blendv_epi8(tilt, three, L::bits(L::greater(sink, drop2)));
    B::storeTilt(w.tiltLevel + p, tilt);
  }
  return q;
}

template <class F>
void writeAll(const PatchWriter<F>& w, size_t first, const F* dx, const F* dy, const F* dz, int64_t count) {
  for (int64_t q = writePatches(w, first, dx, dy, dz, count); q < count; ++q)
    w.write(first + size_t(q), dx[q], dy[q], dz[q]);
}

}  // namespace

void writePatchesAvx2(const PatchWriter<float>& w, size_t first, const float* dx, const float* dy, const float* dz,
                      int64_t count) {
  writeAll(w, first, dx, dy, dz, count);
}
void writePatchesAvx2(const PatchWriter<double>& w, size_t first, const double* dx, const double* dy, const double* dz,
                      int64_t count) {
  writeAll(w, first, dx, dy, dz, count);
}

#else

void writePatchesAvx2(const PatchWriter<float>& w, size_t first, const float* dx, const float* dy, const float* dz,
                      int64_t count) {
  for (int64_t q = 0; q < count; ++q) w.write(first + size_t(q), dx[q], dy[q], dz[q]);
}
void writePatchesAvx2(const PatchWriter<double>& w, size_t first, const double* dx, const double* dy, const double* dz,
                      int64_t count) {
  for (int64_t q = 0; q < count; ++q) w.write(first + size_t(q), dx[q], dy[q], dz[q]);
}

#endif

}  // namespace sg
