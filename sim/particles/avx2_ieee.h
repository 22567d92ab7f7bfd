// IEEE float and double lanes in AVX2, shared by the vector kernels for those scalars
// (particle_row_avx2.cpp's ieee namespace, patches/patch_write_ieee_avx2.cpp). Addition,
// subtraction, multiplication, division and square root are correctly rounded in a vector lane
// exactly as in a scalar register, and the build never contracts a product into an FMA
// (-ffp-contract=off), so a lane that runs the reference's operations in its order has its bits.
// Comparisons are the ordered ones (false for NaN), as C++'s < and > are.
//
// Internal to sim/: include only from translation units whose callers are target("avx2")
// functions reached after avx2KernelAvailable().
#pragma once

#if defined(__x86_64__)

#include <immintrin.h>

#define SG_AVX2_IEEE __attribute__((target("avx2"), always_inline)) inline

namespace sg::avx2 {

template <class F>
struct IeeeLanes;

template <>
struct IeeeLanes<float> {
  using V = __m256;
  static constexpr int kCount = 8;
  SG_AVX2_IEEE static V load(const float* p) { return _mm256_loadu_ps(p); }
  SG_AVX2_IEEE static void store(float* p, V v) { _mm256_storeu_ps(p, v); }
  SG_AVX2_IEEE static V all(float v) { return _mm256_set1_ps(v); }
  SG_AVX2_IEEE static V add(V a, V b) { return _mm256_add_ps(a, b); }
  SG_AVX2_IEEE static V sub(V a, V b) { return _mm256_sub_ps(a, b); }
  SG_AVX2_IEEE static V mul(V a, V b) { return _mm256_mul_ps(a, b); }
  SG_AVX2_IEEE static V div(V a, V b) { return _mm256_div_ps(a, b); }
  SG_AVX2_IEEE static V sqrt(V a) { return _mm256_sqrt_ps(a); }
  SG_AVX2_IEEE static V less(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }
  SG_AVX2_IEEE static V greater(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GT_OQ); }
  /// mask ? ifSet : ifClear, per lane.
  SG_AVX2_IEEE static V select(V mask, V ifSet, V ifClear) { return _mm256_blendv_ps(ifClear, ifSet, mask); }
  SG_AVX2_IEEE static __m256i bits(V v) { return _mm256_castps_si256(v); }
  /// An integer v in every lane of the lane width.
  SG_AVX2_IEEE static __m256i level(int v) { return _mm256_set1_epi32(v); }
};

template <>
struct IeeeLanes<double> {
  using V = __m256d;
  static constexpr int kCount = 4;
  SG_AVX2_IEEE static V load(const double* p) { return _mm256_loadu_pd(p); }
  SG_AVX2_IEEE static void store(double* p, V v) { _mm256_storeu_pd(p, v); }
  SG_AVX2_IEEE static V all(double v) { return _mm256_set1_pd(v); }
  SG_AVX2_IEEE static V add(V a, V b) { return _mm256_add_pd(a, b); }
  SG_AVX2_IEEE static V sub(V a, V b) { return _mm256_sub_pd(a, b); }
  SG_AVX2_IEEE static V mul(V a, V b) { return _mm256_mul_pd(a, b); }
  SG_AVX2_IEEE static V div(V a, V b) { return _mm256_div_pd(a, b); }
  SG_AVX2_IEEE static V sqrt(V a) { return _mm256_sqrt_pd(a); }
  SG_AVX2_IEEE static V less(V a, V b) { return _mm256_cmp_pd(a, b, _CMP_LT_OQ); }
  SG_AVX2_IEEE static V greater(V a, V b) { return _mm256_cmp_pd(a, b, _CMP_GT_OQ); }
  SG_AVX2_IEEE static V select(V mask, V ifSet, V ifClear) { return _mm256_blendv_pd(ifClear, ifSet, mask); }
  SG_AVX2_IEEE static __m256i bits(V v) { return _mm256_castpd_si256(v); }
  SG_AVX2_IEEE static __m256i level(int v) { return _mm256_set1_epi64x(v); }
  /// |a| <= limit per lane (an ordered compare: NaN fails it), all lanes of a mask, a and b.
  SG_AVX2_IEEE static V withinMagnitude(V a, V limit) {
    return _mm256_cmp_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), a), limit, _CMP_LE_OQ);
  }
  SG_AVX2_IEEE static V both(V a, V b) { return _mm256_and_pd(a, b); }
  SG_AVX2_IEEE static bool allLanes(V mask) { return _mm256_movemask_pd(mask) == 0xf; }
};

/// All lanes of a, b and c within a saved state's range, |x| <= 2^48 (FloatTraits::inStateRange):
/// an infinity and a NaN fail it too.
template <class W>
SG_AVX2_IEEE bool inStateRange(typename W::V a, typename W::V b, typename W::V c) {
  if constexpr (W::kCount == 8) {  // float
    // float: the magnitude's bits (sign cleared) order as the magnitudes do, and an infinity's or
    // a NaN's exceed every finite one's, so one integer maximum and one compare test all three:
    // as many operations as the finiteness test this replaced (the float tick's instruction count
    // is gated). 0x57800000 is 2^48's bits (exponent 127 + 48).
    const __m256i magnitude = _mm256_set1_epi32(0x7fffffff);
    const __m256i most = _mm256_max_epi32(_mm256_max_epi32(_mm256_and_si256(_mm256_castps_si256(a), magnitude),
                                                           _mm256_and_si256(_mm256_castps_si256(b), magnitude)),
                                          _mm256_and_si256(_mm256_castps_si256(c), magnitude));
    return _mm256_movemask_epi8(_mm256_cmpgt_epi32(most, _mm256_set1_epi32(0x57800000))) == 0;
  } else {
    const typename W::V limit = W::all(281474976710656.0);  // 2^48, exact in double
    return W::allLanes(
        W::both(W::both(W::withinMagnitude(a, limit), W::withinMagnitude(b, limit)), W::withinMagnitude(c, limit)));
  }
}

}  // namespace sg::avx2

#endif  // __x86_64__
