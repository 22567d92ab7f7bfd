// 128-bit integers for the fixed-point core and the exact rationals: sg::Int128 / sg::UInt128.
//
// Where the compiler has __int128 (GCC and Clang on 64-bit targets, Clang on wasm32) and
// SIMGRASS_PORTABLE_INT128 is not defined, they are plain aliases of the builtin types: x86-64
// code is exactly what it was (same types, same instructions). Elsewhere (i686, or any build defining
// SIMGRASS_PORTABLE_INT128) they are sg::portable::Int128 / UInt128: two unsigned 64-bit limbs
// with the builtin types' semantics, bit for bit, for every operation provided:
//   * + - * and << wrap modulo 2^128 (two's complement), like the builtin types in GCC/Clang;
//   * / and % truncate toward zero, the remainder has the dividend's sign;
//   * >> is arithmetic for Int128, logical for UInt128; & | ^ ~ on the bits;
//   * comparisons; explicit narrowing to a builtin integer is modular (C++20 rules);
//   * sg::addOverflow / sg::mulOverflow with the contract of __builtin_{add,mul}_overflow, and
//     sg::mulFull, the full 256-bit product (for both the builtin and the portable types);
//   * construction from a builtin integer is implicit and value-preserving (sign-extending), so
//     `x < 0`, `q += 1`, `2 * s` read as with the builtin types. Int128 <-> UInt128 is explicit
//     only: a mixed expression that the builtin types would silently convert to unsigned does
//     not compile, so it cannot differ silently either.
// The builtin preconditions stay preconditions (shift counts 0..127, divisor != 0, no MIN / -1);
// the portable code has no undefined behaviour even outside them: a count is taken modulo 128,
// x / 0 gives 0 and x % 0 gives x, MIN / -1 wraps to MIN.
//
// The portable types are always defined (also on x86-64), so tests/int128_test.cpp checks every
// operation against the builtin types, and Fixed<int64_t, portable::Int128, 32> against Fx32.
#pragma once

#include <bit>
#include <compare>
#include <cstdint>
#include <limits>
#include <type_traits>

#if defined(__SIZEOF_INT128__) && !defined(SIMGRASS_PORTABLE_INT128)
#define SIMGRASS_NATIVE_INT128 1
#else
#define SIMGRASS_NATIVE_INT128 0
#endif

namespace sg {
namespace portable {

class Int128;

namespace detail {
/// Builtin integer types (not bool), the ones the portable types convert from and to.
template <class I>
inline constexpr bool kIsBuiltinInt = std::is_integral_v<I> && !std::is_same_v<I, bool>;

struct Limbs {
  uint64_t hi, lo;
};

/// The high limb of a builtin integer widened to 128 bits (sign-extended when signed).
template <class I>
constexpr uint64_t highLimbOf(I v) noexcept {
  if constexpr (sizeof(I) > 8) {
    return static_cast<uint64_t>(static_cast<std::make_unsigned_t<I>>(v) >> 64);
  } else if constexpr (std::is_signed_v<I>) {
    return v < 0 ? ~uint64_t(0) : 0;
  } else {
    return 0;
  }
}

/// Full 64 x 64 -> 128-bit product from 32-bit halves: every partial product fits 64 bits.
constexpr Limbs mul64x64(uint64_t a, uint64_t b) noexcept {
  constexpr uint64_t kLow = 0xffffffffu;
  const uint64_t a0 = a & kLow, a1 = a >> 32, b0 = b & kLow, b1 = b >> 32;
  const uint64_t p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
  // The middle column collects three values below 2^32 each: it cannot overflow.
  const uint64_t mid = (p00 >> 32) + (p01 & kLow) + (p10 & kLow);
  return Limbs{p11 + (p01 >> 32) + (p10 >> 32) + (mid >> 32), (mid << 32) | (p00 & kLow)};
}

/// (u1:u0) / v for u1 < v (the quotient fits 64 bits), remainder to *r: Knuth's algorithm D
/// with 32-bit digits on a normalised divisor (Hacker's Delight, 2nd ed., fig. 9-3, divlu).
/// Each quotient digit's estimate is corrected at most twice; all arithmetic is 64-bit unsigned.
constexpr uint64_t divlu(uint64_t u1, uint64_t u0, uint64_t v, uint64_t* r) noexcept {
  constexpr uint64_t b = uint64_t(1) << 32;
  const int s = std::countl_zero(v);  // v != 0 (callers guarantee it), so s in 0..63
  v <<= s;
  const uint64_t vn1 = v >> 32, vn0 = v & (b - 1);
  // u1 < v before the shift, so u1 << s loses nothing; s == 0 must not shift u0 by 64.
  const uint64_t un32 = (u1 << s) | (s == 0 ? 0 : u0 >> (64 - s));
  const uint64_t un10 = u0 << s;
  const uint64_t un1 = un10 >> 32, un0 = un10 & (b - 1);
  uint64_t q1 = un32 / vn1, rhat = un32 - q1 * vn1;
  // q1 * vn0 is only evaluated once q1 < b, and b * rhat only while rhat < b: no overflow.
  while (q1 >= b || q1 * vn0 > b * rhat + un1) {
    --q1;
    rhat += vn1;
    if (rhat >= b) break;
  }
  const uint64_t un21 = un32 * b + un1 - q1 * v;  // exact modulo 2^64, and the true value is < v
  uint64_t q0 = un21 / vn1;
  rhat = un21 - q0 * vn1;
  while (q0 >= b || q0 * vn0 > b * rhat + un0) {
    --q0;
    rhat += vn1;
    if (rhat >= b) break;
  }
  *r = (un21 * b + un0 - q0 * v) >> s;
  return q1 * b + q0;
}
}  // namespace detail

/// Unsigned 128-bit integer as two 64-bit limbs (see the file comment for the semantics).
class UInt128 {
 public:
  constexpr UInt128() noexcept = default;
  /// Value-preserving for non-negative values; a negative value wraps modulo 2^128 (sign-extends).
  template <class I, std::enable_if_t<detail::kIsBuiltinInt<I>, int> = 0>
  constexpr UInt128(I v) noexcept  // NOLINT: implicit, like the builtin integer conversions
      : lo_(static_cast<uint64_t>(v)), hi_(detail::highLimbOf(v)) {}
  explicit constexpr UInt128(Int128 v) noexcept;  // modular, like static_cast
  static constexpr UInt128 fromLimbs(uint64_t hi, uint64_t lo) noexcept {
    UInt128 r;
    r.hi_ = hi;
    r.lo_ = lo;
    return r;
  }
  constexpr uint64_t hi() const noexcept { return hi_; }
  constexpr uint64_t lo() const noexcept { return lo_; }

  /// Modular narrowing to a builtin integer (C++20: conversion to a signed type is modular too).
  template <class I, std::enable_if_t<detail::kIsBuiltinInt<I>, int> = 0>
  explicit constexpr operator I() const noexcept {
    if constexpr (sizeof(I) > 8) {
      using U = std::make_unsigned_t<I>;
      return static_cast<I>((static_cast<U>(hi_) << 64) | lo_);
    } else {
      return static_cast<I>(lo_);
    }
  }
  explicit constexpr operator bool() const noexcept { return (hi_ | lo_) != 0; }

  friend constexpr UInt128 operator+(UInt128 a, UInt128 b) noexcept {
    const uint64_t lo = a.lo_ + b.lo_;
    return fromLimbs(a.hi_ + b.hi_ + (lo < a.lo_ ? 1 : 0), lo);
  }
  friend constexpr UInt128 operator-(UInt128 a, UInt128 b) noexcept {
    return fromLimbs(a.hi_ - b.hi_ - (a.lo_ < b.lo_ ? 1 : 0), a.lo_ - b.lo_);
  }
  friend constexpr UInt128 operator-(UInt128 a) noexcept { return UInt128() - a; }
  friend constexpr UInt128 operator+(UInt128 a) noexcept { return a; }
  friend constexpr UInt128 operator~(UInt128 a) noexcept { return fromLimbs(~a.hi_, ~a.lo_); }
  friend constexpr UInt128 operator*(UInt128 a, UInt128 b) noexcept {
    // Low 128 bits of the product: the a.hi * b.hi term and the cross terms' high halves fall
    // off the top.
    const detail::Limbs p = detail::mul64x64(a.lo_, b.lo_);
    return fromLimbs(p.hi + a.lo_ * b.hi_ + a.hi_ * b.lo_, p.lo);
  }
  friend constexpr UInt128 operator/(UInt128 a, UInt128 b) noexcept {
    UInt128 r;
    return divMod(a, b, &r);
  }
  friend constexpr UInt128 operator%(UInt128 a, UInt128 b) noexcept {
    UInt128 r;
    divMod(a, b, &r);
    return r;
  }
  friend constexpr UInt128 operator&(UInt128 a, UInt128 b) noexcept { return fromLimbs(a.hi_ & b.hi_, a.lo_ & b.lo_); }
  friend constexpr UInt128 operator|(UInt128 a, UInt128 b) noexcept { return fromLimbs(a.hi_ | b.hi_, a.lo_ | b.lo_); }
  friend constexpr UInt128 operator^(UInt128 a, UInt128 b) noexcept { return fromLimbs(a.hi_ ^ b.hi_, a.lo_ ^ b.lo_); }
  friend constexpr UInt128 operator<<(UInt128 a, int n) noexcept {
    n &= 127;
    if (n == 0) return a;
    if (n >= 64) return fromLimbs(a.lo_ << (n - 64), 0);
    return fromLimbs((a.hi_ << n) | (a.lo_ >> (64 - n)), a.lo_ << n);
  }
  friend constexpr UInt128 operator>>(UInt128 a, int n) noexcept {
    n &= 127;
    if (n == 0) return a;
    if (n >= 64) return fromLimbs(0, a.hi_ >> (n - 64));
    return fromLimbs(a.hi_ >> n, (a.lo_ >> n) | (a.hi_ << (64 - n)));
  }
  friend constexpr bool operator==(UInt128 a, UInt128 b) noexcept { return a.hi_ == b.hi_ && a.lo_ == b.lo_; }
  friend constexpr std::strong_ordering operator<=>(UInt128 a, UInt128 b) noexcept {
    return a.hi_ != b.hi_ ? a.hi_ <=> b.hi_ : a.lo_ <=> b.lo_;
  }

  constexpr UInt128& operator+=(UInt128 b) noexcept { return *this = *this + b; }
  constexpr UInt128& operator-=(UInt128 b) noexcept { return *this = *this - b; }
  constexpr UInt128& operator*=(UInt128 b) noexcept { return *this = *this * b; }
  constexpr UInt128& operator/=(UInt128 b) noexcept { return *this = *this / b; }
  constexpr UInt128& operator%=(UInt128 b) noexcept { return *this = *this % b; }
  constexpr UInt128& operator&=(UInt128 b) noexcept { return *this = *this & b; }
  constexpr UInt128& operator|=(UInt128 b) noexcept { return *this = *this | b; }
  constexpr UInt128& operator<<=(int n) noexcept { return *this = *this << n; }
  constexpr UInt128& operator>>=(int n) noexcept { return *this = *this >> n; }

  /// Quotient and remainder (*rem) of the exact division n / d; d == 0 gives 0 remainder n.
  static constexpr UInt128 divMod(UInt128 n, UInt128 d, UInt128* rem) noexcept {
    if (d.hi_ == 0) {
      if (d.lo_ == 0) {
        *rem = n;
        return UInt128();
      }
      uint64_t r = 0;
      if (n.hi_ < d.lo_) {  // one 128/64 step: the quotient fits 64 bits
        const uint64_t q = detail::divlu(n.hi_, n.lo_, d.lo_, &r);
        *rem = UInt128(r);
        return UInt128(q);
      }
      // Two steps: the high limb by itself, then (its remainder : low limb), which is < d * 2^64.
      const uint64_t qHi = n.hi_ / d.lo_;
      const uint64_t qLo = detail::divlu(n.hi_ % d.lo_, n.lo_, d.lo_, &r);
      *rem = UInt128(r);
      return fromLimbs(qHi, qLo);
    }
    if (n < d) {
      *rem = n;
      return UInt128();
    }
    // d >= 2^64, so the quotient fits 64 bits (Hacker's Delight, 2nd ed., fig. 9-5): divide
    // n / 2 by the divisor's normalised top 64 bits, undo the normalisation; the estimate is
    // then the quotient or one above it (decrement), and one correction step makes it exact.
    const int s = std::countl_zero(d.hi_);  // 0..63
    const uint64_t v1 = (d << s).hi_;       // top bit set
    const UInt128 u1 = n >> 1;              // u1.hi < 2^63 <= v1: one divlu step
    uint64_t unused = 0;
    const uint64_t q1 = detail::divlu(u1.hi_, u1.lo_, v1, &unused);
    uint64_t q0 = ((UInt128(q1) << s) >> 63).lo_;  // < 2^64 here
    if (q0 != 0) --q0;
    UInt128 r = n - UInt128(q0) * d;  // q0 <= the true quotient: no wrap
    if (r >= d) {
      ++q0;
      r = r - d;
    }
    *rem = r;
    return UInt128(q0);
  }

 private:
  // Little-endian limb order: on little-endian hosts the bytes are those of the builtin type.
  uint64_t lo_ = 0;
  uint64_t hi_ = 0;
};

/// Signed 128-bit integer, two's complement in two 64-bit limbs (see the file comment).
class Int128 {
 public:
  constexpr Int128() noexcept = default;
  /// Value-preserving (sign-extending) from every builtin integer type.
  template <class I, std::enable_if_t<detail::kIsBuiltinInt<I>, int> = 0>
  constexpr Int128(I v) noexcept  // NOLINT: implicit, like the builtin integer conversions
      : bits_(v) {}
  explicit constexpr Int128(UInt128 v) noexcept : bits_(v) {}  // modular, like static_cast
  static constexpr Int128 fromLimbs(uint64_t hi, uint64_t lo) noexcept { return Int128(UInt128::fromLimbs(hi, lo)); }
  constexpr uint64_t hi() const noexcept { return bits_.hi(); }
  constexpr uint64_t lo() const noexcept { return bits_.lo(); }
  constexpr UInt128 bits() const noexcept { return bits_; }

  template <class I, std::enable_if_t<detail::kIsBuiltinInt<I>, int> = 0>
  explicit constexpr operator I() const noexcept {
    return static_cast<I>(bits_);
  }
  explicit constexpr operator bool() const noexcept { return static_cast<bool>(bits_); }

  constexpr bool isNegative() const noexcept { return (bits_.hi() >> 63) != 0; }

  // Two's complement: + - * and << are the unsigned operations on the same bits.
  friend constexpr Int128 operator+(Int128 a, Int128 b) noexcept { return Int128(a.bits_ + b.bits_); }
  friend constexpr Int128 operator-(Int128 a, Int128 b) noexcept { return Int128(a.bits_ - b.bits_); }
  friend constexpr Int128 operator-(Int128 a) noexcept { return Int128(-a.bits_); }
  friend constexpr Int128 operator+(Int128 a) noexcept { return a; }
  friend constexpr Int128 operator~(Int128 a) noexcept { return Int128(~a.bits_); }
  friend constexpr Int128 operator*(Int128 a, Int128 b) noexcept { return Int128(a.bits_ * b.bits_); }
  friend constexpr Int128 operator/(Int128 a, Int128 b) noexcept {
    // Truncating: divide the magnitudes, then give the quotient the sign of a * b.
    const UInt128 q = a.magnitude() / b.magnitude();
    return Int128(a.isNegative() != b.isNegative() ? -q : q);
  }
  friend constexpr Int128 operator%(Int128 a, Int128 b) noexcept {
    const UInt128 r = a.magnitude() % b.magnitude();  // the remainder takes the dividend's sign
    return Int128(a.isNegative() ? -r : r);
  }
  friend constexpr Int128 operator&(Int128 a, Int128 b) noexcept { return Int128(a.bits_ & b.bits_); }
  friend constexpr Int128 operator|(Int128 a, Int128 b) noexcept { return Int128(a.bits_ | b.bits_); }
  friend constexpr Int128 operator^(Int128 a, Int128 b) noexcept { return Int128(a.bits_ ^ b.bits_); }
  friend constexpr Int128 operator<<(Int128 a, int n) noexcept { return Int128(a.bits_ << n); }
  friend constexpr Int128 operator>>(Int128 a, int n) noexcept {
    // Arithmetic: shift the complement for negative values (floor division by 2^n).
    return a.isNegative() ? Int128(~(~a.bits_ >> n)) : Int128(a.bits_ >> n);
  }
  friend constexpr bool operator==(Int128 a, Int128 b) noexcept { return a.bits_ == b.bits_; }
  friend constexpr std::strong_ordering operator<=>(Int128 a, Int128 b) noexcept {
    // Flipping the sign bit maps signed order onto unsigned order.
    const UInt128 kSign = UInt128::fromLimbs(uint64_t(1) << 63, 0);
    return (a.bits_ ^ kSign) <=> (b.bits_ ^ kSign);
  }

  constexpr Int128& operator+=(Int128 b) noexcept { return *this = *this + b; }
  constexpr Int128& operator-=(Int128 b) noexcept { return *this = *this - b; }
  constexpr Int128& operator*=(Int128 b) noexcept { return *this = *this * b; }
  constexpr Int128& operator/=(Int128 b) noexcept { return *this = *this / b; }
  constexpr Int128& operator%=(Int128 b) noexcept { return *this = *this % b; }
  constexpr Int128& operator&=(Int128 b) noexcept { return *this = *this & b; }
  constexpr Int128& operator|=(Int128 b) noexcept { return *this = *this | b; }
  constexpr Int128& operator<<=(int n) noexcept { return *this = *this << n; }
  constexpr Int128& operator>>=(int n) noexcept { return *this = *this >> n; }

 private:
  /// |v| as unsigned; |MIN| = 2^127 is representable there.
  constexpr UInt128 magnitude() const noexcept { return isNegative() ? -bits_ : bits_; }

  UInt128 bits_;
};

constexpr UInt128::UInt128(Int128 v) noexcept : UInt128(v.bits()) {}

}  // namespace portable
}  // namespace sg

// numeric_limits for the portable types (allowed for program-defined types): code written for the
// builtin types that asks for min()/max() must not silently get the unspecialised zeros.
template <>
struct std::numeric_limits<sg::portable::UInt128> {
  static constexpr bool is_specialized = true, is_signed = false, is_integer = true, is_exact = true;
  static constexpr int digits = 128;
  static constexpr sg::portable::UInt128 min() noexcept { return {}; }
  static constexpr sg::portable::UInt128 lowest() noexcept { return {}; }
  static constexpr sg::portable::UInt128 max() noexcept { return ~sg::portable::UInt128(); }
};
template <>
struct std::numeric_limits<sg::portable::Int128> {
  static constexpr bool is_specialized = true, is_signed = true, is_integer = true, is_exact = true;
  static constexpr int digits = 127;
  static constexpr sg::portable::Int128 max() noexcept { return sg::portable::Int128(~sg::portable::UInt128() >> 1); }
  static constexpr sg::portable::Int128 min() noexcept { return -max() - 1; }
  static constexpr sg::portable::Int128 lowest() noexcept { return min(); }
};

namespace sg {
#if SIMGRASS_NATIVE_INT128
using Int128 = __int128;
using UInt128 = unsigned __int128;
#else
using Int128 = portable::Int128;
using UInt128 = portable::UInt128;
#endif

/// The unsigned type of the same width: std::make_unsigned for the builtin integers (spelled
/// out for __int128, which strict -std=c++20 does not count as integral), UInt128 for Int128.
template <class T>
struct UnsignedOf {
  using type = std::make_unsigned_t<T>;
};
template <>
struct UnsignedOf<portable::Int128> {
  using type = portable::UInt128;
};
template <>
struct UnsignedOf<portable::UInt128> {
  using type = portable::UInt128;
};
#if defined(__SIZEOF_INT128__)
template <>
struct UnsignedOf<__int128> {
  using type = unsigned __int128;
};
template <>
struct UnsignedOf<unsigned __int128> {
  using type = unsigned __int128;
};
#endif
template <class T>
using UnsignedOfT = typename UnsignedOf<T>::type;

/// True for the portable struct types (the fast paths with builtin-only code skip them).
template <class T>
inline constexpr bool kIsPortableInt128 = std::is_same_v<T, portable::Int128> || std::is_same_v<T, portable::UInt128>;

inline constexpr UInt128 kUInt128Max = ~UInt128(0);
inline constexpr Int128 kInt128Max = Int128(kUInt128Max >> 1);
inline constexpr Int128 kInt128Min = -kInt128Max - 1;

/// Low and high 64 bits of the two's complement representation.
template <class W>
constexpr uint64_t low64(W v) noexcept {
  return static_cast<uint64_t>(v);
}
template <class W>
constexpr uint64_t high64(W v) noexcept {
  return static_cast<uint64_t>(static_cast<UnsignedOfT<W>>(v) >> 64);
}

/// Full 256-bit product of two unsigned 128-bit values: returns the low 128 bits, the high 128
/// bits go to *hi. The same schoolbook as mul64x64, one level up, for either UInt128 type.
template <class U>
constexpr U mulFull(U a, U b, U* hi) noexcept {
  const U kLow = U(~uint64_t(0));
  const U a0 = a & kLow, a1 = a >> 64, b0 = b & kLow, b1 = b >> 64;
  const U p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
  const U mid = (p00 >> 64) + (p01 & kLow) + (p10 & kLow);  // three values below 2^64
  *hi = p11 + (p01 >> 64) + (p10 >> 64) + (mid >> 64);
  return (mid << 64) | (p00 & kLow);
}

// Checked signed arithmetic with the contract of __builtin_{add,mul}_overflow: *out receives
// the wrapped result, the return value says whether the exact result did not fit.
inline constexpr bool addOverflow(portable::Int128 a, portable::Int128 b, portable::Int128* out) noexcept {
  *out = a + b;
  // Overflow exactly when both operands have the same sign and the sum has the other one.
  return a.isNegative() == b.isNegative() && out->isNegative() != a.isNegative();
}
inline constexpr bool mulOverflow(portable::Int128 a, portable::Int128 b, portable::Int128* out) noexcept {
  using portable::UInt128;
  *out = a * b;
  const bool negative = a.isNegative() != b.isNegative();
  const UInt128 ma = a.isNegative() ? -UInt128(a) : UInt128(a);
  const UInt128 mb = b.isNegative() ? -UInt128(b) : UInt128(b);
  UInt128 hi;
  const UInt128 lo = mulFull(ma, mb, &hi);
  // The exact magnitude must be at most 2^127 - 1, or 2^127 for a negative result.
  const UInt128 limit = (UInt128(1) << 127) - (negative ? 0 : 1);
  return hi != 0 || lo > limit;
}
#if defined(__SIZEOF_INT128__)
inline constexpr bool addOverflow(__int128 a, __int128 b, __int128* out) noexcept {
  return __builtin_add_overflow(a, b, out);
}
inline constexpr bool mulOverflow(__int128 a, __int128 b, __int128* out) noexcept {
  return __builtin_mul_overflow(a, b, out);
}
#endif

}  // namespace sg
