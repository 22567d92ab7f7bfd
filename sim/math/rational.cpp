#include "sim/math/rational.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <limits>

namespace sg {
namespace {
// Builtin __int128 where the compiler has it, else the portable struct (sim/math/int128.h).
using I128 = Int128;
using U128 = UInt128;

I128 gcd(I128 a, I128 b) {
  // On magnitudes as unsigned: |INT128_MIN| is representable there.
  U128 x = a < 0 ? U128(0) - U128(a) : U128(a);
  U128 y = b < 0 ? U128(0) - U128(b) : U128(b);
  while (y != 0) {
    const U128 t = x % y;
    x = y;
    y = t;
  }
  return x > U128(~U128(0) >> 1) ? I128(1) : I128(x);  // gcd 2^127 only for (MIN, MIN/0): treat as 1
}

bool mulChecked(I128 a, I128 b, I128* out) { return !mulOverflow(a, b, out); }

U128 magnitude(I128 v) { return v < 0 ? U128(0) - U128(v) : U128(v); }

int bitLength(U128 u) {
  const uint64_t hi = high64(u), lo = low64(u);
  return hi != 0 ? 128 - std::countl_zero(hi) : 64 - std::countl_zero(lo);
}

std::string toDecimalString(I128 v) {
  if (v == 0) return "0";
  const bool neg = v < 0;
  U128 m = neg ? U128(0) - U128(v) : U128(v);
  std::string s;
  while (m != 0) {
    s.insert(s.begin(), char('0' + int(m % 10)));
    m /= 10;
  }
  return neg ? "-" + s : s;
}

// Parses a plain decimal number token: -?digits[.digits][e[+-]digits]. Leading and trailing
// zeros are not significant digits ("1.000" and "0.5" have one).
std::optional<Rational> parseDecimal(std::string_view t, std::string* error) {
  constexpr int kMaxDigits = 30;  // keeps num and 10^k well inside 128 bits
  auto fail = [&](const char* what) {
    if (error) *error = what;
    return std::optional<Rational>();
  };
  size_t i = 0;
  bool neg = false;
  if (i < t.size() && (t[i] == '-' || t[i] == '+')) neg = t[i++] == '-';
  I128 mant = 0;
  // Counts are int64: a text of any length (zeros included) counts exactly, nothing wraps.
  int64_t digits = 0, scale = 0;            // value = mant * 10^(-scale) * 10^pendingInt
  int64_t pendingInt = 0, pendingFrac = 0;  // zeros seen after the last non-zero digit
  bool any = false, dot = false;
  for (; i < t.size(); ++i) {
    const char c = t[i];
    if (c == '.' && !dot) {
      dot = true;
      continue;
    }
    if (!std::isdigit(static_cast<unsigned char>(c))) break;
    any = true;
    if (c == '0') {
      if (mant == 0) {
        if (dot) ++scale;  // leading zeros after the point only shift the scale
      } else {
        ++(dot ? pendingFrac : pendingInt);
      }
      continue;
    }
    // A non-zero digit makes the zeros before it significant.
    digits += pendingInt + pendingFrac + 1;
    if (digits > kMaxDigits) return fail("a number with at most 30 significant digits");
    for (int64_t z = 0; z < pendingInt + pendingFrac; ++z) mant *= 10;
    scale += pendingFrac + (dot ? 1 : 0);
    pendingInt = pendingFrac = 0;
    mant = mant * 10 + (c - '0');
  }
  if (!any) return fail("a number");
  // The exponent saturates at 10^15: far beyond any text's count of zeros (at most its length),
  // so a saturated exponent still decides "too large" / "too small" exactly - never a dropped
  // digit (1000...0e-100000 is 10^(zeros - 100000), not 1).
  constexpr int64_t kExponentCap = 1000000000000000;
  int64_t exp10 = 0;
  if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    bool eneg = false;
    if (i < t.size() && (t[i] == '-' || t[i] == '+')) eneg = t[i++] == '-';
    bool edig = false;
    for (; i < t.size() && std::isdigit(static_cast<unsigned char>(t[i])); ++i) {
      edig = true;
      exp10 = std::min(kExponentCap, exp10 * 10 + (t[i] - '0'));
    }
    if (!edig) return fail("a number (exponent digits after 'e')");
    if (eneg) exp10 = -exp10;
  }
  if (i != t.size()) return fail("a number");
  if (mant == 0) return Rational{0, 1};
  // value = mant * 10^e with mant of `digits` digits: 10^(digits-1+e) <= |value| < 10^(digits+e).
  const int64_t e = exp10 - scale + pendingInt;
  if (digits + e > 36 || digits - 1 + e < -36) return fail("a number from 1e-36 to below 1e36 in magnitude");
  if (e < -38) return fail("a number with at most 38 decimal places");
  I128 p = 1;
  for (int64_t k = 0; k < (e < 0 ? -e : e); ++k) p *= 10;
  const I128 n = neg ? -mant : mant;
  auto r = e >= 0 ? Rational::make(n * p, 1) : Rational::make(n, p);
  if (!r && error) *error = "a number of representable size";
  return r;
}
}  // namespace

std::optional<Rational> Rational::make(I128 num, I128 den) {
  if (den == 0) return std::nullopt;
  constexpr I128 kMin = kInt128Min;
  if (den < 0 && (num == kMin || den == kMin)) return std::nullopt;
  if (den < 0) {
    num = -num;
    den = -den;
  }
  const I128 g = gcd(num, den);
  if (g > 1) {
    num /= g;
    den /= g;
  }
  return Rational{num, den};
}

std::optional<Rational> Rational::parse(std::string_view text, std::string* error) {
  const size_t slash = text.find('/');
  if (slash == std::string_view::npos) return parseDecimal(text, error);
  auto a = parseDecimal(text.substr(0, slash), error);
  auto b = parseDecimal(text.substr(slash + 1), error);
  if (!a || !b) return std::nullopt;
  if (b->isZero()) {
    if (error) *error = "a fraction with a non-zero denominator";
    return std::nullopt;
  }
  auto r = sg::div(*a, *b);
  if (!r && error) *error = "a fraction of representable size";
  return r;
}

std::optional<Rational> add(const Rational& a, const Rational& b) {
  // Over the least common denominator: decimals share powers of ten, which keeps this small.
  const I128 g = gcd(a.den, b.den);
  const I128 ad = a.den / g, bd = b.den / g;
  I128 x, y, d, n;
  if (!mulChecked(a.num, bd, &x) || !mulChecked(b.num, ad, &y) || !mulChecked(a.den, bd, &d) || addOverflow(x, y, &n))
    return std::nullopt;
  return Rational::make(n, d);
}
std::optional<Rational> sub(const Rational& a, const Rational& b) {
  if (b.num == kInt128Min) return std::nullopt;
  return add(a, Rational{-b.num, b.den});
}
std::optional<Rational> mul(const Rational& a, const Rational& b) {
  // Cross-reduce first to keep intermediates small.
  const I128 g1 = gcd(a.num, b.den), g2 = gcd(b.num, a.den);
  const I128 an = g1 ? a.num / g1 : a.num, bd = g1 ? b.den / g1 : b.den;
  const I128 bn = g2 ? b.num / g2 : b.num, ad = g2 ? a.den / g2 : a.den;
  I128 n, d;
  if (!mulChecked(an, bn, &n) || !mulChecked(ad, bd, &d)) return std::nullopt;
  return Rational::make(n, d);
}
std::optional<Rational> div(const Rational& a, const Rational& b) {
  if (b.num == 0 || b.num == kInt128Min) return std::nullopt;
  return mul(a, Rational{b.den * (b.num < 0 ? -1 : 1), b.num < 0 ? -b.num : b.num});
}
int compare(const Rational& a, const Rational& b) {
  // Exact for every pair: the signs first, then |a.num| * b.den against |b.num| * a.den as full
  // 256-bit products (the denominators are positive), so nothing can overflow or round.
  const int sa = a.num < 0 ? -1 : (a.num > 0 ? 1 : 0);
  const int sb = b.num < 0 ? -1 : (b.num > 0 ? 1 : 0);
  if (sa != sb) return sa < sb ? -1 : 1;
  if (sa == 0) return 0;
  U128 lhsHi, rhsHi;
  const U128 lhsLo = mulFull(magnitude(a.num), U128(b.den), &lhsHi);
  const U128 rhsLo = mulFull(magnitude(b.num), U128(a.den), &rhsHi);
  const int byMagnitude = lhsHi != rhsHi ? (lhsHi < rhsHi ? -1 : 1) : (lhsLo < rhsLo ? -1 : (lhsLo > rhsLo ? 1 : 0));
  return sa > 0 ? byMagnitude : -byMagnitude;
}

double Rational::toDouble() const {
  // Correctly rounded (nearest, ties to even, as IEEE division would round num / den if both
  // were exact doubles), in integer arithmetic only: the result is the same on every machine,
  // whatever its long double or its x87 excess precision. (Before, values beyond 2^53 went
  // through long double: 80-bit on x86, 128-bit on aarch64/s390x, double-double on ppc64el.)
  if (num == 0) return 0.0;
  const U128 d = U128(den);  // den > 0
  // Exact long division with f fraction bits: n * 2^f = q * d + r, 0 <= r < d. Add bits until q
  // has at least 54 significant bits: 53 for the double plus the rounding bit; whether r is 0
  // is the sticky bit. Each step brings down s bits at once, as many as r * 2^s fits 128 bits
  // (s >= 1 since r < d < 2^127) and no more than q needs; (r * 2^s) / d < 2^s.
  U128 q = magnitude(num) / d, r = magnitude(num) % d;
  int f = 0;
  for (int have = bitLength(q); have < 54; have = bitLength(q)) {
    const int s = std::min(54 - have, 128 - bitLength(r));
    const U128 shifted = r << s;
    q = (q << s) | (shifted / d);
    r = shifted % d;
    f += s;
  }
  // Keep the top 53 bits of q, round on the rest: above half up, below down, an exact half
  // (nothing below it in q and r == 0) to the even mantissa.
  const int drop = bitLength(q) - 53;  // >= 1
  uint64_t m = uint64_t(q >> drop);
  const U128 rest = q & ((U128(1) << drop) - 1), half = U128(1) << (drop - 1);
  if (rest > half || (rest == half && (r != 0 || (m & 1) != 0))) ++m;  // m <= 2^53: still exact
  // |num/den| lies in [2^-127, 2^127): the scaling by 2^(drop - f) never overflows or goes
  // subnormal, so ldexp is exact (it only sets the exponent).
  const double v = std::ldexp(double(m), drop - f);
  return num < 0 ? -v : v;
}

std::optional<I128> Rational::toScaledInteger(int fracBits) const {
  // Exact long division: integer part, then fracBits + 1 quotient bits and a sticky remainder.
  const bool neg = num < 0;
  const U128 n = magnitude(num);
  const U128 d = U128(den);
  U128 q = n / d, r = n % d;
  if (fracBits >= 126 ? q != 0 : (q >> (126 - fracBits)) != 0) return std::nullopt;
  for (int k = 0; k < fracBits; ++k) {
    r <<= 1;  // r < d < 2^127: no overflow
    q <<= 1;
    if (r >= d) {
      r -= d;
      q |= 1;
    }
  }
  // Round half away from zero on the magnitude: compare 2r with d.
  if (r >= d - r) q += 1;
  if ((q >> 126) != 0) return std::nullopt;
  return neg ? -I128(q) : I128(q);
}

std::optional<int64_t> Rational::roundToInt64() const {
  auto v = toScaledInteger(0);
  if (!v || *v > I128(INT64_MAX) || *v < I128(INT64_MIN)) return std::nullopt;
  return int64_t(*v);
}

std::string Rational::toString() const {
  return den == 1 ? toDecimalString(num) : toDecimalString(num) + "/" + toDecimalString(den);
}

// ---- deterministic pow --------------------------------------------------------------------
namespace {
constexpr int kQ = 62;
constexpr I128 kOne = I128(1) << kQ;

I128 qmul(I128 a, I128 b) {  // |a|,|b| < 2^64 keeps the product inside 128 bits
  const I128 p = a * b;
  return p >= 0 ? (p + (I128(1) << (kQ - 1))) >> kQ : -((-p + (I128(1) << (kQ - 1))) >> kQ);
}
I128 qdiv(I128 a, I128 b) { return (a << kQ) / b; }  // a < 2^64 in use: no overflow

// ln(m) for m in [1/2, 1] via 2*atanh((m-1)/(m+1)); |y| <= 1/3, so 40 terms exceed 2^-62.
I128 lnReduced(I128 m) {
  const I128 y = qdiv(m - kOne, m + kOne);
  const I128 y2 = qmul(y, y);
  I128 term = y, sum = 0;
  for (int k = 1; k < 120 && term != 0; k += 2) {
    sum += term / k;
    term = qmul(term, y2);
  }
  return 2 * sum;
}
I128 ln2() { return -lnReduced(kOne / 2); }

// exp(x) for x <= 0 in Q62: x = -k ln2 + r with r in (-ln2, 0], Taylor series for exp(r).
I128 expNonPositive(I128 x) {
  const I128 l2 = ln2();
  I128 k = (-x) / l2;
  const I128 r = x + k * l2;  // in (-ln2, 0]
  I128 term = kOne, sum = kOne;
  for (int n = 1; n < 60 && term != 0; ++n) {
    term = qmul(term, r) / n;
    sum += term;
  }
  if (k >= 120) return 0;
  return sum >> int(k);
}

/// a * b / 2^62 for a, b >= 0 without a 256-bit product: b is split in 32-bit halves. Returns
/// false when the result exceeds 2^97 (then exp(-result) is 0 in Q62 anyway).
bool mulQ62Wide(I128 a, I128 b, I128* out) {
  const I128 hi = b >> 32, lo = b & ((I128(1) << 32) - 1);
  I128 ph, pl;
  if (mulOverflow(a, hi, &ph) || mulOverflow(a, lo, &pl)) return false;
  *out = ph / (I128(1) << 30) + pl / (I128(1) << 62);
  return true;
}

int bitLength(I128 v) { return bitLength(U128(v)); }
}  // namespace

Rational deterministicPow(const Rational& base, const Rational& exponent) {
  // Preconditions are checked by the scenario loader: 0 < base <= 1, exponent >= 0.
  if (base.num >= base.den || exponent.num <= 0) return Rational{1, 1};
  if (base.num <= 0) return Rational{0, 1};
  // Exact range reduction: base = m * 2^-e with m in [1/2, 1), m computed to 62 bits by exact
  // long division (so a tiny base or one with 30 digits keeps its full precision).
  int e = std::max(0, bitLength(base.den) - bitLength(base.num) - 1);
  I128 m = 0;
  for (int tries = 0; tries < 4; ++tries) {
    m = *base.toScaledInteger(kQ + e);  // base * 2^(62 + e) < 2^63: always fits
    if (m < kOne / 2)
      ++e;
    else if (m >= kOne)
      --e;
    else
      break;
  }
  const I128 lnBase = lnReduced(m) - I128(e) * ln2();  // <= 0, |lnBase| < 2^70
  // x = exponent * ln(base). An x too large for 128 bits means base^exponent < 2^-(2^35): 0.
  const auto scaledExponent = exponent.toScaledInteger(kQ);
  I128 magnitude;
  if (!scaledExponent || !mulQ62Wide(-lnBase, *scaledExponent, &magnitude)) return Rational{0, 1};
  return *Rational::make(expNonPositive(-magnitude), kOne);
}
}  // namespace sg
