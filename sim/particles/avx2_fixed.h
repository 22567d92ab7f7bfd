// Exact fixed-point arithmetic in AVX2 lanes, shared by the vector kernels of the particle pass
// (particle_row_avx2.cpp: the thesis and pbd models; blade_row_avx2.cpp: the blade model). Fx32
// holds one Q32.32 value per 64-bit lane (four particles), Fx16 one Q16.16 per 32-bit lane
// (eight). Every operation gives Fixed's bits or flags its lane "slow": a kernel then discards
// the whole block and runs the scalar reference on it (docs/performance.md, "Vector kernels").
//
//   * Products are formed on magnitudes from exact 32 x 32 -> 64 partial products (AVX2 has no
//     64-bit multiply) and rounded like Fixed::operator* (to nearest, ties away from zero).
//   * The rod projection's |d| and L / |d| are guessed in double (IEEE sqrt and division, used
//     only as guesses) and verified in exact integer arithmetic: len is isqrtNearest(n) iff
//     -len < n - len^2 <= len, and q is the rounded quotient of N by len iff
//     -len <= 2 (N - q len) < len. Both differences are small whenever the guess is within one,
//     so they are computed modulo the lane width from the low halves of the products.
//
// Internal to sim/: include only from a translation unit whose callers are target("avx2")
// functions reached after avx2KernelAvailable().
#pragma once

#if defined(__x86_64__)

#include <immintrin.h>

#include <cstdint>

#include "sim/math/scalar.h"

#define SG_AVX2_INLINE __attribute__((target("avx2"), always_inline)) inline

namespace sg::avx2 {

SG_AVX2_INLINE __m256i ones() { return _mm256_set1_epi64x(-1); }
SG_AVX2_INLINE __m256i all64(int64_t v) { return _mm256_set1_epi64x(v); }
SG_AVX2_INLINE __m256i all32(int32_t v) { return _mm256_set1_epi32(v); }

// ---- Fx32: four values per register ------------------------------------------------------------
namespace q32 {

/// A general product's operands must be below 2^47 in magnitude: |x y| / 2^32 < 2^62.
constexpr int kOperandBits = 47;
constexpr int64_t kMagicBits = 0x4338000000000000;  // the double 2^52 + 2^51
constexpr double kMagic = 6755399441055744.0;

SG_AVX2_INLINE __m256i load(const Fx32* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }
SG_AVX2_INLINE void store(Fx32* p, __m256i v) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v); }

/// 0 or -1 per lane.
SG_AVX2_INLINE __m256i signMask(__m256i x) { return _mm256_cmpgt_epi64(_mm256_setzero_si256(), x); }
SG_AVX2_INLINE __m256i applySign(__m256i magnitude, __m256i sign) {
  return _mm256_sub_epi64(_mm256_xor_si256(magnitude, sign), sign);
}
SG_AVX2_INLINE __m256i magnitude(__m256i x) { return applySign(x, signMask(x)); }

/// Why a block needs the reference: any set bit of `any`, or any set sign bit of `sign`
/// (overflow words and comparison masks go there without a shift).
struct Flags {
  __m256i any, sign;
  SG_AVX2_INLINE static Flags none() { return {_mm256_setzero_si256(), _mm256_setzero_si256()}; }
  SG_AVX2_INLINE void flag(__m256i bits) { any = _mm256_or_si256(any, bits); }
  SG_AVX2_INLINE void flagSign(__m256i bits) { sign = _mm256_or_si256(sign, bits); }
  SG_AVX2_INLINE bool clear() const {
    return _mm256_testz_si256(any, any) && _mm256_testz_si256(sign, _mm256_set1_epi64x(INT64_MIN));
  }
};

/// a + b; flags a signed overflow (where Fixed::operator+ faults).
SG_AVX2_INLINE __m256i addChecked(__m256i a, __m256i b, Flags& slow) {
  const __m256i r = _mm256_add_epi64(a, b);
  slow.flagSign(_mm256_and_si256(_mm256_xor_si256(a, r), _mm256_xor_si256(b, r)));
  return r;
}
SG_AVX2_INLINE __m256i subChecked(__m256i a, __m256i b, Flags& slow) {
  const __m256i r = _mm256_sub_epi64(a, b);
  slow.flagSign(_mm256_and_si256(_mm256_xor_si256(a, b), _mm256_xor_si256(a, r)));
  return r;
}

/// A non-negative multiplier split into 32-bit halves (lo: each lane's low half counts).
struct Multiplier {
  __m256i lo, hi;
};
SG_AVX2_INLINE Multiplier split(__m256i y) { return {y, _mm256_srli_epi64(y, 32)}; }

/// x * y rounded like Fixed::operator* (to nearest, ties away from zero), for 0 <= y < 2^47.
/// |x| |y| = p3 2^64 + (p1 + p2) 2^32 + p0, so (|x| |y| + 2^31) >> 32 carries only from p0.
/// Wide: flags |x| >= 2^47 (then the result stays below 2^62). Narrow (y < 2^32, p2 = p3 = 0):
/// exact for every x, because the result is smaller than |x| <= 2^63: nothing to check.
template <bool Narrow>
SG_AVX2_INLINE __m256i mul(__m256i x, Multiplier y, Flags& slow) {
  const __m256i sign = signMask(x);
  const __m256i ax = applySign(x, sign);  // |x|; INT64_MIN gives 2^63, exact as unsigned
  const __m256i xh = _mm256_srli_epi64(ax, 32);
  const __m256i p0 = _mm256_mul_epu32(ax, y.lo);
  const __m256i p1 = _mm256_mul_epu32(xh, y.lo);
  const __m256i rounded = _mm256_srli_epi64(_mm256_add_epi64(p0, all64(int64_t(1) << 31)), 32);
  if constexpr (Narrow) return applySign(_mm256_add_epi64(p1, rounded), sign);
  slow.flag(_mm256_srli_epi64(ax, kOperandBits));
  const __m256i p2 = _mm256_mul_epu32(ax, y.hi);
  const __m256i p3 = _mm256_mul_epu32(xh, y.hi);
  const __m256i m = _mm256_add_epi64(_mm256_add_epi64(_mm256_slli_epi64(p3, 32), _mm256_add_epi64(p1, p2)), rounded);
  return applySign(m, sign);
}

/// x^2 mod 2^64 for x >= 0 (x^2 = xl^2 + 2 xl xh 2^32 + xh^2 2^64).
SG_AVX2_INLINE __m256i squareLow(__m256i x) {
  return _mm256_add_epi64(_mm256_mul_epu32(x, x), _mm256_slli_epi64(_mm256_mul_epu32(x, _mm256_srli_epi64(x, 32)), 33));
}
/// a b mod 2^64 for a, b >= 0.
SG_AVX2_INLINE __m256i productLow(__m256i a, __m256i b) {
  const __m256i cross =
      _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(a, 32), b), _mm256_mul_epu32(a, _mm256_srli_epi64(b, 32)));
  return _mm256_add_epi64(_mm256_mul_epu32(a, b), _mm256_slli_epi64(cross, 32));
}

/// Exact for |x| < 2^51 (AVX2 has no 64-bit integer conversions).
SG_AVX2_INLINE __m256d toDouble(__m256i x) {
  return _mm256_sub_pd(_mm256_castsi256_pd(_mm256_add_epi64(x, all64(kMagicBits))), _mm256_set1_pd(kMagic));
}
/// An integer near 0 <= d < 2^51 (how it rounds does not matter: it is a guess).
SG_AVX2_INLINE __m256i toIntegerGuess(__m256d d) {
  return _mm256_sub_epi64(_mm256_castpd_si256(_mm256_add_pd(d, _mm256_set1_pd(kMagic))), all64(kMagicBits));
}

/// x * y for any signs, rounded like Fixed::operator* (whose rounding is symmetric, so
/// x y = sign(y) (x |y|)). Flags |x| or |y| >= 2^47.
SG_AVX2_INLINE __m256i mulSigned(__m256i x, __m256i y, Flags& slow) {
  const __m256i sign = signMask(y);
  const __m256i ay = applySign(y, sign);
  slow.flag(_mm256_srli_epi64(ay, kOperandBits));  // also INT64_MIN, whose magnitude is 2^63
  return applySign(mul<false>(x, split(ay), slow), sign);
}

/// What projecting onto a rod of length L needs: Fixed::operator/ divides N = L 2^32 by |d|.
struct RodDivision {
  __m256i numeratorLow;  ///< N mod 2^64
  __m256d numerator;     ///< N as a double, exact (L < 2^47)
};
SG_AVX2_INLINE RodDivision rodDivision(int64_t rodRaw) {
  return {_mm256_set1_epi64x(int64_t(uint64_t(rodRaw) << 32)), _mm256_set1_pd(double(rodRaw) * 4294967296.0)};
}

struct Offsets {
  __m256i x, y, z;
};

/// The rod projection's offset d (L / |d|), as rod_constraint.h computes it:
/// scale = L / length3(d), then d * scale per axis. Flags d = 0 (the reference puts the tip
/// upright) and every lane whose guesses it cannot verify.
SG_AVX2_INLINE Offsets scaleToRod(__m256i dx, __m256i dy, __m256i dz, const RodDivision& rod, Flags& slow) {
  // The products d * scale at the end flag |d| >= 2^47, which also covers the double
  // conversions here (exact below 2^51): a block with a larger d is discarded whatever its
  // guesses were.
  // len = isqrtNearest(n), n = dx^2 + dy^2 + dz^2: a double guess, then -len < n - len^2 <= len.
  // With the guess within one, |n - len^2| <= 2 len + 1 < 2^50: exact modulo 2^64.
  const __m256d ddx = toDouble(dx), ddy = toDouble(dy), ddz = toDouble(dz);
  const __m256d sumSquares =
      _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(ddx, ddx), _mm256_mul_pd(ddy, ddy)), _mm256_mul_pd(ddz, ddz));
  const __m256i len = toIntegerGuess(_mm256_sqrt_pd(sumSquares));
  const __m256i negLen = _mm256_sub_epi64(_mm256_setzero_si256(), len);
  const __m256i n =
      _mm256_add_epi64(_mm256_add_epi64(squareLow(magnitude(dx)), squareLow(magnitude(dy))), squareLow(magnitude(dz)));
  const __m256i excess = _mm256_sub_epi64(n, squareLow(len));
  slow.flagSign(_mm256_xor_si256(_mm256_cmpgt_epi64(excess, negLen), ones()));  // also len = 0 (d = 0: upright)
  slow.flagSign(_mm256_cmpgt_epi64(excess, len));
  // scale = round(N / len): a double guess, then -len <= 2 (N - scale len) < len (ties round
  // up, as divRound does for positive values). The guess must stay below 2^47, where the magic
  // conversion is exact and the modular remainder provably small; no test reaches that check
  // (a larger scale needs len < L / 2^15, where the products stay exact anyway), but the proof
  // needs it.
  const __m256d scaleGuess = _mm256_div_pd(rod.numerator, toDouble(len));
  slow.flagSign(_mm256_castpd_si256(_mm256_cmp_pd(scaleGuess, _mm256_set1_pd(0x1p47), _CMP_NLT_UQ)));
  const __m256i scale = toIntegerGuess(scaleGuess);
  const __m256i twiceRemainder = _mm256_slli_epi64(_mm256_sub_epi64(rod.numeratorLow, productLow(scale, len)), 1);
  slow.flagSign(_mm256_cmpgt_epi64(negLen, twiceRemainder));
  slow.flagSign(_mm256_xor_si256(_mm256_cmpgt_epi64(len, twiceRemainder), ones()));
  const Multiplier s = split(scale);
  return {mul<false>(dx, s, slow), mul<false>(dy, s, slow), mul<false>(dz, s, slow)};
}

}  // namespace q32

// ---- Fx16: eight values per register -----------------------------------------------------------
namespace q16 {

SG_AVX2_INLINE __m256i load(const Fx16* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }
SG_AVX2_INLINE void store(Fx16* p, __m256i v) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v); }

SG_AVX2_INLINE void flag(__m256i& slow, __m256i bits) { slow = _mm256_or_si256(slow, bits); }

/// a + b; flags a signed overflow.
SG_AVX2_INLINE __m256i addChecked(__m256i a, __m256i b, __m256i& slow) {
  const __m256i r = _mm256_add_epi32(a, b);
  flag(slow, _mm256_srai_epi32(_mm256_and_si256(_mm256_xor_si256(a, r), _mm256_xor_si256(b, r)), 31));
  return r;
}
SG_AVX2_INLINE __m256i subChecked(__m256i a, __m256i b, __m256i& slow) {
  const __m256i r = _mm256_sub_epi32(a, b);
  flag(slow, _mm256_srai_epi32(_mm256_and_si256(_mm256_xor_si256(a, b), _mm256_xor_si256(a, r)), 31));
  return r;
}

/// x * y rounded like Fixed::operator* for 0 <= y < 2^31 per lane: |x| y exactly in 64 bits
/// (even and odd lanes apart), + 2^15, >> 16. Flags a magnitude >= 2^31 (-2^31 itself would
/// fit: the reference handles that rare case).
SG_AVX2_INLINE __m256i mul(__m256i x, __m256i y, __m256i& slow) {
  const __m256i ax = _mm256_abs_epi32(x);  // INT32_MIN gives 2^31, exact as unsigned
  const __m256i bias = all64(int64_t(1) << 15);
  const __m256i even = _mm256_add_epi64(_mm256_mul_epu32(ax, y), bias);
  const __m256i odd = _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(ax, 32), _mm256_srli_epi64(y, 32)), bias);
  flag(slow, _mm256_srli_epi64(_mm256_or_si256(even, odd), 47));
  const __m256i m = _mm256_blend_epi32(_mm256_srli_epi64(even, 16), _mm256_slli_epi64(odd, 16), 0xAA);
  return _mm256_sign_epi32(m, x);  // x = 0 gives 0, which the product is
}

SG_AVX2_INLINE __m256d sumSquares(__m256d x, __m256d y, __m256d z) {
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(x, x), _mm256_mul_pd(y, y)), _mm256_mul_pd(z, z));
}
/// Four doubles (exact) from the low or the high four lanes.
SG_AVX2_INLINE __m256d lowToDouble(__m256i x) { return _mm256_cvtepi32_pd(_mm256_castsi256_si128(x)); }
SG_AVX2_INLINE __m256d highToDouble(__m256i x) { return _mm256_cvtepi32_pd(_mm256_extracti128_si256(x, 1)); }
/// Nearest integers, as guesses; out of the int32 range gives INT32_MIN.
SG_AVX2_INLINE __m256i toIntegerGuess(__m256d low, __m256d high) {
  return _mm256_inserti128_si256(_mm256_castsi128_si256(_mm256_cvtpd_epi32(low)), _mm256_cvtpd_epi32(high), 1);
}

/// x * y for any signs (Fixed's rounding is symmetric: x y = sign(y) (x |y|)). |y| = 2^31 (from
/// INT32_MIN) is exact in mul's unsigned partial products.
SG_AVX2_INLINE __m256i mulSigned(__m256i x, __m256i y, __m256i& slow) {
  return _mm256_sign_epi32(mul(x, _mm256_abs_epi32(y), slow), y);  // y = 0 gives 0, which the product is
}

/// What projecting onto a rod of length L needs: Fixed::operator/ divides N = L 2^16 by |d|.
struct RodDivision {
  __m256i numeratorLow;  ///< N mod 2^32
  __m256d numerator;     ///< N as a double, exact
};
SG_AVX2_INLINE RodDivision rodDivision(int32_t rodRaw) {
  const int64_t numerator = int64_t(rodRaw) << 16;
  return {_mm256_set1_epi32(int32_t(uint32_t(uint64_t(numerator)))), _mm256_set1_pd(double(numerator))};
}

struct Offsets {
  __m256i x, y, z;
};

/// The rod projection's offset d (L / |d|), as rod_constraint.h computes it. Flags d = 0 and
/// every lane whose guesses it cannot verify.
SG_AVX2_INLINE Offsets scaleToRod(__m256i dx, __m256i dy, __m256i dz, const RodDivision& rod, __m256i& slow) {
  // len = isqrtNearest(n): a double guess, then -len < n - len^2 <= len modulo 2^32 (mullo):
  // exact, because with the guess within one |n - len^2| <= 2 len + 1, and len < 2^29 (a
  // bound the proof needs; above it, 8 km, a wrong guess by one no longer moves the tip in
  // any test we could build).
  const __m256d lowSum = sumSquares(lowToDouble(dx), lowToDouble(dy), lowToDouble(dz));
  const __m256d highSum = sumSquares(highToDouble(dx), highToDouble(dy), highToDouble(dz));
  const __m256i len = toIntegerGuess(_mm256_sqrt_pd(lowSum), _mm256_sqrt_pd(highSum));
  flag(slow, _mm256_srli_epi32(len, 29));  // also INT32_MIN, no guess
  const __m256i negLen = _mm256_sub_epi32(_mm256_setzero_si256(), len);
  const __m256i n = _mm256_add_epi32(_mm256_add_epi32(_mm256_mullo_epi32(dx, dx), _mm256_mullo_epi32(dy, dy)),
                                     _mm256_mullo_epi32(dz, dz));
  const __m256i excess = _mm256_sub_epi32(n, _mm256_mullo_epi32(len, len));
  flag(slow, _mm256_xor_si256(_mm256_cmpgt_epi32(excess, negLen), ones()));  // also len = 0 (d = 0: upright)
  flag(slow, _mm256_cmpgt_epi32(excess, len));
  // scale = round(N / len): a double guess, which must fit int32 as the reference's quotient
  // must (INT32_MIN otherwise), then -len <= 2 (N - scale len) < len modulo 2^32: exact,
  // because with the guess within one |N - scale len| <= len. (In Q16.16 the double quotient
  // of two exact integers misses only at exact ties, by rounding down: the lower bound is
  // never the one that fires, and is kept for the proof.)
  const __m256i scale =
      toIntegerGuess(_mm256_div_pd(rod.numerator, lowToDouble(len)), _mm256_div_pd(rod.numerator, highToDouble(len)));
  flag(slow, _mm256_srli_epi32(scale, 31));
  const __m256i twiceRemainder =
      _mm256_slli_epi32(_mm256_sub_epi32(rod.numeratorLow, _mm256_mullo_epi32(scale, len)), 1);
  flag(slow, _mm256_cmpgt_epi32(negLen, twiceRemainder));
  flag(slow, _mm256_xor_si256(_mm256_cmpgt_epi32(len, twiceRemainder), ones()));
  return {mul(dx, scale, slow), mul(dy, scale, slow), mul(dz, scale, slow)};
}

}  // namespace q16

}  // namespace sg::avx2

#endif  // __x86_64__
