// markHeightBand and withinReachMask (grass_candidates.h): AVX2 loops for Fx32 (four 64-bit lanes)
// and Fx16 (eight 32-bit lanes) that give exactly the reference's answers: the same integer
// comparisons, four or eight at a time. One loop per function, over the lane type (Lanes64,
// Lanes32: the only difference is the width of the integer in each lane).
#include "sim/collision/grass_candidates.h"

#include <algorithm>
#include <type_traits>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace sg {

namespace {

template <class S>
void markReference(const S* py, int64_t begin, int64_t n, const HeightBand<S>& band, uint64_t* marks) {
  for (int64_t k = begin; k < n; ++k)
    if (band.marks(py[k])) marks[k / 64] |= uint64_t(1) << (k % 64);
}

#if defined(__x86_64__)

#define SG_AVX2 __attribute__((target("avx2"), always_inline)) inline

// The loads go through __m256i (a may-alias type): a run of Fixed is a run of its raw integers.
static_assert(sizeof(Fx32) == sizeof(int64_t) && sizeof(Fx16) == sizeof(int32_t), "a Fixed is its raw integer");

/// Fx32's lanes: four signed 64-bit integers.
struct Lanes64 {
  using S = Fx32;
  static constexpr int kWidth = 4;
  SG_AVX2 static __m256i all(int64_t v) { return _mm256_set1_epi64x(v); }
  SG_AVX2 static __m256i sub(__m256i a, __m256i b) { return _mm256_sub_epi64(a, b); }
  SG_AVX2 static __m256i greater(__m256i a, __m256i b) { return _mm256_cmpgt_epi64(a, b); }
  SG_AVX2 static __m256i magnitude(__m256i d) {  // the most negative integer stays negative
    const __m256i negative = _mm256_cmpgt_epi64(_mm256_setzero_si256(), d);
    return _mm256_sub_epi64(_mm256_xor_si256(d, negative), negative);
  }
  SG_AVX2 static uint64_t bits(__m256i m) { return uint32_t(_mm256_movemask_pd(_mm256_castsi256_pd(m))); }
  SG_AVX2 static __m256i first(int left) { return greater(all(left), _mm256_setr_epi64x(0, 1, 2, 3)); }
  SG_AVX2 static __m256i load(const S* p, __m256i lanes) {
    return _mm256_maskload_epi64(reinterpret_cast<const long long*>(p), lanes);
  }
};

/// Fx16's lanes: eight signed 32-bit integers.
struct Lanes32 {
  using S = Fx16;
  static constexpr int kWidth = 8;
  SG_AVX2 static __m256i all(int32_t v) { return _mm256_set1_epi32(v); }
  SG_AVX2 static __m256i sub(__m256i a, __m256i b) { return _mm256_sub_epi32(a, b); }
  SG_AVX2 static __m256i greater(__m256i a, __m256i b) { return _mm256_cmpgt_epi32(a, b); }
  SG_AVX2 static __m256i magnitude(__m256i d) { return _mm256_abs_epi32(d); }  // INT32_MIN stays negative
  SG_AVX2 static uint64_t bits(__m256i m) { return uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(m))); }
  SG_AVX2 static __m256i first(int left) { return greater(all(left), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)); }
  SG_AVX2 static __m256i load(const S* p, __m256i lanes) {
    return _mm256_maskload_epi32(reinterpret_cast<const int*>(p), lanes);
  }
};

/// Whole blocks of markHeightBand; returns the first particle not done (the tail goes to the
/// reference).
template <class L>
__attribute__((target("avx2"))) int64_t markBlocks(const typename L::S* py, int64_t n,
                                                   const HeightBand<typename L::S>& band, uint64_t* marks) {
  using Band = HeightBand<typename L::S>;
  const __m256i bottom = L::all(band.bottom), top = L::all(band.top);
  const __m256i bound = L::all(Band::kBound), negativeBound = L::all(-Band::kBound);
  int64_t k = 0;
  for (; k + L::kWidth <= n; k += L::kWidth) {
    const __m256i y = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(py + k));
    const __m256i inside = _mm256_and_si256(L::greater(y, bottom), L::greater(top, y));
    const __m256i beyond = _mm256_or_si256(L::greater(y, bound), L::greater(negativeBound, y));
    marks[k / 64] |= L::bits(_mm256_or_si256(inside, beyond)) << (k % 64);  // a block stays in one word
  }
  return k;
}

/// One axis of a block: the lanes whose |a - c| < reach. Sets the sign bit of *bad in a lane
/// where a - c overflowed (operands of opposite signs, the result's sign differing from a's) or
/// where its magnitude does not fit.
template <class L>
SG_AVX2 __m256i axisWithin(__m256i a, __m256i c, __m256i reach, __m256i* bad) {
  const __m256i d = L::sub(a, c);
  const __m256i magnitude = L::magnitude(d);
  *bad = _mm256_or_si256(*bad, _mm256_and_si256(_mm256_xor_si256(a, c), _mm256_xor_si256(a, d)));
  *bad = _mm256_or_si256(*bad, magnitude);
  return L::greater(reach, magnitude);
}

/// withinReachMask's loop. As withinReach, y first: x and z are formed only for blocks with a lane
/// inside on y (the reference forms them only for that lane; forming more can only decline more
/// often). Partial blocks load only their lanes (nothing past the run is read); the others count
/// neither as inside nor as faults.
template <class L>
__attribute__((target("avx2"))) bool reachBlocks(const typename L::S* px, const typename L::S* py,
                                                 const typename L::S* pz, int n, const Vec3<typename L::S>& c,
                                                 typename L::S reach, uint64_t* mask) {
  const __m256i vx = L::all(c.x().raw()), vy = L::all(c.y().raw()), vz = L::all(c.z().raw());
  const __m256i vr = L::all(reach.raw());
  __m256i bad = _mm256_setzero_si256();
  uint64_t bits = 0;
  for (int k = 0; k < n; k += L::kWidth) {
    const __m256i lanes = L::first(n - k);
    __m256i blockBad = _mm256_setzero_si256();
    __m256i inside = _mm256_and_si256(axisWithin<L>(L::load(py + k, lanes), vy, vr, &blockBad), lanes);
    if (!_mm256_testz_si256(inside, inside)) {
      inside = _mm256_and_si256(inside, axisWithin<L>(L::load(px + k, lanes), vx, vr, &blockBad));
      inside = _mm256_and_si256(inside, axisWithin<L>(L::load(pz + k, lanes), vz, vr, &blockBad));
    }
    bad = _mm256_or_si256(bad, _mm256_and_si256(lanes, blockBad));
    bits |= L::bits(inside) << k;
  }
  if (L::bits(bad) != 0) return false;
  *mask = bits;
  return true;
}

template <class S>
using LanesOf = std::conditional_t<std::is_same_v<S, Fx32>, Lanes64, Lanes32>;

#endif

}  // namespace

template <class S>
void markHeightBand(const S* py, int64_t n, const HeightBand<S>& band, ParticleKernel kernel, uint64_t* marks) {
  std::fill(marks, marks + (n + 63) / 64, uint64_t(band.everything ? ~uint64_t(0) : 0));
  if (band.everything) return;
  int64_t done = 0;
#if defined(__x86_64__)
  if (kernel == ParticleKernel::Avx2 && avx2KernelAvailable()) done = markBlocks<LanesOf<S>>(py, n, band, marks);
#else
  (void)kernel;
#endif
  markReference(py, done, n, band, marks);
}

template <class S>
bool withinReachMask(const S* px, const S* py, const S* pz, int n, const Vec3<S>& c, S reach, uint64_t* mask) {
#if defined(__x86_64__)
  return avx2KernelAvailable() && reachBlocks<LanesOf<S>>(px, py, pz, n, c, reach, mask);
#else
  (void)px, (void)py, (void)pz, (void)n, (void)c, (void)reach, (void)mask;
  return false;
#endif
}

template void markHeightBand<Fx32>(const Fx32*, int64_t, const HeightBand<Fx32>&, ParticleKernel, uint64_t*);
template void markHeightBand<Fx16>(const Fx16*, int64_t, const HeightBand<Fx16>&, ParticleKernel, uint64_t*);
template bool withinReachMask<Fx32>(const Fx32*, const Fx32*, const Fx32*, int, const Vec3<Fx32>&, Fx32, uint64_t*);
template bool withinReachMask<Fx16>(const Fx16*, const Fx16*, const Fx16*, int, const Vec3<Fx16>&, Fx16, uint64_t*);

}  // namespace sg
