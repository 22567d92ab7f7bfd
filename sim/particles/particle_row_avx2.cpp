// The fused particle pass (particle_row.h) for Fx32 and Fx16 in AVX2, with the reference's
// exact bits: Fx32 four particles per block (one Q32.32 value per 64-bit lane), Fx16 eight
// (one Q16.16 value per 32-bit lane).
//
// How it stays exact (docs/performance.md, "Vector kernels"):
//   * Products are formed on magnitudes from exact 32 x 32 -> 64 partial products (AVX2 has no
//     64-bit multiply) and rounded like Fixed::operator* (to nearest, ties away from zero).
//     Where a product could leave the format, its operand or its result is checked.
//   * |d| and L / |d| are guessed in double (IEEE sqrt and division, used only as guesses) and
//     verified in exact integer arithmetic: len is isqrtNearest(n) iff -len < n - len^2 <= len,
//     and q is the rounded quotient of N by len iff -len <= 2 (N - q len) < len. Both
//     differences are small whenever the guess is within one, so they are computed modulo the
//     lane width from the low halves of the products.
//   * Every check ORs into a `slow` mask. A block with any lane flagged writes nothing and is
//     recomputed by the scalar reference from the untouched memory, so faults, rare rounding
//     cases and anything out of range get the reference's bits and its fault report.
// A guess that is off only costs a block its speed, never its bits. The functions carry
// target("avx2") and are called only when the CPU has AVX2 (particle_row.h picks the kernel).
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <type_traits>

#include "sim/particles/particle_row.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace sg {

const char* particleKernelName(ParticleKernel kernel) { return kernel == ParticleKernel::Avx2 ? "avx2" : "scalar"; }

#if defined(__x86_64__)

bool avx2KernelAvailable() {
  static const bool available = __builtin_cpu_supports("avx2");
  return available;
}

namespace {

#define SG_AVX2 __attribute__((target("avx2"), always_inline)) inline

SG_AVX2 __m256i ones() { return _mm256_set1_epi64x(-1); }
SG_AVX2 __m256i all64(int64_t v) { return _mm256_set1_epi64x(v); }
SG_AVX2 __m256i all32(int32_t v) { return _mm256_set1_epi32(v); }

// ---- Fx32: four particles per block ---------------------------------------------------------
namespace q32 {

/// A general product's operands must be below 2^47 in magnitude: |x y| / 2^32 < 2^62.
constexpr int kOperandBits = 47;
constexpr int64_t kMagicBits = 0x4338000000000000;  // the double 2^52 + 2^51
constexpr double kMagic = 6755399441055744.0;

SG_AVX2 __m256i load(const Fx32* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }
SG_AVX2 void store(Fx32* p, __m256i v) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v); }

/// 0 or -1 per lane.
SG_AVX2 __m256i signMask(__m256i x) { return _mm256_cmpgt_epi64(_mm256_setzero_si256(), x); }
SG_AVX2 __m256i applySign(__m256i magnitude, __m256i sign) {
  return _mm256_sub_epi64(_mm256_xor_si256(magnitude, sign), sign);
}
SG_AVX2 __m256i magnitude(__m256i x) { return applySign(x, signMask(x)); }

/// Why a block needs the reference: any set bit of `any`, or any set sign bit of `sign`
/// (overflow words and comparison masks go there without a shift).
struct Flags {
  __m256i any, sign;
  SG_AVX2 static Flags none() { return {_mm256_setzero_si256(), _mm256_setzero_si256()}; }
  SG_AVX2 void flag(__m256i bits) { any = _mm256_or_si256(any, bits); }
  SG_AVX2 void flagSign(__m256i bits) { sign = _mm256_or_si256(sign, bits); }
  SG_AVX2 bool clear() const {
    return _mm256_testz_si256(any, any) && _mm256_testz_si256(sign, _mm256_set1_epi64x(INT64_MIN));
  }
};

/// a + b; flags a signed overflow (where Fixed::operator+ faults).
SG_AVX2 __m256i addChecked(__m256i a, __m256i b, Flags& slow) {
  const __m256i r = _mm256_add_epi64(a, b);
  slow.flagSign(_mm256_and_si256(_mm256_xor_si256(a, r), _mm256_xor_si256(b, r)));
  return r;
}
SG_AVX2 __m256i subChecked(__m256i a, __m256i b, Flags& slow) {
  const __m256i r = _mm256_sub_epi64(a, b);
  slow.flagSign(_mm256_and_si256(_mm256_xor_si256(a, b), _mm256_xor_si256(a, r)));
  return r;
}

/// A non-negative multiplier split into 32-bit halves (lo: each lane's low half counts).
struct Multiplier {
  __m256i lo, hi;
};
SG_AVX2 Multiplier split(__m256i y) { return {y, _mm256_srli_epi64(y, 32)}; }

/// x * y rounded like Fixed::operator* (to nearest, ties away from zero), for 0 <= y < 2^47.
/// |x| |y| = p3 2^64 + (p1 + p2) 2^32 + p0, so (|x| |y| + 2^31) >> 32 carries only from p0.
/// Wide: flags |x| >= 2^47 (then the result stays below 2^62). Narrow (y < 2^32, p2 = p3 = 0):
/// exact for every x, because the result is smaller than |x| <= 2^63: nothing to check.
template <bool Narrow>
SG_AVX2 __m256i mul(__m256i x, Multiplier y, Flags& slow) {
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
SG_AVX2 __m256i squareLow(__m256i x) {
  return _mm256_add_epi64(_mm256_mul_epu32(x, x), _mm256_slli_epi64(_mm256_mul_epu32(x, _mm256_srli_epi64(x, 32)), 33));
}
/// a b mod 2^64 for a, b >= 0.
SG_AVX2 __m256i productLow(__m256i a, __m256i b) {
  const __m256i cross =
      _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(a, 32), b), _mm256_mul_epu32(a, _mm256_srli_epi64(b, 32)));
  return _mm256_add_epi64(_mm256_mul_epu32(a, b), _mm256_slli_epi64(cross, 32));
}

/// Exact for |x| < 2^51 (AVX2 has no 64-bit integer conversions).
SG_AVX2 __m256d toDouble(__m256i x) {
  return _mm256_sub_pd(_mm256_castsi256_pd(_mm256_add_epi64(x, all64(kMagicBits))), _mm256_set1_pd(kMagic));
}
/// An integer near 0 <= d < 2^51 (how it rounds does not matter: it is a guess).
SG_AVX2 __m256i toIntegerGuess(__m256d d) {
  return _mm256_sub_epi64(_mm256_castpd_si256(_mm256_add_pd(d, _mm256_set1_pd(kMagic))), all64(kMagicBits));
}

struct RowConstants {
  Multiplier dt, damping, invDt;
  __m256i dvx, dvy, dvz, rod;
  __m256i numeratorLow;  ///< N = L 2^32 (what Fixed::operator/ divides by |d|) mod 2^64
  __m256d numerator;     ///< N as a double, exact (L < 2^47)
};

/// Whether dt and damping^dt are below 1 (raw < 2^32), as in every scenario so far: their
/// products then need two partial products instead of four, and no check.
inline bool narrowStepConstants(const ParticleConstants<Fx32>& c) {
  return (uint64_t(c.dt.raw()) >> 32) == 0 && (uint64_t(c.dampingPerTick.raw()) >> 32) == 0;
}

/// False when a constant is outside what the kernel handles (the row then runs the reference).
__attribute__((target("avx2"))) bool makeRowConstants(const ParticleConstants<Fx32>& c, Fx32 dvx, Fx32 dvy, Fx32 dvz,
                                                      RowConstants& k) {
  const auto fits = [](int64_t v) { return v >= 0 && (uint64_t(v) >> kOperandBits) == 0; };  // no intrinsics here
  const int64_t rod = c.rodLength.raw();
  if (!fits(c.dt.raw()) || !fits(c.dampingPerTick.raw()) || !fits(c.invDt.raw()) || rod <= 0 || !fits(rod))
    return false;
  k.dt = split(all64(c.dt.raw()));
  k.damping = split(all64(c.dampingPerTick.raw()));
  k.invDt = split(all64(c.invDt.raw()));
  k.dvx = all64(dvx.raw());
  k.dvy = all64(dvy.raw());
  k.dvz = all64(dvz.raw());
  k.rod = all64(rod);
  k.numeratorLow = all64(int64_t(uint64_t(rod) << 32));
  k.numerator = _mm256_set1_pd(double(rod) * 4294967296.0);
  return true;
}

/// Particles [i, i + 4). Returns false, having written nothing, when a lane needs the reference.
template <bool Pbd, bool Narrow>
__attribute__((target("avx2"))) bool advanceBlock(ParticleArrays<Fx32>& p, int64_t i, const RowConstants& k, Fx32* outX,
                                                  Fx32* outY, Fx32* outZ) {
  Flags slow = Flags::none();
  __m256i px = load(&p.px[i]), py = load(&p.py[i]), pz = load(&p.pz[i]);
  __m256i vx = load(&p.vx[i]), vy = load(&p.vy[i]), vz = load(&p.vz[i]);

  // Integration (integrate.h): thesis order p += v dt; v = (v + dv) damping, or symplectic.
  if constexpr (!Pbd) {
    px = addChecked(px, mul<Narrow>(vx, k.dt, slow), slow);
    py = addChecked(py, mul<Narrow>(vy, k.dt, slow), slow);
    pz = addChecked(pz, mul<Narrow>(vz, k.dt, slow), slow);
  }
  vx = mul<Narrow>(addChecked(vx, k.dvx, slow), k.damping, slow);
  vy = mul<Narrow>(addChecked(vy, k.dvy, slow), k.damping, slow);
  vz = mul<Narrow>(addChecked(vz, k.dvz, slow), k.damping, slow);
  if constexpr (Pbd) {
    px = addChecked(px, mul<Narrow>(vx, k.dt, slow), slow);
    py = addChecked(py, mul<Narrow>(vy, k.dt, slow), slow);
    pz = addChecked(pz, mul<Narrow>(vz, k.dt, slow), slow);
  }

  // Rod projection (rod_constraint.h): d = p - anchor; p = anchor + d (L / |d|). The products
  // d * scale below flag |d| >= 2^47, which also covers the double conversions here (exact
  // below 2^51): a block with a larger d is discarded whatever its guesses were.
  const __m256i ax = load(&p.anchorX[i]), ay = load(&p.anchorY[i]), az = load(&p.anchorZ[i]);
  const __m256i dx = subChecked(px, ax, slow), dy = subChecked(py, ay, slow), dz = subChecked(pz, az, slow);
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
  const __m256d scaleGuess = _mm256_div_pd(k.numerator, toDouble(len));
  slow.flagSign(_mm256_castpd_si256(_mm256_cmp_pd(scaleGuess, _mm256_set1_pd(0x1p47), _CMP_NLT_UQ)));
  const __m256i scale = toIntegerGuess(scaleGuess);
  const __m256i twiceRemainder = _mm256_slli_epi64(_mm256_sub_epi64(k.numeratorLow, productLow(scale, len)), 1);
  slow.flagSign(_mm256_cmpgt_epi64(negLen, twiceRemainder));
  slow.flagSign(_mm256_xor_si256(_mm256_cmpgt_epi64(len, twiceRemainder), ones()));

  const Multiplier s = split(scale);
  const __m256i offX = mul<false>(dx, s, slow), offY = mul<false>(dy, s, slow), offZ = mul<false>(dz, s, slow);
  const __m256i nx = addChecked(ax, offX, slow), ny = addChecked(ay, offY, slow), nz = addChecked(az, offZ, slow);
  if constexpr (Pbd) {  // v += (p_new - p) / dt
    vx = addChecked(vx, mul<false>(subChecked(nx, px, slow), k.invDt, slow), slow);
    vy = addChecked(vy, mul<false>(subChecked(ny, py, slow), k.invDt, slow), slow);
    vz = addChecked(vz, mul<false>(subChecked(nz, pz, slow), k.invDt, slow), slow);
  }
  if (!slow.clear()) return false;

  store(&p.px[i], nx);
  store(&p.py[i], ny);
  store(&p.pz[i], nz);
  store(&p.vx[i], vx);
  store(&p.vy[i], vy);
  store(&p.vz[i], vz);
  // Tip displacement p - anchor - (0, L, 0) (patch_state.h): exactly the offset d * scale.
  store(outX + i, offX);
  store(outY + i, _mm256_sub_epi64(offY, k.rod));
  store(outZ + i, offZ);
  return true;
}

}  // namespace q32

// ---- Fx16: eight particles per block --------------------------------------------------------
namespace q16 {

SG_AVX2 __m256i load(const Fx16* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }
SG_AVX2 void store(Fx16* p, __m256i v) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v); }

SG_AVX2 void flag(__m256i& slow, __m256i bits) { slow = _mm256_or_si256(slow, bits); }

/// a + b; flags a signed overflow.
SG_AVX2 __m256i addChecked(__m256i a, __m256i b, __m256i& slow) {
  const __m256i r = _mm256_add_epi32(a, b);
  flag(slow, _mm256_srai_epi32(_mm256_and_si256(_mm256_xor_si256(a, r), _mm256_xor_si256(b, r)), 31));
  return r;
}
SG_AVX2 __m256i subChecked(__m256i a, __m256i b, __m256i& slow) {
  const __m256i r = _mm256_sub_epi32(a, b);
  flag(slow, _mm256_srai_epi32(_mm256_and_si256(_mm256_xor_si256(a, b), _mm256_xor_si256(a, r)), 31));
  return r;
}

/// x * y rounded like Fixed::operator* for 0 <= y < 2^31 per lane: |x| y exactly in 64 bits
/// (even and odd lanes apart), + 2^15, >> 16. Flags a magnitude >= 2^31 (-2^31 itself would
/// fit: the reference handles that rare case).
SG_AVX2 __m256i mul(__m256i x, __m256i y, __m256i& slow) {
  const __m256i ax = _mm256_abs_epi32(x);  // INT32_MIN gives 2^31, exact as unsigned
  const __m256i bias = all64(int64_t(1) << 15);
  const __m256i even = _mm256_add_epi64(_mm256_mul_epu32(ax, y), bias);
  const __m256i odd = _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(ax, 32), _mm256_srli_epi64(y, 32)), bias);
  flag(slow, _mm256_srli_epi64(_mm256_or_si256(even, odd), 47));
  const __m256i m = _mm256_blend_epi32(_mm256_srli_epi64(even, 16), _mm256_slli_epi64(odd, 16), 0xAA);
  return _mm256_sign_epi32(m, x);  // x = 0 gives 0, which the product is
}

SG_AVX2 __m256d sumSquares(__m256d x, __m256d y, __m256d z) {
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(x, x), _mm256_mul_pd(y, y)), _mm256_mul_pd(z, z));
}
/// Four doubles (exact) from the low or the high four lanes.
SG_AVX2 __m256d lowToDouble(__m256i x) { return _mm256_cvtepi32_pd(_mm256_castsi256_si128(x)); }
SG_AVX2 __m256d highToDouble(__m256i x) { return _mm256_cvtepi32_pd(_mm256_extracti128_si256(x, 1)); }
/// Nearest integers, as guesses; out of the int32 range gives INT32_MIN.
SG_AVX2 __m256i toIntegerGuess(__m256d low, __m256d high) {
  return _mm256_inserti128_si256(_mm256_castsi128_si256(_mm256_cvtpd_epi32(low)), _mm256_cvtpd_epi32(high), 1);
}

struct RowConstants {
  __m256i dt, damping, invDt, dvx, dvy, dvz, rod;
  __m256i numeratorLow;  ///< N = L 2^16 (what Fixed::operator/ divides by |d|) mod 2^32
  __m256d numerator;     ///< N as a double, exact
};

__attribute__((target("avx2"))) bool makeRowConstants(const ParticleConstants<Fx16>& c, Fx16 dvx, Fx16 dvy, Fx16 dvz,
                                                      RowConstants& k) {
  const int32_t rod = c.rodLength.raw();
  if (c.dt.raw() < 0 || c.dampingPerTick.raw() < 0 || c.invDt.raw() < 0 || rod <= 0) return false;
  const int64_t numerator = int64_t(rod) << 16;
  k = RowConstants{all32(c.dt.raw()),
                   all32(c.dampingPerTick.raw()),
                   all32(c.invDt.raw()),
                   all32(dvx.raw()),
                   all32(dvy.raw()),
                   all32(dvz.raw()),
                   all32(rod),
                   all32(int32_t(uint32_t(uint64_t(numerator)))),
                   _mm256_set1_pd(double(numerator))};
  return true;
}

/// Particles [i, i + 8). Returns false, having written nothing, when a lane needs the reference.
template <bool Pbd>
__attribute__((target("avx2"))) bool advanceBlock(ParticleArrays<Fx16>& p, int64_t i, const RowConstants& k, Fx16* outX,
                                                  Fx16* outY, Fx16* outZ) {
  __m256i slow = _mm256_setzero_si256();  // any set bit: the block needs the reference
  __m256i px = load(&p.px[i]), py = load(&p.py[i]), pz = load(&p.pz[i]);
  __m256i vx = load(&p.vx[i]), vy = load(&p.vy[i]), vz = load(&p.vz[i]);

  if constexpr (!Pbd) {
    px = addChecked(px, mul(vx, k.dt, slow), slow);
    py = addChecked(py, mul(vy, k.dt, slow), slow);
    pz = addChecked(pz, mul(vz, k.dt, slow), slow);
  }
  vx = mul(addChecked(vx, k.dvx, slow), k.damping, slow);
  vy = mul(addChecked(vy, k.dvy, slow), k.damping, slow);
  vz = mul(addChecked(vz, k.dvz, slow), k.damping, slow);
  if constexpr (Pbd) {
    px = addChecked(px, mul(vx, k.dt, slow), slow);
    py = addChecked(py, mul(vy, k.dt, slow), slow);
    pz = addChecked(pz, mul(vz, k.dt, slow), slow);
  }

  const __m256i ax = load(&p.anchorX[i]), ay = load(&p.anchorY[i]), az = load(&p.anchorZ[i]);
  const __m256i dx = subChecked(px, ax, slow), dy = subChecked(py, ay, slow), dz = subChecked(pz, az, slow);
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
      toIntegerGuess(_mm256_div_pd(k.numerator, lowToDouble(len)), _mm256_div_pd(k.numerator, highToDouble(len)));
  flag(slow, _mm256_srli_epi32(scale, 31));
  const __m256i twiceRemainder = _mm256_slli_epi32(_mm256_sub_epi32(k.numeratorLow, _mm256_mullo_epi32(scale, len)), 1);
  flag(slow, _mm256_cmpgt_epi32(negLen, twiceRemainder));
  flag(slow, _mm256_xor_si256(_mm256_cmpgt_epi32(len, twiceRemainder), ones()));

  const __m256i offX = mul(dx, scale, slow), offY = mul(dy, scale, slow), offZ = mul(dz, scale, slow);
  const __m256i nx = addChecked(ax, offX, slow), ny = addChecked(ay, offY, slow), nz = addChecked(az, offZ, slow);
  if constexpr (Pbd) {
    vx = addChecked(vx, mul(subChecked(nx, px, slow), k.invDt, slow), slow);
    vy = addChecked(vy, mul(subChecked(ny, py, slow), k.invDt, slow), slow);
    vz = addChecked(vz, mul(subChecked(nz, pz, slow), k.invDt, slow), slow);
  }
  if (!_mm256_testz_si256(slow, slow)) return false;

  store(&p.px[i], nx);
  store(&p.py[i], ny);
  store(&p.pz[i], nz);
  store(&p.vx[i], vx);
  store(&p.vy[i], vy);
  store(&p.vz[i], vz);
  store(outX + i, offX);
  store(outY + i, _mm256_sub_epi32(offY, k.rod));  // wraps like unchecked::sub
  store(outZ + i, offZ);
  return true;
}

}  // namespace q16

// ---- one row ----------------------------------------------------------------------------------

template <class S>
struct Lanes;
template <>
struct Lanes<Fx32> {
  static constexpr int kBlock = 4;
  using Constants = q32::RowConstants;
};
template <>
struct Lanes<Fx16> {
  static constexpr int kBlock = 8;
  using Constants = q16::RowConstants;
};

template <class S, bool Pbd, bool Narrow>
__attribute__((target("avx2"))) RowFault advanceRow(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy,
                                                    S dvz, const ParticleConstants<S>& c, std::vector<S>& dx,
                                                    std::vector<S>& dy, std::vector<S>& dz) {
  constexpr int kBlock = Lanes<S>::kBlock;
  typename Lanes<S>::Constants k;
  bool handled;
  if constexpr (std::is_same_v<S, Fx32>)
    handled = q32::makeRowConstants(c, dvx, dvy, dvz, k);
  else
    handled = q16::makeRowConstants(c, dvx, dvy, dvz, k);
  if (ScalarTraits<S>::faultPending() || !handled)
    return advanceParticleRowScalar<S, Pbd>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
  int64_t i = begin;
  for (; i + kBlock <= end; i += kBlock) {
    bool done;
    if constexpr (std::is_same_v<S, Fx32>)
      done = q32::advanceBlock<Pbd, Narrow>(p, i, k, dx.data(), dy.data(), dz.data());
    else
      done = q16::advanceBlock<Pbd>(p, i, k, dx.data(), dy.data(), dz.data());
    if (done) continue;
    // The reference for this block. Particles are independent, so the state is the same as if
    // the whole row ran the reference; only a fault needs care: the reference integrates the
    // whole row before projecting any of it, so a projection fault here is reported only if
    // no later particle of the row faults in integration.
    const RowFault fault = advanceParticleRowScalar<S, Pbd>(p, i, i + kBlock, dvx, dvy, dvz, c, dx, dy, dz);
    if (fault.particle < 0) continue;
    if (fault.stage == Stage::Constraints) {
      // The reference would have stopped there with only that particle's fault bits.
      const uint32_t projectionFaults = takeFixedFaults();
      if (const int64_t at = integrateParticleRow<S, Pbd>(p, i + kBlock, end, dvx, dvy, dvz, c); at >= 0)
        return {at, Stage::Integrate};
      detail::raiseFixedFault(projectionFaults);
    }
    return fault;
  }
  return advanceParticleRowScalar<S, Pbd>(p, i, end, dvx, dvy, dvz, c, dx, dy, dz);
}

}  // namespace

// Not itself target("avx2"): GCC would take a differently targeted definition of a declared
// function for a multiversioned one. It only forwards.
template <class S, bool Pbd>
RowFault advanceParticleRowAvx2(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy, S dvz,
                                const ParticleConstants<S>& c, std::vector<S>& dx, std::vector<S>& dy,
                                std::vector<S>& dz) {
  if constexpr (std::is_same_v<S, Fx32>)
    if (q32::narrowStepConstants(c)) return advanceRow<S, Pbd, true>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
  return advanceRow<S, Pbd, false>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
}

#else  // no AVX2 on this architecture: the reference

bool avx2KernelAvailable() { return false; }

template <class S, bool Pbd>
RowFault advanceParticleRowAvx2(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy, S dvz,
                                const ParticleConstants<S>& c, std::vector<S>& dx, std::vector<S>& dy,
                                std::vector<S>& dz) {
  return advanceParticleRowScalar<S, Pbd>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
}

#endif

namespace {
// Process-wide choice for worlds built from now on (setDefaultParticleKernel); relaxed is enough:
// it is read when a world is built, and a world's kernel is fixed from then on.
std::atomic<uint8_t> gDefaultKernel{uint8_t(ParticleKernel::Avx2)};
}  // namespace

ParticleKernel defaultParticleKernel() {
  const auto wanted = ParticleKernel(gDefaultKernel.load(std::memory_order_relaxed));
  return wanted == ParticleKernel::Avx2 && avx2KernelAvailable() ? ParticleKernel::Avx2 : ParticleKernel::Scalar;
}

void setDefaultParticleKernel(ParticleKernel kernel) {
  gDefaultKernel.store(uint8_t(kernel), std::memory_order_relaxed);
}

#define SG_INSTANTIATE_AVX2_ROW(S, PBD)                                                                           \
  template RowFault advanceParticleRowAvx2<S, PBD>(ParticleArrays<S>&, int64_t, int64_t, S, S, S,                 \
                                                   const ParticleConstants<S>&, std::vector<S>&, std::vector<S>&, \
                                                   std::vector<S>&);
SG_INSTANTIATE_AVX2_ROW(Fx32, false)
SG_INSTANTIATE_AVX2_ROW(Fx32, true)
SG_INSTANTIATE_AVX2_ROW(Fx16, false)
SG_INSTANTIATE_AVX2_ROW(Fx16, true)

}  // namespace sg
