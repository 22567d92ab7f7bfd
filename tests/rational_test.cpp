// sg::Rational: exact scenario numbers, their parsing, arithmetic and one-rounding conversions,
// and sg::deterministicPow, all against independent references (exact __int128 arithmetic,
// strtod, powl). Random samples come from fixed-seed std::mt19937_64 generators.
#include <gtest/gtest.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "sim/math/rational.h"
#include "sim/math/scalar.h"
#include "tests/printers.h"

namespace {

using sg::Rational;
using I128 = __int128;
using U128 = unsigned __int128;

std::string str(I128 v) {
  if (v == 0) return "0";
  U128 m = v < 0 ? U128(0) - U128(v) : U128(v);
  std::string s;
  while (m != 0) {
    s.push_back(char('0' + int(m % 10)));
    m /= 10;
  }
  if (v < 0) s.push_back('-');
  return std::string(s.rbegin(), s.rend());
}
std::string str(const Rational& r) { return str(r.num) + "/" + str(r.den); }
std::string str(const std::optional<Rational>& r) { return r ? str(*r) : std::string("nullopt"); }

I128 pow10(int k) {
  I128 p = 1;
  while (k-- > 0) p *= 10;
  return p;
}
I128 gcd(I128 a, I128 b) {
  if (a < 0) a = -a;
  if (b < 0) b = -b;
  while (b != 0) {
    const I128 t = a % b;
    a = b;
    b = t;
  }
  return a;
}
/// Reduced, positive denominator: the invariant every Rational must keep.
bool canonical(const Rational& r) { return r.den > 0 && gcd(r.num, r.den) == 1; }

/// n / d rounded to nearest, ties away from zero, via floor division and the remainder.
I128 refRoundDiv(I128 n, I128 d) {
  if (d < 0) {
    n = -n;
    d = -d;
  }
  I128 q = n / d;
  if (n % d != 0 && n < 0) --q;  // floor
  const I128 r = n - q * d;      // 0 <= r < d
  if (2 * r > d || (2 * r == d && n > 0)) ++q;
  return q;
}

std::optional<Rational> parse(const std::string& s, std::string* err = nullptr) { return Rational::parse(s, err); }

// ---- parsing -----------------------------------------------------------------------------------

TEST(RationalParse, JsonNumbersAreExact) {
  struct Case {
    const char* text;
    I128 num, den;
  };
  const std::vector<Case> cases = {
      {"0.97", 97, 100},
      {"-12.5e-3", -1, 80},  // -0.0125
      {"1e-36", 1, pow10(36)},
      {"0.1", 1, 10},
      {"1/60", 1, 60},
      {"0", 0, 1},
      {"-0", 0, 1},
      {"0.000", 0, 1},
      {"42", 42, 1},
      {"-7", -7, 1},
      {"2.5E+2", 250, 1},
      {"1E2", 100, 1},
      {"0.00025", 1, 4000},
      {"100.500", 201, 2},
      {"3.14159", 314159, 100000},
      {"9.81", 981, 100},
      {"-9.81e0", -981, 100},
      {"1.5/-0.5", -3, 1},
      {"-1/-2", 1, 2},
      {"0.5/0.25", 2, 1},
      {"1/3", 1, 3},
      {"123456789012345678901234567890", I128(123456789012345678) * I128(1000000000000) + 901234567890, 1},
      {"1e35", pow10(35), 1},
      {"0.000000000000000000000000000000000001", 1, pow10(36)},
  };
  for (const auto& c : cases) {
    std::string err;
    const auto r = parse(c.text, &err);
    ASSERT_TRUE(r.has_value()) << c.text << ": " << err;
    EXPECT_EQ(r->num, c.num) << c.text << " -> " << str(*r);
    EXPECT_EQ(r->den, c.den) << c.text << " -> " << str(*r);
    EXPECT_TRUE(canonical(*r)) << c.text;
  }
  // A null error pointer is allowed.
  EXPECT_TRUE(Rational::parse("0.5", nullptr).has_value());
  EXPECT_FALSE(Rational::parse("x", nullptr).has_value());
}

TEST(RationalParse, ErrorsSayWhatWasExpected) {
  struct Case {
    const char* text;
    const char* expectInError;
  };
  const std::vector<Case> cases = {
      {"3/0", "non-zero denominator"},
      {"1/0.0", "non-zero denominator"},
      {"abc", "a number"},
      {"", "a number"},
      {"-", "a number"},
      {".", "a number"},
      {"1e", "exponent"},
      {"1e+", "exponent"},
      {"1.2.3", "a number"},
      {"--1", "a number"},
      {"1/2/3", "a number"},
      {"0x10", "a number"},
      {"1 ", "a number"},
      {" 1", "a number"},
      {"nan", "a number"},
      {"1234567890123456789012345678901", "30 significant digits"},  // 31 digits
      {"0.1234567890123456789012345678901", "30 significant digits"},
      {"1e40", "1e36"},
      {"1e-40", "1e-36"},
      {"1e-37", "1e-36"},
      {"123e34", "1e36"},
  };
  for (const auto& c : cases) {
    std::string err;
    const auto r = parse(c.text, &err);
    EXPECT_FALSE(r.has_value()) << "'" << c.text << "' parsed as " << str(r);
    EXPECT_NE(err.find(c.expectInError), std::string::npos) << "'" << c.text << "': error '" << err << "'";
  }
}

TEST(RationalParse, DecimalsAreExactNotBinary) {
  const Rational tenth = *parse("0.1");
  EXPECT_EQ(tenth, (Rational{1, 10}));
  EXPECT_EQ(tenth, *parse("1/10"));
  EXPECT_EQ(tenth, *parse("1e-1"));
  EXPECT_EQ(*sg::mul(tenth, Rational::integer(10)), Rational::integer(1));
  // 0.1 + 0.2 == 0.3 exactly (unlike binary floating point).
  EXPECT_EQ(*sg::add(tenth, *parse("0.2")), *parse("0.3"));
  EXPECT_EQ(sg::compare(*sg::add(tenth, *parse("0.2")), *parse("0.3")), 0);
  // Leading and trailing zeros do not change the value.
  EXPECT_EQ(*parse("000.97000"), *parse("0.97"));
  EXPECT_EQ(*parse("0.0001e4"), Rational::integer(1));
}

// ---- toDouble -------------------------------------------------------------------------------

TEST(RationalToDouble, MatchesStrtod) {
  // glibc's strtod is correctly rounded (nearest, ties to even) for any decimal, and so is
  // toDouble for any num/den: they must agree exactly, small operands or not.
  std::mt19937_64 g(0x7a7a);
  int parsed = 0, smallChecked = 0, largeChecked = 0;
  const int kN = 100000;
  for (int i = 0; i < kN; ++i) {
    // A random decimal: 1..30 significant digits (the parser's limit), an optional point, an
    // optional exponent.
    const int digits = 1 + int(g() % (g() % 4 == 0 ? 30 : 17));
    std::string s = (g() & 1) ? "-" : "";
    std::string mant;
    for (int k = 0; k < digits; ++k) mant += char('0' + int(g() % 10));
    if (g() & 1) mant.insert(mant.begin() + std::ptrdiff_t(g() % (mant.size() + 1)), '.');
    if (mant.front() == '.') mant.insert(mant.begin(), '0');
    s += mant;
    if (g() % 3 != 0) {
      s += 'e';
      s += std::to_string(int(g() % 41) - 20);
    }
    const auto r = parse(s);
    if (!r) continue;
    ++parsed;
    const double got = r->toDouble();
    errno = 0;
    const double want = std::strtod(s.c_str(), nullptr);
    constexpr I128 k2p53 = I128(1) << 53;
    // Both operands below 2^53 (one IEEE division would round the same) or not.
    ++(r->num > -k2p53 && r->num < k2p53 && r->den < k2p53 ? smallChecked : largeChecked);
    ASSERT_EQ(got, want) << s << " = " << str(*r) << ": got " << got << " want " << want;
  }
  EXPECT_GT(parsed, kN * 9 / 10);
  EXPECT_GT(smallChecked, kN / 4);
  EXPECT_GT(largeChecked, kN / 10);
  EXPECT_EQ(parse("0.1")->toDouble(), 0.1);
  EXPECT_EQ(parse("1/3")->toDouble(), 1.0 / 3.0);
  EXPECT_EQ(parse("-0.97")->toDouble(), -0.97);
}

/// Unsigned big integers as 32-bit digits (little-endian), just enough for exact comparisons of
/// products of 128-bit values scaled by powers of two: independent of the code under test.
using Big = std::vector<uint32_t>;
Big big(U128 v) {
  Big r;
  for (; v != 0; v >>= 32) r.push_back(uint32_t(v));
  return r;
}
Big mulBig(const Big& a, const Big& b) {
  Big r(a.size() + b.size(), 0);
  for (size_t i = 0; i < a.size(); ++i) {
    uint64_t carry = 0;
    for (size_t j = 0; j < b.size(); ++j) {
      const uint64_t t = uint64_t(a[i]) * b[j] + r[i + j] + carry;
      r[i + j] = uint32_t(t);
      carry = t >> 32;
    }
    r[i + b.size()] = uint32_t(carry);
  }
  return r;
}
Big shlBig(const Big& a, int n) {
  Big r(size_t(n / 32), 0);
  uint32_t carry = 0;
  for (uint32_t d : a) {
    r.push_back(n % 32 == 0 ? d : (d << (n % 32)) | carry);
    carry = n % 32 == 0 ? 0 : d >> (32 - n % 32);
  }
  r.push_back(carry);
  return r;
}
int cmpBig(Big a, Big b) {
  while (!a.empty() && a.back() == 0) a.pop_back();
  while (!b.empty() && b.back() == 0) b.pop_back();
  if (a.size() != b.size()) return a.size() < b.size() ? -1 : 1;
  for (size_t i = a.size(); i-- > 0;)
    if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
  return 0;
}
/// Sign of n/d - m * 2^e for n, d, m > 0.
int cmpWithScaled(U128 n, U128 d, U128 m, int e) {
  return cmpBig(shlBig(big(n), e < 0 ? -e : 0), shlBig(mulBig(big(m), big(d)), e > 0 ? e : 0));
}

/// Checks that c is the double nearest to |num|/den, ties to even, from the exact midpoints to
/// c's neighbours (c = M * 2^E with a 53-bit M; below a power of two the lower neighbour is
/// half as far).
::testing::AssertionResult correctlyRounded(const Rational& r, double c) {
  const U128 n = r.num < 0 ? U128(0) - U128(r.num) : U128(r.num), d = U128(r.den);
  if ((c < 0) != (r.num < 0) || c == 0) return ::testing::AssertionFailure() << "sign or zero";
  int ex = 0;
  const double f = std::frexp(std::fabs(c), &ex);  // exact
  const uint64_t m = uint64_t(std::ldexp(f, 53));  // exact: 2^52 <= m < 2^53
  const int e = ex - 53;
  const int above = cmpWithScaled(n, d, 2 * U128(m) + 1, e - 1);
  const int below = m == (uint64_t(1) << 52) ? cmpWithScaled(n, d, 4 * U128(m) - 1, e - 2)
                                             : cmpWithScaled(n, d, 2 * U128(m) - 1, e - 1);
  if (above > 0 || below < 0) return ::testing::AssertionFailure() << "not the nearest double";
  if ((above == 0 || below == 0) && (m & 1) != 0) return ::testing::AssertionFailure() << "tie not to even";
  return ::testing::AssertionSuccess();
}

TEST(RationalToDouble, CorrectlyRoundedForAnySize) {
  // num and den of every bit length up to 127, so the quotient spans 2^-127 .. 2^127 and the
  // long division produces anywhere from 54 to 127 quotient bits.
  std::mt19937_64 g(0xd0b1e);
  auto draw = [&g]() -> I128 {
    const int bits = 1 + int(g() % 127);
    const U128 v = ((U128(g()) << 64 | g()) >> (128 - bits)) | (U128(1) << (bits - 1));
    return I128(v);
  };
  for (int i = 0; i < 50000; ++i) {
    const I128 num = g() & 1 ? -draw() : draw();
    const auto r = Rational::make(num, draw());
    ASSERT_TRUE(r.has_value());
    ASSERT_TRUE(correctlyRounded(*r, r->toDouble())) << str(*r) << " -> " << r->toDouble();
  }
}

TEST(RationalToDouble, TiesGoToEvenAndTheStickyBitCounts) {
  const I128 k2p53 = I128(1) << 53;
  EXPECT_EQ((Rational{k2p53 + 1, 1}).toDouble(), 9007199254740992.0);      // 2^53 + 1, a tie: down to even
  EXPECT_EQ((Rational{k2p53 + 3, 1}).toDouble(), 9007199254740996.0);      // 2^53 + 3, a tie: up to even
  EXPECT_EQ((Rational{4 * k2p53 + 5, 4}).toDouble(), 9007199254740994.0);  // 2^53 + 1.25: above the tie (sticky)
  EXPECT_EQ((Rational{4 * k2p53 + 3, 4}).toDouble(), 9007199254740992.0);  // 2^53 + 0.75
  EXPECT_EQ((Rational{2 * k2p53 + 3, 2}).toDouble(), 9007199254740994.0);  // 2^53 + 1.5
  // Huge numerators and denominators: no long double on the way.
  EXPECT_EQ((Rational{sg::kInt128Max, 1}).toDouble(), std::ldexp(1.0, 127));
  EXPECT_EQ((Rational{sg::kInt128Min + 1, 1}).toDouble(), -std::ldexp(1.0, 127));
  EXPECT_EQ((Rational{1, sg::kInt128Max}).toDouble(), std::ldexp(1.0, -127));
  EXPECT_EQ((Rational{1, I128(1) << 126}).toDouble(), std::ldexp(1.0, -126));
  EXPECT_EQ((Rational{1, 3 * (I128(1) << 100)}).toDouble(), std::ldexp(1.0 / 3.0, -100));
  EXPECT_EQ((Rational{(I128(1) << 120) + 1, 1}).toDouble(), std::ldexp(1.0, 120));
}

// ---- toScaledInteger / roundToInt64 ----------------------------------------------------------------

TEST(RationalRounding, ScaledIntegerTiesAwayFromZero) {
  // (2k + 1) / 2^33 scaled by 2^32 is k + 1/2: must round to k + 1, and -(k + 1) when negative.
  std::mt19937_64 g(3);
  for (int i = 0; i < 20000; ++i) {
    const I128 k = I128(g() >> 2);
    const Rational pos{2 * k + 1, I128(1) << 33}, neg{-(2 * k + 1), I128(1) << 33};
    ASSERT_EQ(pos.toScaledInteger(32), k + 1) << str(pos);
    ASSERT_EQ(neg.toScaledInteger(32), -(k + 1)) << str(neg);
    // One part in 2^40 below / above the tie.
    const Rational below{(2 * k + 1) * 128 - 1, I128(1) << 40}, above{(2 * k + 1) * 128 + 1, I128(1) << 40};
    ASSERT_EQ(below.toScaledInteger(32), k) << str(below);
    ASSERT_EQ(above.toScaledInteger(32), k + 1) << str(above);
    ASSERT_EQ((Rational{-below.num, below.den}).toScaledInteger(32), -k);
    ASSERT_EQ((Rational{-above.num, above.den}).toScaledInteger(32), -(k + 1));
  }
  EXPECT_EQ((Rational{1, 2}).toScaledInteger(0), 1);
  EXPECT_EQ((Rational{-1, 2}).toScaledInteger(0), -1);
  EXPECT_EQ((Rational{5, 2}).toScaledInteger(0), 3);  // not banker's 2
  EXPECT_EQ((Rational{-5, 2}).toScaledInteger(0), -3);
  EXPECT_EQ((Rational{1, 3}).toScaledInteger(0), 0);
  EXPECT_EQ((Rational{2, 3}).toScaledInteger(0), 1);
  EXPECT_EQ((Rational{0, 1}).toScaledInteger(32), 0);
  // Huge denominators (the long division must not overflow): 0.5 +- 2^-121.
  EXPECT_EQ((Rational{(I128(1) << 120) + 1, I128(1) << 121}).toScaledInteger(0), 1);
  EXPECT_EQ((Rational{(I128(1) << 120) - 1, I128(1) << 121}).toScaledInteger(0), 0);
  EXPECT_EQ((Rational{(I128(1) << 120) - 1, I128(1) << 121}).toScaledInteger(1), 1);
  EXPECT_EQ((Rational{(I128(1) << 120) + 1, I128(1) << 121}).toScaledInteger(32), I128(1) << 31);
  EXPECT_EQ((Rational{-((I128(1) << 120) + 1), I128(1) << 121}).toScaledInteger(0), -1);
}

TEST(RationalRounding, ScaledIntegerMatchesExactReference) {
  std::mt19937_64 g(4);
  const int fracs[] = {0, 1, 16, 32, 62};
  for (int i = 0; i < 100000; ++i) {
    const I128 n = I128(int64_t(g()) >> (4 + g() % 60));  // |n| < 2^60
    const I128 d = I128((g() >> (4 + g() % 60)) | 1);     // 1 <= d < 2^60
    const Rational r = *Rational::make(n, d);
    const int f = fracs[i % 5];
    const I128 want = refRoundDiv(r.num * (I128(1) << f), r.den);  // |num| 2^62 < 2^122: exact
    ASSERT_EQ(r.toScaledInteger(f), want) << str(r) << " frac " << f;
  }
}

TEST(RationalRounding, ScaledIntegerRangeLimit) {
  // Documented: nullopt when |result| >= 2^126.
  EXPECT_FALSE((Rational{I128(1) << 94, 1}).toScaledInteger(32).has_value());
  EXPECT_FALSE((Rational{-(I128(1) << 94), 1}).toScaledInteger(32).has_value());
  EXPECT_EQ((Rational{(I128(1) << 94) - 1, 1}).toScaledInteger(32), ((I128(1) << 94) - 1) << 32);
  EXPECT_EQ((Rational{-((I128(1) << 94) - 1), 1}).toScaledInteger(32), -(((I128(1) << 94) - 1) << 32));
  // 2^94 - 2^-33 scales to 2^126 - 1/2, which rounds up to 2^126: out of range.
  const I128 k2p127m1 = I128(~U128(0) >> 1);
  EXPECT_FALSE((Rational{k2p127m1, I128(1) << 33}).toScaledInteger(32).has_value());
  // 2^94 - 2^-31 scales to 2^126 - 2: fits.
  EXPECT_EQ((Rational{(I128(1) << 125) - 1, I128(1) << 31}).toScaledInteger(32), (I128(1) << 126) - 2);
}

TEST(RationalRounding, RoundToInt64) {
  EXPECT_EQ((Rational{5, 2}).roundToInt64(), 3);
  EXPECT_EQ((Rational{-5, 2}).roundToInt64(), -3);
  EXPECT_EQ((Rational{7, 3}).roundToInt64(), 2);
  EXPECT_EQ((Rational{-7, 3}).roundToInt64(), -2);
  EXPECT_EQ((Rational{8, 3}).roundToInt64(), 3);
  EXPECT_EQ(Rational::integer(INT64_MAX).roundToInt64(), INT64_MAX);
  EXPECT_EQ(Rational::integer(INT64_MIN).roundToInt64(), INT64_MIN);
  EXPECT_FALSE((Rational{I128(INT64_MAX) + 1, 1}).roundToInt64().has_value());
  EXPECT_FALSE((Rational{I128(INT64_MIN) - 1, 1}).roundToInt64().has_value());
  // 2^63 - 1/2 rounds away from zero to 2^63: does not fit. -2^63 + 1/2 rounds to -2^63: fits.
  EXPECT_FALSE((Rational{(I128(1) << 64) - 1, 2}).roundToInt64().has_value());
  EXPECT_EQ((Rational{-((I128(1) << 64) - 1), 2}).roundToInt64(), INT64_MIN);
  EXPECT_EQ((Rational{(I128(1) << 64) - 3, 2}).roundToInt64(), INT64_MAX);  // 2^63 - 3/2 -> 2^63 - 1
  EXPECT_FALSE((Rational{-((I128(1) << 64) + 1), 2}).roundToInt64().has_value());
  EXPECT_FALSE((Rational{I128(1) << 120, 3}).roundToInt64().has_value());
}

// ---- arithmetic -----------------------------------------------------------------------------------

TEST(RationalArithmetic, MatchesCrossMultiplication) {
  std::mt19937_64 g(5);
  auto draw = [&] {
    const I128 n = I128(int64_t(g()) >> (33 + g() % 30));  // |n| < 2^31
    const I128 d = I128((g() >> (33 + g() % 30)) + 1);     // 1 <= d <= 2^31
    return *Rational::make(n, d);
  };
  for (int i = 0; i < 50000; ++i) {
    const Rational a = draw(), b = draw();
    ASSERT_TRUE(canonical(a) && canonical(b));
    // a + b = (an bd + bn ad) / (ad bd): every term < 2^64, exact.
    const auto s = sg::add(a, b);
    ASSERT_TRUE(s && canonical(*s));
    ASSERT_EQ(s->num * (a.den * b.den), (a.num * b.den + b.num * a.den) * s->den) << str(a) << " + " << str(b);
    const auto dsub = sg::sub(a, b);
    ASSERT_TRUE(dsub && canonical(*dsub));
    ASSERT_EQ(dsub->num * (a.den * b.den), (a.num * b.den - b.num * a.den) * dsub->den) << str(a) << " - " << str(b);
    const auto p = sg::mul(a, b);
    ASSERT_TRUE(p && canonical(*p));
    ASSERT_EQ(p->num * (a.den * b.den), (a.num * b.num) * p->den) << str(a) << " * " << str(b);
    const auto q = sg::div(a, b);
    if (b.num == 0) {
      ASSERT_FALSE(q.has_value());
    } else {
      ASSERT_TRUE(q && canonical(*q));
      ASSERT_EQ(q->num * (a.den * b.num), (a.num * b.den) * q->den) << str(a) << " / " << str(b);
    }
    const I128 l = a.num * b.den, r = b.num * a.den;
    ASSERT_EQ(sg::compare(a, b), l < r ? -1 : (l > r ? 1 : 0)) << str(a) << " <=> " << str(b);
    ASSERT_EQ(sg::compare(b, a), -sg::compare(a, b));
  }
}

TEST(RationalArithmetic, CompareIsExactForAnySize) {
  // Operands whose cross products need up to 254 bits (the old code fell back to long double
  // there): against exact big-integer cross products.
  std::mt19937_64 g(0xc0c0);
  auto draw = [&g](bool positive) -> I128 {
    const int bits = 1 + int(g() % 127);
    const I128 v = I128(((U128(g()) << 64 | g()) >> (128 - bits)) | (U128(1) << (bits - 1)));
    return positive || (g() & 1) ? v : -v;
  };
  auto mag = [](I128 v) { return v < 0 ? U128(0) - U128(v) : U128(v); };
  for (int i = 0; i < 50000; ++i) {
    const auto a = Rational::make(draw(false), draw(true));
    // Every fourth pair shares a's value up to a tiny step, so near-equal values are compared.
    auto b = Rational::make(draw(false), draw(true));
    if (i % 4 == 0) b = sg::add(*a, g() % 3 == 0 ? Rational{0, 1} : Rational{1, I128(1) << 120});
    if (!b) continue;
    const int sa = a->num < 0 ? -1 : 1, sb = b->num < 0 ? -1 : (b->num > 0 ? 1 : 0);
    int want = sa != sb ? (sa < sb ? -1 : 1)
                        : sa * cmpBig(mulBig(big(mag(a->num)), big(U128(b->den))),
                                      mulBig(big(mag(b->num)), big(U128(a->den))));
    ASSERT_EQ(sg::compare(*a, *b), want) << str(*a) << " <=> " << str(*b);
    ASSERT_EQ(sg::compare(*b, *a), -want);
  }
}

TEST(RationalArithmetic, OverflowIsReportedNotWrapped) {
  const Rational big{I128(1) << 126, 1};
  EXPECT_FALSE(sg::add(big, big).has_value());
  EXPECT_FALSE(sg::sub(Rational{-(I128(1) << 126), 1}, Rational{(I128(1) << 126) + 1, 1}).has_value());
  EXPECT_FALSE(sg::mul(Rational{I128(1) << 100, 1}, Rational{I128(1) << 30, 1}).has_value());
  EXPECT_FALSE(sg::div(Rational{I128(1) << 100, 1}, Rational{1, I128(1) << 30}).has_value());
  EXPECT_FALSE(sg::div(Rational{1, 3}, Rational{0, 1}).has_value());
  // Cross-reduction keeps exact results that fit: (2^100/3) * (3/2^100) = 1.
  EXPECT_EQ(sg::mul(Rational{I128(1) << 100, 3}, Rational{3, I128(1) << 100}), Rational::integer(1));
  EXPECT_EQ(sg::div(Rational{I128(1) << 100, 3}, Rational{I128(1) << 100, 3}), Rational::integer(1));
  // compare never fails, even when the difference does not fit.
  EXPECT_EQ(sg::compare(big, Rational{-(I128(1) << 126), 1}), 1);
  EXPECT_EQ(sg::compare(Rational{-(I128(1) << 126), 1}, big), -1);
  EXPECT_EQ(sg::compare(Rational{1, 3}, Rational{1, 3}), 0);
  EXPECT_EQ(sg::compare(Rational{1, 3}, Rational{1, 2}), -1);
  EXPECT_EQ(sg::compare(Rational{-1, 3}, Rational{-1, 2}), 1);
}

TEST(RationalArithmetic, MakeNormalisesAndPredicates) {
  EXPECT_EQ(Rational::make(6, -4), (Rational{-3, 2}));
  EXPECT_EQ(Rational::make(-6, -4), (Rational{3, 2}));
  EXPECT_EQ(Rational::make(0, -5), (Rational{0, 1}));
  EXPECT_EQ(Rational::make(10, 5), (Rational{2, 1}));
  EXPECT_FALSE(Rational::make(1, 0).has_value());
  EXPECT_EQ(Rational::integer(-7), (Rational{-7, 1}));
  EXPECT_TRUE(Rational{}.isZero());
  EXPECT_TRUE((Rational{-1, 2}).isNegative());
  EXPECT_FALSE((Rational{1, 2}).isNegative());
  EXPECT_FALSE((Rational{1, 2}).isInteger());
  EXPECT_TRUE(Rational::integer(3).isInteger());
  EXPECT_EQ(parse("-12.5e-3")->toString(), "-1/80");
  EXPECT_EQ(parse("1/60")->toString(), "1/60");
  EXPECT_EQ(parse("42")->toString(), "42");
  EXPECT_EQ(parse("0")->toString(), "0");
  EXPECT_EQ(parse("1e-36")->toString(), "1/1000000000000000000000000000000000000");
}

// ---- conversion into the scalars ------------------------------------------------------------------

TEST(RationalScalar, FixedFromRationalRoundsOnce) {
  // round(0.97 * 2^32) = round(97 * 2^32 / 100) = 4166118277 (remainder 12 of 100: down).
  const I128 n = I128(97) << 32;
  ASSERT_EQ(n / 100, 4166118277);
  ASSERT_EQ(n % 100, 12);
  const auto v = sg::ScalarTraits<sg::Fx32>::fromRational(*parse("0.97"));
  ASSERT_TRUE(v.has_value());
  EXPECT_EQ(v->raw(), 4166118277);
  EXPECT_EQ(sg::ScalarTraits<sg::Fx32>::fromRational(*parse("-0.97"))->raw(), -4166118277);
  // Q16.16: 97 * 65536 / 100 = 63569.92 -> 63570.
  EXPECT_EQ(sg::ScalarTraits<sg::Fx16>::fromRational(*parse("0.97"))->raw(), 63570);
  // 1/60 in Q32.32: 2^32 / 60 = 71582788.27 -> 71582788.
  EXPECT_EQ(sg::ScalarTraits<sg::Fx32>::fromRational(*parse("1/60"))->raw(), 71582788);
  // A tie: 3 / 2^33 is 1.5 ulps of Q32.32 -> 2 ulps; negative -> -2.
  EXPECT_EQ(sg::ScalarTraits<sg::Fx32>::fromRational(Rational{3, I128(1) << 33})->raw(), 2);
  EXPECT_EQ(sg::ScalarTraits<sg::Fx32>::fromRational(Rational{-3, I128(1) << 33})->raw(), -2);
  // Range: Q32.32 < 2^31, Q16.16 < 2^15; values that round to max still fit.
  EXPECT_FALSE(sg::ScalarTraits<sg::Fx32>::fromRational(*parse("3e9")).has_value());
  EXPECT_FALSE(sg::ScalarTraits<sg::Fx32>::fromRational(*parse("2147483648")).has_value());
  EXPECT_EQ(sg::ScalarTraits<sg::Fx32>::fromRational(*parse("-2147483648")), sg::Fx32::min());
  EXPECT_FALSE(sg::ScalarTraits<sg::Fx16>::fromRational(*parse("40000")).has_value());
  EXPECT_FALSE(sg::ScalarTraits<sg::Fx16>::fromRational(*parse("32768")).has_value());
  EXPECT_EQ(sg::ScalarTraits<sg::Fx16>::fromRational(*parse("32767.99999")), sg::Fx16::max());
  EXPECT_EQ(sg::ScalarTraits<sg::Fx16>::fromRational(*parse("-32768")), sg::Fx16::min());
  EXPECT_FALSE(sg::ScalarTraits<sg::Fx16>::fromRational(*parse("-32768.00001")).has_value());
  // Float scalars take the correctly rounded double.
  EXPECT_EQ(*sg::ScalarTraits<double>::fromRational(*parse("0.97")), 0.97);
  EXPECT_EQ(*sg::ScalarTraits<float>::fromRational(*parse("0.1")), 0.1f);
  EXPECT_EQ(sg::pendingFixedFaults(), 0u) << "fromRational reports range by nullopt, not by faults";
}

TEST(RationalScalar, FixedFromRationalMatchesReferenceForRandomDecimals) {
  std::mt19937_64 g(6);
  for (int i = 0; i < 50000; ++i) {
    // value = m * 10^-e with |m| < 10^9, e in 0..12: within range of both formats' conversion.
    const int64_t m = int64_t(g() % 2000000000) - 1000000000;
    const int e = int(g() % 13);
    const std::string s = std::to_string(m) + "e-" + std::to_string(e);
    const Rational r = *parse(s);
    const I128 want32 = refRoundDiv(I128(m) << 32, pow10(e));
    const auto got32 = sg::ScalarTraits<sg::Fx32>::fromRational(r);
    if (want32 >= I128(INT64_MIN) && want32 <= I128(INT64_MAX)) {
      ASSERT_TRUE(got32.has_value()) << s;
      ASSERT_EQ(I128(got32->raw()), want32) << s;
    } else {
      ASSERT_FALSE(got32.has_value()) << s;
    }
    const I128 want16 = refRoundDiv(I128(m) << 16, pow10(e));
    const auto got16 = sg::ScalarTraits<sg::Fx16>::fromRational(r);
    if (want16 >= I128(INT32_MIN) && want16 <= I128(INT32_MAX)) {
      ASSERT_TRUE(got16.has_value()) << s;
      ASSERT_EQ(I128(got16->raw()), want16) << s;
    } else {
      ASSERT_FALSE(got16.has_value()) << s;
    }
  }
}

// ---- deterministicPow --------------------------------------------------------------------------

long double asLd(const Rational& r) { return static_cast<long double>(r.num) / static_cast<long double>(r.den); }

/// Tolerance, derived from the Q2.62 implementation: every fixed-point step (qdiv, qmul, the
/// series terms) errs by at most one unit of 2^-62 = 2.2e-19. ln(m) sums <= 60 such terms and
/// e * ln2 adds e <= 10 copies of ln2's error (bases >= 1e-3), so |d ln(base)| < 1e-17; the
/// exponent (<= 2.5) scales that to |dx| < 3e-17, plus 2^-62 for the truncating division. exp(x)
/// then has relative error |dx| + (<= 60 series roundings) 1.3e-17, and truncating the base to
/// Q62 costs 2^-62 / base <= 2.2e-16 relative in ln -> <= 5.5e-16 in the result: all well below
/// 1e-15 relative. The result is an integer multiple of 2^-62, so on top of that it can be off
/// by its final >> k truncation: a few units of 2^-62 absolute (this dominates tiny results such
/// as 0.001^2.5 = 3.2e-8). The powl reference errs by < 1e-18 relative (80-bit long double).
constexpr long double kPowRel = 1e-15L;
const long double kPowAbs = 4.0L * std::ldexp(1.0L, -62);

::testing::AssertionResult powClose(const char* baseText, const char* expText) {
  const auto b = parse(baseText), e = parse(expText);
  if (!b || !e) return ::testing::AssertionFailure() << "parse " << baseText << " " << expText;
  const Rational got = sg::deterministicPow(*b, *e);
  const long double ref = powl(asLd(*b), asLd(*e));
  const long double g = asLd(got);
  const long double err = fabsl(g - ref);
  std::ostringstream o;
  o.precision(21);
  o << baseText << " ^ " << expText << ": got " << g << " (" << str(got) << "), powl " << ref << ", error " << err
    << " (" << double(err / ref) << " relative)";
  // Documented form: an exact fraction raw / 2^62.
  if (got.den <= 0 || (got.den & (got.den - 1)) != 0 || got.den > (I128(1) << 62))
    return ::testing::AssertionFailure() << o.str() << ": denominator is not a power of two <= 2^62";
  if (!(err <= kPowRel * ref + kPowAbs)) return ::testing::AssertionFailure() << o.str();
  return ::testing::AssertionSuccess() << o.str();
}

TEST(RationalPow, MatchesPowlForDampingLikeInputs) {
  const char* bases[] = {"0.97", "0.5", "0.999", "1e-3", "1", "0.123456789", "0.9999999999", "0.01", "0.75"};
  const char* exps[] = {"1/60", "1/240", "1", "2.5", "0", "0.00001", "1/7", "0.5"};
  for (const char* b : bases)
    for (const char* e : exps) EXPECT_TRUE(powClose(b, e));
}

TEST(RationalPow, ExactlyOneForUnitBaseOrZeroExponent) {
  const char* values[] = {"0.97", "0.5", "1e-3", "1", "0.999", "1e-30"};
  for (const char* v : values) {
    EXPECT_EQ(sg::deterministicPow(*parse(v), Rational{0, 1}), Rational::integer(1)) << v << " ^ 0";
    EXPECT_EQ(sg::deterministicPow(Rational::integer(1), *parse(v)), Rational::integer(1)) << "1 ^ " << v;
  }
  // Exact powers of two come out exact: 0.5^1 = 1/2, 0.25^0.5 = 1/2 (within a 2^-62 unit).
  const Rational half = sg::deterministicPow(Rational{1, 2}, Rational::integer(1));
  EXPECT_LE(sg::compare(*sg::sub(half, Rational{1, 2}), Rational{1, I128(1) << 61}), 0) << str(half);
  EXPECT_GE(sg::compare(*sg::sub(half, Rational{1, 2}), Rational{-1, I128(1) << 61}), 0) << str(half);
  // Monotone in the exponent for a base below 1.
  const Rational a = sg::deterministicPow(*parse("0.97"), *parse("1/240"));
  const Rational b = sg::deterministicPow(*parse("0.97"), *parse("1/60"));
  EXPECT_EQ(sg::compare(b, a), -1);
  EXPECT_EQ(sg::compare(a, Rational::integer(1)), -1);
  EXPECT_EQ(sg::compare(b, *parse("0.97")), 1);
}

/// The scenario loader accepts any damping in (0, 1] and any time step in [1e-5, 1] with up to
/// 30 significant digits; the documented accuracy (about 1e-17) should hold for all of them.
TEST(RationalPow, SmallBasesKeepAccuracy) {
  const char* bases[] = {"1e-6", "1e-12", "1e-18", "1e-20", "1e-30"};
  const char* exps[] = {"1/60", "1/240", "0.00001"};
  for (const char* b : bases)
    for (const char* e : exps) EXPECT_TRUE(powClose(b, e));
}

TEST(RationalPow, ManyDigitInputsDoNotOverflow) {
  // 20 and 21 nines: numerators 10^20 - 1 and 10^21 - 1 exceed 2^64.
  EXPECT_TRUE(powClose("0.99999999999999999999", "1/60"));
  EXPECT_TRUE(powClose("0.999999999999999999999", "1/60"));
  EXPECT_TRUE(powClose("0.97", "0.0166666666666666666666666667"));  // 1/60 to 28 digits
  EXPECT_TRUE(powClose("0.001", "0.01666666666666666667"));
  EXPECT_TRUE(powClose("0.5", "0.016666666666666666666667"));  // numerator ~2^74 times ln(0.5) 2^62
}

/// Results below 2^-63 round to 0 in Q2.62; a huge exponent must not overflow the product
/// exponent * ln(base) into a wrong, large result.
TEST(RationalPow, HugeExponentsUnderflowToZero) {
  EXPECT_TRUE(powClose("1e-36", "1"));       // 1e-36 < 2^-63: 0 within the absolute tolerance
  EXPECT_TRUE(powClose("0.999", "100000"));  // e^-100
  EXPECT_TRUE(powClose("0.97", "1000000"));
  EXPECT_TRUE(powClose("0.5", "1000000000"));
  EXPECT_TRUE(powClose("1e-36", "300000000"));
  EXPECT_TRUE(powClose("1e-36", "500000000"));
  EXPECT_TRUE(powClose("1e-36", "1e30"));
  EXPECT_TRUE(powClose("0.9999999999", "1e13"));  // (1 - 1e-10)^1e13 = e^-1000
}

}  // namespace

// Significant digits and magnitude (docs/fixed-point.md): zeros after the last non-zero digit are
// not significant, the limit is on the magnitude, not on the written exponent.
TEST(RationalParse, TrailingZerosAreNotSignificantAndMagnitudeDecides) {
  std::string why;
  auto one = sg::Rational::parse("1.0000000000000000000000000000000000", &why);  // 35 zeros
  ASSERT_TRUE(one) << why;
  EXPECT_EQ(*one, (sg::Rational{1, 1}));
  auto big = sg::Rational::parse("12300000000000000000000000000000000", &why);  // 1.23e34
  ASSERT_TRUE(big) << why;
  EXPECT_EQ(big->num, sg::Rational::parse("1.23e34", nullptr)->num);
  EXPECT_TRUE(sg::Rational::parse("1.5e-36", &why)) << why;
  EXPECT_TRUE(sg::Rational::parse("1.23e-35", &why)) << why;
  EXPECT_TRUE(sg::Rational::parse("9.99e35", &why)) << why;
  EXPECT_FALSE(sg::Rational::parse("1e36", &why));
  EXPECT_NE(why.find("below 1e36"), std::string::npos) << why;
  EXPECT_FALSE(sg::Rational::parse("9e-37", &why));
  EXPECT_TRUE(sg::Rational::parse("1.00000000000000000000000000001", &why)) << "30 significant digits: " << why;
  EXPECT_FALSE(sg::Rational::parse("1.000000000000000000000000000001", &why)) << "31 significant digits";
  EXPECT_NE(why.find("30 significant"), std::string::npos) << why;
  EXPECT_EQ(*sg::Rational::parse("100.500", nullptr), (sg::Rational{201, 2}));
}
