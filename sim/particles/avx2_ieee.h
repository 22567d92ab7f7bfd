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
  /// All lanes of every argument finite (x - x is 0 for finite x, NaN for inf and NaN).
  SG_AVX2_IEEE static bool finite(V a, V b, V c) {
    const V sum = _mm256_add_ps(_mm256_add_ps(_mm256_sub_ps(a, a), _mm256_sub_ps(b, b)), _mm256_sub_ps(c, c));
    return _mm256_movemask_ps(_mm256_cmp_ps(sum, sum, _CMP_UNORD_Q)) == 0;
  }
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
  SG_AVX2_IEEE static bool finite(V a, V b, V c) {
    const V sum = _mm256_add_pd(_mm256_add_pd(_mm256_sub_pd(a, a), _mm256_sub_pd(b, b)), _mm256_sub_pd(c, c));
    return _mm256_movemask_pd(_mm256_cmp_pd(sum, sum, _CMP_UNORD_Q)) == 0;
  }
};

}  // namespace sg::avx2

#endif  // __x86_64__
