// Fixed-point scalars for the deterministic core.
//
//   Fx32 = Q32.32 in int64_t, products and quotients in Int128   (the reference scalar).
//   Fx16 = Q16.16 in int32_t, products and quotients in int64_t  (the fast variant).
// Int128 (sim/math/int128.h) is the builtin __int128 where the compiler has it, else a portable
// two-limb struct with the same bits: the wide type is a template parameter, so tests build
// Fixed<int64_t, portable::Int128, 32> next to Fx32 and compare them bit for bit.
//
// Rounding (documented in docs/fixed-point.md, tested against exact references):
//   * a * b, a / b and sqrt(a) round to nearest; exact ties round away from zero. This makes
//     (-a) * b == -(a * b) and (-a) / b == -(a / b), so mirror-symmetric scenes stay symmetric.
//   * + and - are exact.
// Overflow is never undefined behaviour: every operation computes in a wider or builtin-checked
// type. A result that does not fit raises a sticky per-thread fault bit (see FixedFault) and
// returns the wrapped value; the world's step checks the bits after each particle and turns a
// fault into a reported simulation error (tick, stage, particle).
#pragma once

#include <compare>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "sim/math/int128.h"

namespace sg {

/// Sticky fault bits raised by fixed-point operations on the current thread.
enum FixedFault : uint32_t {
  kFixedFaultNone = 0,
  kFixedFaultOverflow = 1,      ///< a result did not fit the format
  kFixedFaultDivideByZero = 2,  ///< x / 0
  kFixedFaultDomain = 4,        ///< sqrt of a negative number
};

namespace detail {
// __thread (not thread_local): trivially initialised, so no TLS wrapper call on access.
extern __thread uint32_t tlsFixedFaults __attribute__((tls_model("initial-exec")));
[[gnu::cold, gnu::noinline]] void raiseFixedFault(uint32_t fault) noexcept;
}  // namespace detail

/// Fault bits raised on this thread since the last takeFixedFaults().
inline uint32_t pendingFixedFaults() noexcept { return detail::tlsFixedFaults; }
/// Returns and clears this thread's fault bits.
inline uint32_t takeFixedFaults() noexcept {
  const uint32_t f = detail::tlsFixedFaults;
  detail::tlsFixedFaults = 0;
  return f;
}
/// Human-readable name of the most significant fault bit ("overflow", ...).
const char* fixedFaultName(uint32_t faults) noexcept;

/// Integer square roots, exact: floor variant and round-to-nearest variant. isqrtNearest needs
/// n <= 2^128 - 2^64 (its result must fit 64 bits); sqrt and length3 stay far below that.
/// Overloaded for the portable type too where UInt128 is the builtin one (tests compare them).
uint64_t isqrtFloor(UInt128 n) noexcept;
#if SIMGRASS_NATIVE_INT128
uint64_t isqrtFloor(portable::UInt128 n) noexcept;
#endif
namespace detail {
template <class U>
inline uint64_t isqrtNearest(U n) noexcept {
  const uint64_t r = isqrtFloor(n);
  // (r + 1/2)^2 = r^2 + r + 1/4, so n rounds up exactly when n - r^2 > r (no ties for integers).
  return (n - static_cast<U>(r) * r > r) ? r + 1 : r;
}
}  // namespace detail
inline uint64_t isqrtNearest(UInt128 n) noexcept { return detail::isqrtNearest(n); }
#if SIMGRASS_NATIVE_INT128
inline uint64_t isqrtNearest(portable::UInt128 n) noexcept { return detail::isqrtNearest(n); }
#endif

template <class Raw, class Wide, int Frac>
class Fixed {
  static_assert(std::is_signed_v<Raw> && sizeof(Wide) == 2 * sizeof(Raw));
  static constexpr int kRawBits = int(sizeof(Raw) * 8);

 public:
  using RawType = Raw;
  using WideType = Wide;
  using UnsignedWideType = UnsignedOfT<Wide>;
  static constexpr int kFracBits = Frac;
  static constexpr Raw kOneRaw = Raw(1) << Frac;

  constexpr Fixed() noexcept = default;
  /// Exact conversion from an integer; raises an overflow fault when it does not fit.
  template <class I, std::enable_if_t<std::is_integral_v<I> && !std::is_same_v<I, bool>, int> = 0>
  constexpr Fixed(I value) noexcept  // NOLINT: implicit, so Eigen's Scalar(0), v * 2 work
      : raw_(fromInteger(value)) {}

  static constexpr Fixed fromRaw(Raw raw) noexcept {
    Fixed f;
    f.raw_ = raw;
    return f;
  }
  constexpr Raw raw() const noexcept { return raw_; }

  /// For reports, plots and tests only; never used inside the step.
  constexpr double toDouble() const noexcept { return double(raw_) / double(kOneRaw); }
  /// For tests and tools only: nearest representable value (ties away from zero).
  static Fixed fromDouble(double v) noexcept;

  static constexpr Fixed max() noexcept { return fromRaw(std::numeric_limits<Raw>::max()); }
  static constexpr Fixed min() noexcept { return fromRaw(std::numeric_limits<Raw>::min()); }
  static constexpr Fixed epsilon() noexcept { return fromRaw(1); }

  [[gnu::always_inline]] friend constexpr Fixed operator+(Fixed a, Fixed b) noexcept {
    Raw r;
    if (__builtin_add_overflow(a.raw_, b.raw_, &r)) detail::raiseFixedFault(kFixedFaultOverflow);
    return fromRaw(r);
  }
  [[gnu::always_inline]] friend constexpr Fixed operator-(Fixed a, Fixed b) noexcept {
    Raw r;
    if (__builtin_sub_overflow(a.raw_, b.raw_, &r)) detail::raiseFixedFault(kFixedFaultOverflow);
    return fromRaw(r);
  }
  friend constexpr Fixed operator-(Fixed a) noexcept { return Fixed() - a; }
  friend constexpr Fixed operator+(Fixed a) noexcept { return a; }

  [[gnu::always_inline]] friend constexpr Fixed operator*(Fixed a, Fixed b) noexcept {
    // |a*b| <= 2^(2*kRawBits - 2): the wide product never overflows.
    return fromRaw(narrow(roundShift(Wide(a.raw_) * Wide(b.raw_))));
  }
  /// floor(a * b) as an integer, with the product rounded as operator* rounds it but never
  /// narrowed to Raw: the same integer as floorToInt(a * b) wherever a * b fits, and the right one
  /// where it does not (a lattice index far from the origin in Q16.16).
  static constexpr int64_t floorOfProduct(Fixed a, Fixed b) noexcept {
    return int64_t(roundShift(Wide(a.raw_) * Wide(b.raw_)) >> Frac);
  }
  friend constexpr Fixed operator/(Fixed a, Fixed b) noexcept {
    if (b.raw_ == 0) {
      detail::raiseFixedFault(kFixedFaultDivideByZero);
      return a.raw_ < 0 ? min() : max();
    }
    return fromRaw(narrow(divRound(Wide(a.raw_) * Wide(kOneRaw), Wide(b.raw_))));
  }

  constexpr Fixed& operator+=(Fixed b) noexcept { return *this = *this + b; }
  constexpr Fixed& operator-=(Fixed b) noexcept { return *this = *this - b; }
  constexpr Fixed& operator*=(Fixed b) noexcept { return *this = *this * b; }
  constexpr Fixed& operator/=(Fixed b) noexcept { return *this = *this / b; }

  friend constexpr bool operator==(Fixed a, Fixed b) noexcept = default;
  friend constexpr auto operator<=>(Fixed a, Fixed b) noexcept = default;

  /// round(a * b / c) with the full-width product (one rounding instead of two).
  static constexpr Fixed mulDiv(Fixed a, Fixed b, Fixed c) noexcept {
    if (c.raw_ == 0) {
      detail::raiseFixedFault(kFixedFaultDivideByZero);
      return max();
    }
    return fromRaw(narrow(divRound(Wide(a.raw_) * Wide(b.raw_), Wide(c.raw_))));
  }

  template <class I>
  static constexpr Raw fromInteger(I value) noexcept {
    // The limits are compared in the wider of I and Raw, where both convert exactly (kMaxInt >= 0
    // also converts exactly to an unsigned I), so every integer type, __int128 included, is
    // handled exactly without a 128-bit type of our own.
    constexpr Raw kMaxInt = std::numeric_limits<Raw>::max() >> Frac;
    constexpr Raw kMinInt = std::numeric_limits<Raw>::min() >> Frac;
    bool above, below = false;
    if constexpr (std::is_signed_v<I>) {
      if constexpr (sizeof(I) <= sizeof(Raw)) {
        above = Raw(value) > kMaxInt;
        below = Raw(value) < kMinInt;
      } else {
        above = value > I(kMaxInt);
        below = value < I(kMinInt);
      }
    } else if constexpr (sizeof(I) < sizeof(Raw)) {
      above = Raw(value) > kMaxInt;
    } else {
      above = value > static_cast<I>(kMaxInt);
    }
    if (above || below) {
      detail::raiseFixedFault(kFixedFaultOverflow);
      return above ? std::numeric_limits<Raw>::max() : std::numeric_limits<Raw>::min();
    }
    // In range: value fits Raw and value * 2^Frac stays within Raw's limits (no overflow).
    return static_cast<Raw>(static_cast<Raw>(value) * kOneRaw);
  }
  /// Narrows a wide value to Raw, raising an overflow fault when it does not fit.
  [[gnu::always_inline]] static constexpr Raw narrow(Wide w) noexcept {
    if (w > Wide(std::numeric_limits<Raw>::max()) || w < Wide(std::numeric_limits<Raw>::min()))
      detail::raiseFixedFault(kFixedFaultOverflow);
    return static_cast<Raw>(w);  // modular since C++20: defined
  }
  /// p / 2^Frac rounded to nearest, ties away from zero. Requires |p| < 2^(2*kRawBits-1).
  /// For p < 0, -floor((|p| + h) / D) == floor((p + h - 1) / D) with D = 2h, so one add of the
  /// sign (0 or -1) and an arithmetic shift (floor) give the symmetric rounding without a branch.
  [[gnu::always_inline]] static constexpr Wide roundShift(Wide p) noexcept {
    const Wide sign = p >> (2 * kRawBits - 1);  // 0 or -1 (arithmetic shift, defined in C++20)
    return (p + (Wide(1) << (Frac - 1)) + sign) >> Frac;
  }
  /// n / d rounded to nearest, ties away from zero. d != 0; |n|, |d| < 2^(2*kRawBits-1).
  static constexpr Wide divRound(Wide n, Wide d) noexcept {
    if constexpr (sizeof(Wide) == 16) {
      // Fast path for Q32.32: magnitudes with |n| / |d| < 2^64 divide with one 128/64 divq.
      // Same exact quotient and remainder as the generic path, so the same bits.
      using U = UnsignedWideType;
      const U un = n < 0 ? U(0) - U(n) : U(n);
      const U ud = d < 0 ? U(0) - U(d) : U(d);
      if (!std::is_constant_evaluated() && (ud >> 64) == 0 && uint64_t(un >> 64) < uint64_t(ud)) {
        uint64_t r;
        uint64_t q = udiv128by64(uint64_t(un >> 64), uint64_t(un), uint64_t(ud), &r);
        const bool up = r >= uint64_t(ud) - r;  // 2r >= d without overflow
        const Wide mag = Wide(q) + (up ? 1 : 0);
        return ((n < 0) != (d < 0)) ? -mag : mag;
      }
    }
    Wide q = n / d;
    const Wide r = n - q * d;  // remainder without a second wide division
    const Wide absR = r < 0 ? -r : r;
    const Wide absD = d < 0 ? -d : d;
    if (absR >= absD - absR) q += ((n < 0) != (d < 0)) ? -1 : 1;
    return q;
  }

  /// (hi:lo) / d for hi < d (the quotient fits 64 bits); the remainder goes to *rem.
  static uint64_t udiv128by64(uint64_t hi, uint64_t lo, uint64_t d, uint64_t* rem) noexcept {
#if defined(__x86_64__)
    // One divq; not for the portable type, so that its own division is what tests compare.
    constexpr bool kDivq = !kIsPortableInt128<Wide>;
#else
    constexpr bool kDivq = false;
#endif
    if constexpr (kDivq) {
#if defined(__x86_64__)
      uint64_t q, r;
      __asm__("divq %4" : "=a"(q), "=d"(r) : "a"(lo), "d"(hi), "rm"(d));
      *rem = r;
      return q;
#endif
    } else if constexpr (kIsPortableInt128<Wide>) {
      return portable::detail::divlu(hi, lo, d, rem);  // the portable type's own 128/64 step
    } else {
      using U = UnsignedWideType;
      const U n = (static_cast<U>(hi) << 64) | lo;
      *rem = uint64_t(n % d);
      return uint64_t(n / d);
    }
  }

 private:
  Raw raw_ = 0;
};

using Fx32 = Fixed<int64_t, Int128, 32>;
using Fx16 = Fixed<int32_t, int64_t, 16>;

template <class Raw, class Wide, int Frac>
Fixed<Raw, Wide, Frac> Fixed<Raw, Wide, Frac>::fromDouble(double v) noexcept {
  // Exact in double arithmetic only (no long double, whose width differs between machines):
  // v * 2^Frac is exact (a power-of-two scaling; an overflow gives +-inf, which fails the range
  // test below), and the rounding works on the integer and fraction parts, both exact.
  const double scaled = v * double(kOneRaw);
  if (scaled != scaled) {  // NaN: not representable
    detail::raiseFixedFault(kFixedFaultOverflow);
    return Fixed();
  }
  // Guard the double -> integer conversion first (converting an out-of-range value is UB):
  // [-2^63, 2^63) holds every value that can round into an int64 Raw, and no more.
  constexpr double kTwo63 = 9223372036854775808.0;
  if (!(scaled >= -kTwo63 && scaled < kTwo63)) {
    detail::raiseFixedFault(kFixedFaultOverflow);
    return v < 0 ? min() : max();
  }
  // Nearest, ties away from zero, on the magnitude. From 2^52 up a double is an integer; below,
  // the truncated integer part r is exact, and so is mag - r (r is a multiple of mag's ulp, so
  // the difference is a multiple of it below 1: representable), which decides against 1/2.
  const double mag = scaled < 0 ? -scaled : scaled;
  uint64_t r = uint64_t(mag);  // mag < 2^63
  if (mag < 4503599627370496.0 && mag - double(r) >= 0.5) ++r;
  const bool neg = scaled < 0;
  constexpr uint64_t kMaxMag = uint64_t(std::numeric_limits<Raw>::max());
  if (r > kMaxMag + (neg ? 1 : 0)) {
    detail::raiseFixedFault(kFixedFaultOverflow);
    return neg ? min() : max();
  }
  // -r as the two's complement bits (r = 2^(bits-1) gives min()); modular conversion is defined.
  return fromRaw(static_cast<Raw>(neg ? uint64_t(0) - r : r));
}

// ---- free functions (found by argument-dependent lookup, also by Eigen) -------------------

template <class R, class W, int F>
constexpr Fixed<R, W, F> abs(Fixed<R, W, F> a) noexcept {
  return a.raw() < 0 ? -a : a;
}

namespace detail {
/// The unsigned 128-bit type sqrt and length3 compute their radicands in: Fx32's own wide type
/// (builtin or portable), and UInt128 for the narrower formats (Fx16's radicands need < 64
/// bits, but the code has always used 128 and x86-64 keeps exactly that code).
template <class W>
using RadicandOf = std::conditional_t<sizeof(W) == 16, UnsignedOfT<W>, UInt128>;

/// sqrt with the radicand type U as a parameter, so tests can run Fx16's with the portable type.
template <class U, class R, class W, int F>
inline Fixed<R, W, F> sqrtWith(Fixed<R, W, F> a) noexcept {
  using Fx = Fixed<R, W, F>;
  if (a.raw() < 0) {
    raiseFixedFault(kFixedFaultDomain);
    return Fx();
  }
  // sqrt(raw / 2^F) * 2^F = sqrt(raw * 2^F): the radicand is exact in 128 bits.
  const U n = static_cast<U>(a.raw()) << F;
  return Fx::fromRaw(static_cast<R>(isqrtNearest(n)));  // < 2^(bits/2 + F/2): always fits
}

template <class U, class R, class W, int F>
inline Fixed<R, W, F> length3With(Fixed<R, W, F> x, Fixed<R, W, F> y, Fixed<R, W, F> z) noexcept {
  using Fx = Fixed<R, W, F>;
  auto sq = [](R v) {
    const U m = v < 0 ? U(0) - U(v) : U(v);
    return m * m;
  };
  // Each square is < 2^(2*bits-2), so the sum of three fits in 2*bits unsigned bits.
  const uint64_t r = isqrtNearest(sq(x.raw()) + sq(y.raw()) + sq(z.raw()));
  if (r > uint64_t(std::numeric_limits<R>::max())) raiseFixedFault(kFixedFaultOverflow);
  return Fx::fromRaw(static_cast<R>(r));
}
}  // namespace detail

/// Square root rounded to nearest; a negative argument raises a domain fault and returns 0.
template <class R, class W, int F>
inline Fixed<R, W, F> sqrt(Fixed<R, W, F> a) noexcept {
  return detail::sqrtWith<detail::RadicandOf<W>>(a);
}

/// |(x, y, z)| rounded to nearest from the exact sum of squares (one rounding only). An axis
/// vector (0, y, 0) has length exactly |y|.
template <class R, class W, int F>
inline Fixed<R, W, F> length3(Fixed<R, W, F> x, Fixed<R, W, F> y, Fixed<R, W, F> z) noexcept {
  return detail::length3With<detail::RadicandOf<W>>(x, y, z);
}

/// Whether length3(x, y, z) >= r, exactly, without the square root (for r > 0): length3 rounds
/// to nearest with no ties, so it reaches r exactly when the sum of squares N of the raw values
/// is at least r^2 - r + 1 (raw units). Any raw values fit: three squares below 2^126 each (Fx32)
/// sum below 2^128.
template <class R, class W, int F>
inline bool length3AtLeast(Fixed<R, W, F> x, Fixed<R, W, F> y, Fixed<R, W, F> z, Fixed<R, W, F> r) noexcept {
  using U = detail::RadicandOf<W>;
  const auto sq = [](R v) {
    const U m = v < 0 ? U(0) - U(v) : U(v);
    return m * m;
  };
  const U radius = static_cast<U>(r.raw());
  return sq(x.raw()) + sq(y.raw()) + sq(z.raw()) >= radius * radius - radius + U(1);
}

template <class R, class W, int F>
constexpr Fixed<R, W, F> min(Fixed<R, W, F> a, Fixed<R, W, F> b) noexcept {
  return b < a ? b : a;
}
template <class R, class W, int F>
constexpr Fixed<R, W, F> max(Fixed<R, W, F> a, Fixed<R, W, F> b) noexcept {
  return a < b ? b : a;
}

}  // namespace sg
