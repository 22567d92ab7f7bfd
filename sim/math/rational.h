// Exact rational numbers for scenario values and the conversions from them into each scalar.
//
// Scenario decimals ("0.97", "1e-3", "1/60") are parsed into an exact fraction num/den; every
// scalar then rounds that exact value once (docs/fixed-point.md). Arithmetic is checked: a result
// that does not fit 128 bits is reported, never wrapped.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "sim/math/int128.h"

namespace sg {

struct Rational {
  Int128 num = 0;
  Int128 den = 1;  ///< always > 0, gcd(num, den) == 1

  static std::optional<Rational> make(Int128 num, Int128 den);
  static Rational integer(int64_t v) { return Rational{v, 1}; }

  bool isZero() const { return num == 0; }
  bool isNegative() const { return num < 0; }
  bool isInteger() const { return den == 1; }

  /// Parses a JSON number token or a fraction "a/b" (a, b decimal numbers). Returns an error
  /// text (what was expected) on failure.
  static std::optional<Rational> parse(std::string_view text, std::string* error);

  /// The double nearest to num/den, ties to even: correctly rounded, computed in integers only,
  /// so the same on every machine (no long double, whose width differs between them).
  double toDouble() const;
  /// round(value * 2^fracBits), nearest, ties away from zero; nullopt when |result| >= 2^126.
  std::optional<Int128> toScaledInteger(int fracBits) const;
  /// round(value), ties away from zero; nullopt when it does not fit int64.
  std::optional<int64_t> roundToInt64() const;
  std::string toString() const;

  friend bool operator==(const Rational&, const Rational&) = default;
};

std::optional<Rational> add(const Rational& a, const Rational& b);
std::optional<Rational> sub(const Rational& a, const Rational& b);
std::optional<Rational> mul(const Rational& a, const Rational& b);
std::optional<Rational> div(const Rational& a, const Rational& b);
int compare(const Rational& a, const Rational& b);  ///< -1, 0, 1 (exact)

/// base^exponent for 0 < base <= 1 and exponent >= 0, by integer ln/exp series in Q2.62
/// (no libm): the result is the same bits on every machine. Accurate to about 1e-17; returned
/// as the exact fraction raw / 2^62. Used for the per-tick damping factor damping^dt.
Rational deterministicPow(const Rational& base, const Rational& exponent);

}  // namespace sg
