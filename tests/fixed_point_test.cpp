// Fixed-point scalars (sg::Fx32 = Q32.32, sg::Fx16 = Q16.16) against exact references.
//
// Every expected value here is computed independently of the implementation: products and
// quotients exactly in __int128 (or long double where that is exact), rounded by floor division
// plus a remainder comparison (the implementation rounds magnitudes with add-half-and-shift or
// truncating division), square roots checked by the defining inequality on exact integers.
// Random samples come from fixed-seed std::mt19937_64 generators, so failures reproduce.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "sim/math/fixed.h"
#include "sim/math/scalar.h"
#include "sim/math/scalar_ops.h"
#include "tests/printers.h"

namespace {

using sg::Fx16;
using sg::Fx32;
using I128 = __int128;
using U128 = unsigned __int128;

std::string str(U128 v) {
  if (v == 0) return "0";
  std::string s;
  while (v != 0) {
    s.push_back(char('0' + int(v % 10)));
    v /= 10;
  }
  return std::string(s.rbegin(), s.rend());
}
std::string str(I128 v) { return v < 0 ? "-" + str(U128(0) - U128(v)) : str(U128(v)); }

/// Collects mismatches of a large sample; reports the count and the first few inputs.
class Mismatches {
 public:
  template <class F>
  void check(bool ok, F&& describe) {
    ++checked_;
    if (ok) return;
    if (count_++ < 5) first_ += "\n  " + describe();
  }
  ::testing::AssertionResult result() const {
    if (count_ == 0) return ::testing::AssertionSuccess() << checked_ << " checked";
    return ::testing::AssertionFailure() << count_ << " of " << checked_ << " mismatched; first:" << first_;
  }

 private:
  uint64_t checked_ = 0, count_ = 0;
  std::string first_;
};

// ---- exact references ---------------------------------------------------------------------

/// floor(n / d), d != 0, from C++'s truncating division.
I128 floorDiv(I128 n, I128 d) {
  const I128 q = n / d;
  return (n % d != 0 && ((n < 0) != (d < 0))) ? q - 1 : q;
}
/// n / d rounded to nearest, ties away from zero: floor quotient q and remainder 0 <= r < |d|
/// of the sign-normalised fraction, then round up when 2r > |d|, or 2r == |d| and n/d > 0.
I128 refRoundDiv(I128 n, I128 d) {
  if (d < 0) {
    n = -n;
    d = -d;
  }
  const I128 q = floorDiv(n, d);
  const I128 r = n - q * d;  // 0 <= r < d
  if (2 * r > d) return q + 1;
  if (2 * r == d) return n > 0 ? q + 1 : q;  // tie: floor is already away from zero below 0
  return q;
}

/// Exact rounded product raw, before narrowing. Fx32: __int128 + floor-division reference.
/// Fx16: long double (a 64-bit mantissa holds the 62-bit product and /2^16 exactly) + roundl,
/// which rounds halfway cases away from zero.
template <class Fx>
I128 refMul(typename Fx::RawType a, typename Fx::RawType b) {
  if constexpr (std::is_same_v<Fx, Fx16>) {
    const long double exact = static_cast<long double>(int64_t(a) * int64_t(b)) / 65536.0L;
    return I128(static_cast<int64_t>(std::roundl(exact)));
  } else {
    return refRoundDiv(I128(a) * I128(b), I128(1) << Fx::kFracBits);
  }
}
template <class Fx>
I128 refDiv(typename Fx::RawType a, typename Fx::RawType b) {
  return refRoundDiv(I128(a) * (I128(1) << Fx::kFracBits), I128(b));
}
template <class Fx>
bool fits(I128 v) {
  using Raw = typename Fx::RawType;
  return v >= I128(std::numeric_limits<Raw>::min()) && v <= I128(std::numeric_limits<Raw>::max());
}

// ---- random raws -------------------------------------------------------------------------

template <class Fx>
typename Fx::RawType fullRaw(std::mt19937_64& g) {
  return static_cast<typename Fx::RawType>(g());  // modular conversion (defined in C++20)
}
/// Any magnitude: a full-range raw shifted right by 0..bits-1 (sign kept by the shift).
template <class Fx>
typename Fx::RawType anyMagnitudeRaw(std::mt19937_64& g) {
  constexpr int kBits = int(sizeof(typename Fx::RawType) * 8);
  return static_cast<typename Fx::RawType>(fullRaw<Fx>(g) >> int(g() % kBits));
}
/// "Physically typical": uniform over |x| < limit.
template <class Fx>
typename Fx::RawType typicalRaw(std::mt19937_64& g, int64_t limit = 100) {
  const int64_t m = limit * int64_t(Fx::kOneRaw) - 1;
  return static_cast<typename Fx::RawType>(std::uniform_int_distribution<int64_t>(-m, m)(g));
}

/// Raws that are most likely to break rounding and range handling.
template <class Fx>
std::vector<typename Fx::RawType> edgeRaws() {
  using Raw = typename Fx::RawType;
  constexpr Raw kMax = std::numeric_limits<Raw>::max(), kMin = std::numeric_limits<Raw>::min();
  constexpr Raw one = Fx::kOneRaw, half = one / 2;
  std::vector<Raw> v = {0,
                        1,
                        2,
                        3,
                        half - 1,
                        half,
                        half + 1,
                        one - 1,
                        one,
                        one + 1,
                        3 * half,
                        2 * one,
                        3 * one,
                        kMax,
                        kMax - 1,
                        Raw(kMax / 2),
                        Raw(kMax >> (Fx::kFracBits / 2)),
                        Raw(Raw(1) << (sizeof(Raw) * 8 - 2))};
  const size_t n = v.size();
  for (size_t i = 0; i < n; ++i) v.push_back(Raw(-v[i]));  // includes -max
  v.push_back(kMin);
  v.push_back(kMin + 1);
  return v;
}

/// Clears the sticky fault bits before and after each test.
class FaultsCleared : public ::testing::Test {
 protected:
  void SetUp() override { sg::takeFixedFaults(); }
  void TearDown() override { sg::takeFixedFaults(); }
};
using FixedMul = FaultsCleared;
using FixedDiv = FaultsCleared;
using FixedSymmetry = FaultsCleared;
using FixedFault = FaultsCleared;
using FixedSqrt = FaultsCleared;
using FixedIsqrt = FaultsCleared;
using FixedLength3 = FaultsCleared;
using FixedConversion = FaultsCleared;
using FixedMulDiv = FaultsCleared;
using FixedCompare = FaultsCleared;

// ---- multiplication -------------------------------------------------------------------------

/// One product against the reference: the value (wrapped when it does not fit, as documented)
/// and the overflow bit, which must be raised exactly when the rounded result does not fit.
template <class Fx>
void checkMul(Mismatches& m, typename Fx::RawType a, typename Fx::RawType b) {
  using Raw = typename Fx::RawType;
  sg::takeFixedFaults();
  const Raw got = (Fx::fromRaw(a) * Fx::fromRaw(b)).raw();
  const uint32_t faults = sg::takeFixedFaults();
  const I128 want = refMul<Fx>(a, b);
  const uint32_t wantFaults = fits<Fx>(want) ? 0u : uint32_t(sg::kFixedFaultOverflow);
  m.check(got == static_cast<Raw>(want) && faults == wantFaults, [&] {
    return "raw " + str(I128(a)) + " * raw " + str(I128(b)) + ": want " + str(want) + " faults " +
           std::to_string(wantFaults) + ", got " + str(I128(got)) + " faults " + std::to_string(faults);
  });
}

template <class Fx>
void mulSamples(uint64_t seed) {
  std::mt19937_64 g(seed);
  constexpr int kN = 200000;
  Mismatches full, mag, typical, edge;
  for (int i = 0; i < kN; ++i) checkMul<Fx>(full, fullRaw<Fx>(g), fullRaw<Fx>(g));
  for (int i = 0; i < kN; ++i) checkMul<Fx>(mag, anyMagnitudeRaw<Fx>(g), anyMagnitudeRaw<Fx>(g));
  for (int i = 0; i < kN; ++i) checkMul<Fx>(typical, typicalRaw<Fx>(g), typicalRaw<Fx>(g));
  for (auto a : edgeRaws<Fx>())
    for (auto b : edgeRaws<Fx>()) checkMul<Fx>(edge, a, b);
  EXPECT_TRUE(full.result()) << "full raw range";
  EXPECT_TRUE(mag.result()) << "all magnitudes";
  EXPECT_TRUE(typical.result()) << "|x| < 100";
  EXPECT_TRUE(edge.result()) << "edge cases";
}

TEST_F(FixedMul, Fx32MatchesExactRoundedProduct) { mulSamples<Fx32>(0x5eed0001); }
TEST_F(FixedMul, Fx16MatchesExactRoundedProduct) { mulSamples<Fx16>(0x5eed0002); }

/// Hand-computed ties and near-ties (no reference function involved).
TEST_F(FixedMul, HalfUlpTiesRoundAwayFromZero) {
  const Fx32 half = Fx32::fromRaw(int64_t(1) << 31), quarter = Fx32::fromRaw(int64_t(1) << 30);
  const Fx32 threeQuarters = Fx32::fromRaw(int64_t(3) << 30);
  EXPECT_EQ((Fx32::epsilon() * half).raw(), 1);    // 0.5 ulp -> 1
  EXPECT_EQ((-Fx32::epsilon() * half).raw(), -1);  // -0.5 ulp -> -1
  EXPECT_EQ((Fx32::fromRaw(3) * half).raw(), 2);   // 1.5 ulp -> 2
  EXPECT_EQ((Fx32::fromRaw(-3) * half).raw(), -2);
  EXPECT_EQ((Fx32::fromRaw(5) * half).raw(), 3);  // 2.5 -> 3 (not banker's 2)
  EXPECT_EQ((Fx32::fromRaw(-5) * half).raw(), -3);
  EXPECT_EQ((Fx32::epsilon() * quarter).raw(), 0);  // 0.25 ulp -> 0
  EXPECT_EQ((Fx32::epsilon() * threeQuarters).raw(), 1);
  EXPECT_EQ((Fx32::fromRaw(-1) * threeQuarters).raw(), -1);
  // Just below and above a tie: raw 2^31 - 1 and 2^31 + 1 times one ulp.
  EXPECT_EQ((Fx32::epsilon() * Fx32::fromRaw((int64_t(1) << 31) - 1)).raw(), 0);
  EXPECT_EQ((Fx32::epsilon() * Fx32::fromRaw((int64_t(1) << 31) + 1)).raw(), 1);
  EXPECT_EQ((Fx32(3) * Fx32(-7)).raw(), -21 * (int64_t(1) << 32));

  const Fx16 h16 = Fx16::fromRaw(1 << 15);
  EXPECT_EQ((Fx16::epsilon() * h16).raw(), 1);
  EXPECT_EQ((-Fx16::epsilon() * h16).raw(), -1);
  EXPECT_EQ((Fx16::fromRaw(5) * h16).raw(), 3);
  EXPECT_EQ((Fx16::fromRaw(-5) * h16).raw(), -3);
  EXPECT_EQ((Fx16::epsilon() * Fx16::fromRaw((1 << 15) - 1)).raw(), 0);
  EXPECT_EQ((Fx16(-100) * Fx16(300)).raw(), -30000 * 65536);
  EXPECT_EQ(sg::takeFixedFaults(), 0u);
}

/// Products that are exact ties by construction: raw a (odd) times (2k+1)/2 in value gives
/// P/2 ulps with P = a(2k+1) odd, whose away-from-zero rounding is (P + sign(P)) / 2.
template <class Fx>
void exactTieProducts(uint64_t seed) {
  using Raw = typename Fx::RawType;
  std::mt19937_64 g(seed);
  Mismatches m;
  for (int i = 0; i < 100000; ++i) {
    const int64_t a = int64_t(std::uniform_int_distribution<int64_t>(-1000000, 1000000)(g)) | 1;
    const int64_t k = std::uniform_int_distribution<int64_t>(-1000, 1000)(g);
    const Raw b = static_cast<Raw>((2 * k + 1) * (int64_t(1) << (Fx::kFracBits - 1)));
    const int64_t p = a * (2 * k + 1);
    const int64_t want = (p + (p > 0 ? 1 : -1)) / 2;
    const Raw got = (Fx::fromRaw(Raw(a)) * Fx::fromRaw(b)).raw();
    m.check(got == want, [&] { return "raw " + std::to_string(a) + " * raw " + std::to_string(b); });
  }
  EXPECT_TRUE(m.result());
  EXPECT_EQ(sg::takeFixedFaults(), 0u);
}
TEST_F(FixedMul, Fx32ExactTies) { exactTieProducts<Fx32>(11); }
TEST_F(FixedMul, Fx16ExactTies) {
  // Keep |a (2k+1) / 2| inside Q16.16's 2^31 raw range: |a| <= 1e6 and |2k+1| <= 2001 give < 2^31.
  exactTieProducts<Fx16>(12);
}

// ---- division -------------------------------------------------------------------------------

template <class Fx>
void checkDiv(Mismatches& m, typename Fx::RawType a, typename Fx::RawType b) {
  using Raw = typename Fx::RawType;
  if (b == 0) return;
  sg::takeFixedFaults();
  const Raw got = (Fx::fromRaw(a) / Fx::fromRaw(b)).raw();
  const uint32_t faults = sg::takeFixedFaults();
  const I128 want = refDiv<Fx>(a, b);
  const uint32_t wantFaults = fits<Fx>(want) ? 0u : uint32_t(sg::kFixedFaultOverflow);
  m.check(got == static_cast<Raw>(want) && faults == wantFaults, [&] {
    return "raw " + str(I128(a)) + " / raw " + str(I128(b)) + ": want " + str(want) + " faults " +
           std::to_string(wantFaults) + ", got " + str(I128(got)) + " faults " + std::to_string(faults);
  });
}

template <class Fx>
void divSamples(uint64_t seed) {
  std::mt19937_64 g(seed);
  constexpr int kN = 200000;
  Mismatches full, mag, typical, edge;
  for (int i = 0; i < kN; ++i) checkDiv<Fx>(full, fullRaw<Fx>(g), fullRaw<Fx>(g));
  for (int i = 0; i < kN; ++i) checkDiv<Fx>(mag, anyMagnitudeRaw<Fx>(g), anyMagnitudeRaw<Fx>(g));
  for (int i = 0; i < kN; ++i) checkDiv<Fx>(typical, typicalRaw<Fx>(g), typicalRaw<Fx>(g));
  for (auto a : edgeRaws<Fx>())
    for (auto b : edgeRaws<Fx>()) checkDiv<Fx>(edge, a, b);
  EXPECT_TRUE(full.result()) << "full raw range";
  EXPECT_TRUE(mag.result()) << "all magnitudes";
  EXPECT_TRUE(typical.result()) << "|x| < 100";
  EXPECT_TRUE(edge.result()) << "edge cases";
}

TEST_F(FixedDiv, Fx32MatchesExactRoundedQuotient) { divSamples<Fx32>(0x5eed0003); }
TEST_F(FixedDiv, Fx16MatchesExactRoundedQuotient) { divSamples<Fx16>(0x5eed0004); }

TEST_F(FixedDiv, HandComputedQuotients) {
  // 2^32 / 3 = 1431655765.33..., 2^33 / 3 = 2863311530.67...
  EXPECT_EQ((Fx32(1) / Fx32(3)).raw(), 1431655765);
  EXPECT_EQ((Fx32(2) / Fx32(3)).raw(), 2863311531);
  EXPECT_EQ((Fx32(-2) / Fx32(3)).raw(), -2863311531);
  EXPECT_EQ((Fx32(2) / Fx32(-3)).raw(), -2863311531);
  EXPECT_EQ((Fx32(-2) / Fx32(-3)).raw(), 2863311531);
  EXPECT_EQ((Fx32::epsilon() / Fx32(2)).raw(), 1);  // 0.5 ulp tie -> away from zero
  EXPECT_EQ((-Fx32::epsilon() / Fx32(2)).raw(), -1);
  EXPECT_EQ((Fx32::fromRaw(5) / Fx32(2)).raw(), 3);
  EXPECT_EQ((Fx32::fromRaw(5) / Fx32(-2)).raw(), -3);
  EXPECT_EQ((Fx32::fromRaw(1) / Fx32(3)).raw(), 0);  // 1/3 ulp
  EXPECT_EQ((Fx32::fromRaw(2) / Fx32(3)).raw(), 1);  // 2/3 ulp
  EXPECT_EQ((Fx32(7) / Fx32(7)).raw(), Fx32::kOneRaw);
  // 65536 / 3 = 21845.33, 131072 / 3 = 43690.67
  EXPECT_EQ((Fx16(1) / Fx16(3)).raw(), 21845);
  EXPECT_EQ((Fx16(2) / Fx16(3)).raw(), 43691);
  EXPECT_EQ((Fx16(-2) / Fx16(3)).raw(), -43691);
  EXPECT_EQ((Fx16::epsilon() / Fx16(2)).raw(), 1);
  EXPECT_EQ((-Fx16::epsilon() / Fx16(2)).raw(), -1);
  EXPECT_EQ((Fx16::fromRaw(-5) / Fx16(2)).raw(), -3);
  EXPECT_EQ(sg::takeFixedFaults(), 0u);
}

/// Quotients that tie by construction: a = m(2q+1) ulps divided by the integer 2m is q + 1/2
/// ulps, which must round to q + 1 (and to -(q + 1) for a negative sign on either side).
template <class Fx>
void exactTieQuotients(uint64_t seed) {
  using Raw = typename Fx::RawType;
  std::mt19937_64 g(seed);
  Mismatches m;
  for (int i = 0; i < 100000; ++i) {
    const int64_t mm = std::uniform_int_distribution<int64_t>(1, 10000)(g);
    const int64_t q = std::uniform_int_distribution<int64_t>(0, 100000)(g);
    const int sa = (g() & 1) ? -1 : 1, sb = (g() & 1) ? -1 : 1;
    const Raw a = static_cast<Raw>(sa * mm * (2 * q + 1));
    const Fx b = Fx(sb * 2 * mm);
    const int64_t want = sa * sb * (q + 1);
    const Raw got = (Fx::fromRaw(a) / b).raw();
    m.check(got == want, [&] { return "raw " + std::to_string(a) + " / " + std::to_string(sb * 2 * mm); });
  }
  EXPECT_TRUE(m.result());
  EXPECT_EQ(sg::takeFixedFaults(), 0u);
}
TEST_F(FixedDiv, Fx32ExactTies) { exactTieQuotients<Fx32>(21); }
TEST_F(FixedDiv, Fx16ExactTies) { exactTieQuotients<Fx16>(22); }  // |a| < 1e4 * 2e5 = 2e9 < 2^31

// ---- odd symmetry ---------------------------------------------------------------------------

template <class Fx>
void oddSymmetry(uint64_t seed) {
  using Raw = typename Fx::RawType;
  std::mt19937_64 g(seed);
  Mismatches mul, div;
  auto draw = [&](int kind) {
    Raw r = kind == 0 ? typicalRaw<Fx>(g) : anyMagnitudeRaw<Fx>(g);
    return r == std::numeric_limits<Raw>::min() ? Raw(r + 1) : r;  // -min does not exist
  };
  for (int i = 0; i < 200000; ++i) {
    const Fx a = Fx::fromRaw(draw(i & 1)), b = Fx::fromRaw(draw((i >> 1) & 1));
    sg::takeFixedFaults();
    const Fx p = a * b;
    const bool pOk = sg::takeFixedFaults() == 0;
    const Fx pn = (-a) * b;
    if (pOk) mul.check(pn == -p, [&] { return "raw " + str(I128(a.raw())) + " * raw " + str(I128(b.raw())); });
    if (b.raw() == 0) continue;
    sg::takeFixedFaults();
    const Fx q = a / b;
    const bool qOk = sg::takeFixedFaults() == 0;
    const Fx qn = (-a) / b;
    const Fx qd = a / (-b);
    if (qOk)
      div.check(qn == -q && qd == -q, [&] { return "raw " + str(I128(a.raw())) + " / raw " + str(I128(b.raw())); });
  }
  EXPECT_TRUE(mul.result()) << "(-a) * b == -(a * b)";
  EXPECT_TRUE(div.result()) << "(-a) / b == -(a / b) == a / (-b)";
}
TEST_F(FixedSymmetry, Fx32NegationCommutesWithMulAndDiv) { oddSymmetry<Fx32>(31); }
TEST_F(FixedSymmetry, Fx16NegationCommutesWithMulAndDiv) { oddSymmetry<Fx16>(32); }

// ---- faults -----------------------------------------------------------------------------------

template <class Fx>
void overflowCases() {
  using Raw = typename Fx::RawType;
  const Fx eps = Fx::epsilon(), mx = Fx::max(), mn = Fx::min();
  auto expectFault = [](auto&& op, uint32_t want, const char* what) {
    sg::takeFixedFaults();
    op();
    EXPECT_EQ(sg::takeFixedFaults(), want) << what;
  };
  const uint32_t kO = sg::kFixedFaultOverflow;
  expectFault([&] { EXPECT_EQ((mx + eps).raw(), std::numeric_limits<Raw>::min()); }, kO, "max + eps (wraps)");
  expectFault([&] { EXPECT_EQ((mn - eps).raw(), std::numeric_limits<Raw>::max()); }, kO, "min - eps (wraps)");
  expectFault([&] { (void)(-mn); }, kO, "-min");
  expectFault([&] { (void)sg::abs(mn); }, kO, "abs(min)");
  expectFault([&] { (void)(mx * mx); }, kO, "max * max");
  expectFault([&] { (void)(mn * mn); }, kO, "min * min");
  expectFault([&] { (void)(mn * Fx(-1)); }, kO, "min * -1");
  expectFault([&] { (void)(mn / Fx(-1)); }, kO, "min / -1");
  expectFault([&] { (void)(Fx(1000) / eps); }, kO, "1000 / eps");
  expectFault([&] { (void)(Fx(-1) / eps); }, kO, "-1 / eps = -2^F");
  // -1 / (3 ulps) = -2^(2F) / 3 ulps: -6148914691236517205.3 (Q32.32), -1431655765.3 (Q16.16): fits.
  expectFault(
      [&] {
        EXPECT_EQ(int64_t((Fx(-1) / Fx::fromRaw(3)).raw()),
                  Fx::kFracBits == 32 ? int64_t(-6148914691236517205) : int64_t(-1431655765));
      },
      0, "-1 / 3 ulps");
  // 2^(F/2 - 1) * 2^(F/2) = 2^(F - 1) in value: one ulp past max (2^31 - u for Q32.32, 2^15 - u
  // for Q16.16); with the second factor one ulp smaller the product is 2^(F-1) - 2^(F/2-1) u: fits.
  const Raw big = static_cast<Raw>(Raw(1) << (Fx::kFracBits + Fx::kFracBits / 2 - 1));
  expectFault([&] { (void)(Fx::fromRaw(big) * Fx::fromRaw(Raw(big * 2))); }, kO, "2^(F/2-1) * 2^(F/2)");
  expectFault([&] { (void)(Fx::fromRaw(big) * Fx::fromRaw(Raw(big * 2 - 1))); }, 0, "just below max");
  expectFault([&] { (void)Fx::mulDiv(mx, Fx(2), Fx(1)); }, kO, "mulDiv(max, 2, 1)");
  expectFault(
      [&] {
        Fx c = mx;
        c += eps;
      },
      kO, "+=");
  // In range: must NOT raise anything.
  expectFault([&] { EXPECT_EQ((mx - eps).raw(), std::numeric_limits<Raw>::max() - 1); }, 0, "max - eps");
  expectFault([&] { EXPECT_EQ((mn + eps).raw(), std::numeric_limits<Raw>::min() + 1); }, 0, "min + eps");
  expectFault([&] { EXPECT_EQ((mx * Fx(1)), mx); }, 0, "max * 1");
  expectFault([&] { EXPECT_EQ((mn * Fx(1)), mn); }, 0, "min * 1");
  expectFault([&] { EXPECT_EQ((mn / Fx(1)), mn); }, 0, "min / 1");
  expectFault([&] { EXPECT_EQ((mx / Fx(-1)).raw(), -std::numeric_limits<Raw>::max()); }, 0, "max / -1");
  expectFault([&] { EXPECT_EQ((-mx).raw(), -std::numeric_limits<Raw>::max()); }, 0, "-max");
  expectFault([&] { EXPECT_EQ(Fx::mulDiv(mx, Fx(3), Fx(3)), mx); }, 0, "mulDiv(max, 3, 3): wide intermediate");
}
TEST_F(FixedFault, Fx32OverflowRaisedExactlyWhenOutOfRange) { overflowCases<Fx32>(); }
TEST_F(FixedFault, Fx16OverflowRaisedExactlyWhenOutOfRange) { overflowCases<Fx16>(); }

TEST_F(FixedFault, IntegerConstructorRange) {
  auto faultsOf = [](auto make) {
    sg::takeFixedFaults();
    (void)make();
    return sg::takeFixedFaults();
  };
  const uint32_t kO = sg::kFixedFaultOverflow;
  // Q16.16 holds integers -32768 ... 32767.
  EXPECT_EQ(faultsOf([] { return Fx16(40000); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx16(-40000); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx16(32768); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx16(-32769); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx16(40000u); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx16(uint64_t(1) << 63); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx16(std::numeric_limits<int64_t>::min()); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx16(32767); }), 0u);
  EXPECT_EQ(faultsOf([] { return Fx16(-32768); }), 0u);
  EXPECT_EQ(faultsOf([] { return Fx16(uint16_t(32767)); }), 0u);
  EXPECT_EQ(Fx16(-32768), Fx16::min());
  EXPECT_EQ(Fx16(32767).raw(), 32767 * 65536);
  // Q32.32 holds integers -2^31 ... 2^31 - 1.
  EXPECT_EQ(faultsOf([] { return Fx32(int64_t(5000000000)); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx32(int64_t(-5000000000)); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx32(int64_t(2147483648)); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx32(int64_t(-2147483649)); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx32(uint32_t(2147483648u)); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx32(std::numeric_limits<uint64_t>::max()); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx32(std::numeric_limits<int64_t>::max()); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx32(int64_t(2147483647)); }), 0u);
  EXPECT_EQ(faultsOf([] { return Fx32(int64_t(-2147483648)); }), 0u);
  EXPECT_EQ(Fx32(int64_t(-2147483648)), Fx32::min());
  EXPECT_EQ(Fx32(int64_t(2147483647)).raw(), int64_t(2147483647) << 32);
}

/// __int128 is an integral type under gnu++20, so Fx32(someInt128) compiles (Rational::num is
/// one): an out-of-range value must raise the fault rather than be truncated silently.
TEST_F(FixedFault, Int128ConstructorRange) {
  auto faultsOf = [](auto make) {
    sg::takeFixedFaults();
    (void)make();
    return sg::takeFixedFaults();
  };
  const uint32_t kO = sg::kFixedFaultOverflow;
  EXPECT_EQ(Fx32(I128(-7)).raw(), int64_t(-7) << 32);
  EXPECT_EQ(faultsOf([] { return Fx32(I128(1) << 64); }), kO) << "2^64 truncates to 0 if converted via uint64";
  EXPECT_EQ(faultsOf([] { return Fx32(-(I128(1) << 64)); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx32((I128(1) << 64) + 5); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx16(U128(1) << 64); }), kO);
  EXPECT_EQ(faultsOf([] { return Fx16(-(I128(1) << 64) + 3); }), kO);
}

TEST_F(FixedFault, InRangeBatchRaisesNothing) {
  std::mt19937_64 g(41);
  int64_t sink32 = 0;
  int32_t sink16 = 0;
  for (int i = 0; i < 200000; ++i) {
    // |a|, |b| < 100 and |c| in [1/128, 100): products < 1e4, quotients < 1.28e4 < 2^15.
    const Fx32 a = Fx32::fromRaw(typicalRaw<Fx32>(g)), b = Fx32::fromRaw(typicalRaw<Fx32>(g));
    Fx32 c = Fx32::fromRaw(typicalRaw<Fx32>(g));
    if (sg::abs(c) < Fx32::fromRaw(Fx32::kOneRaw / 128)) c = Fx32(1);
    // Sum < 1e4 + 1.28e4 + 100 + 10 + 174 + 3334 < 2^15: fits Q16.16 as well.
    const Fx32 r32 =
        a * b + a / c - b + sg::sqrt(sg::abs(a)) + sg::length3(a, b, c) + Fx32::mulDiv(a, b, sg::abs(c) + Fx32(3));
    sink32 += r32.raw();
    const Fx16 x = Fx16::fromRaw(typicalRaw<Fx16>(g)), y = Fx16::fromRaw(typicalRaw<Fx16>(g));
    Fx16 z = Fx16::fromRaw(typicalRaw<Fx16>(g));
    if (sg::abs(z) < Fx16::fromRaw(Fx16::kOneRaw / 128)) z = Fx16(1);
    const Fx16 r16 =
        x * y + x / z - y + sg::sqrt(sg::abs(x)) + sg::length3(x, y, z) + Fx16::mulDiv(x, y, sg::abs(z) + Fx16(3));
    sink16 += r16.raw() & 0xff;
  }
  EXPECT_EQ(sg::takeFixedFaults(), 0u) << "sink " << sink32 << " " << sink16;
}

TEST_F(FixedFault, DivideByZeroAndDomain) {
  EXPECT_EQ(Fx32(1) / Fx32(0), Fx32::max());
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultDivideByZero));
  EXPECT_EQ(Fx32(-1) / Fx32(0), Fx32::min());
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultDivideByZero));
  (void)(Fx16(0) / Fx16(0));
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultDivideByZero));
  (void)Fx32::mulDiv(Fx32(1), Fx32(2), Fx32(0));
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultDivideByZero));
  (void)Fx16::mulDiv(Fx16(1), Fx16(2), Fx16(0));
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultDivideByZero));

  EXPECT_EQ(sg::sqrt(-Fx32::epsilon()), Fx32(0));
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultDomain));
  EXPECT_EQ(sg::sqrt(Fx16(-4)), Fx16(0));
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultDomain));
  EXPECT_EQ(sg::sqrt(Fx32::min()), Fx32(0));
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultDomain));
  (void)sg::sqrt(Fx32(0));
  EXPECT_EQ(sg::takeFixedFaults(), 0u);
}

TEST_F(FixedFault, BitsAreStickyPerThreadAndTakeClears) {
  (void)(Fx32::max() + Fx32::epsilon());
  (void)(Fx32(1) * Fx32(2));  // a later in-range op does not clear the bit
  (void)(Fx16(1) / Fx16(0));
  EXPECT_EQ(sg::pendingFixedFaults(), uint32_t(sg::kFixedFaultOverflow | sg::kFixedFaultDivideByZero));
  EXPECT_EQ(sg::pendingFixedFaults(), uint32_t(sg::kFixedFaultOverflow | sg::kFixedFaultDivideByZero))
      << "pending must not clear";
  EXPECT_STREQ(sg::fixedFaultName(sg::pendingFixedFaults()), "division by zero");  // most significant first
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultOverflow | sg::kFixedFaultDivideByZero));
  EXPECT_EQ(sg::takeFixedFaults(), 0u);
  EXPECT_STREQ(sg::fixedFaultName(0), "none");
  EXPECT_STREQ(sg::fixedFaultName(sg::kFixedFaultOverflow), "fixed-point overflow");

  uint32_t seenThere = 99, leftThere = 99;
  std::thread t([&] {
    seenThere = sg::pendingFixedFaults();
    (void)sg::sqrt(Fx32(-1));
    leftThere = sg::takeFixedFaults();
  });
  (void)(Fx32::min() - Fx32::epsilon());
  t.join();
  EXPECT_EQ(seenThere, 0u);
  EXPECT_EQ(leftThere, uint32_t(sg::kFixedFaultDomain));
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultOverflow)) << "other thread's fault leaked here";
}

// ---- square roots ---------------------------------------------------------------------------

U128 absDiff(U128 a, U128 b) { return a > b ? a - b : b - a; }

/// r is the nearest integer square root of n: |r^2 - n| < |(r +- 1)^2 - n| (no ties exist for
/// integers, since (r + 1/2)^2 is never an integer).
bool isNearestRoot(U128 n, U128 r) {
  if (r >= (U128(1) << 64)) return false;
  const U128 d = absDiff(r * r, n);
  if (r > 0 && !(d < absDiff((r - 1) * (r - 1), n))) return false;
  // (r + 1)^2 = 2^128 > n does not fit when r = 2^64 - 1: its distance is 2^128 - n.
  const U128 up = r + 1 == (U128(1) << 64) ? U128(0) - n : absDiff((r + 1) * (r + 1), n);
  return d < up;
}

template <class Fx>
void sqrtSamples(uint64_t seed) {
  using Raw = typename Fx::RawType;
  std::mt19937_64 g(seed);
  Mismatches m;
  auto check = [&](Raw raw) {
    sg::takeFixedFaults();
    const Raw got = sg::sqrt(Fx::fromRaw(raw)).raw();
    const uint32_t faults = sg::takeFixedFaults();
    const U128 n = U128(raw) << Fx::kFracBits;
    m.check(got >= 0 && faults == 0 && isNearestRoot(n, U128(got)), [&] {
      return "sqrt(raw " + str(I128(raw)) + ") = raw " + str(I128(got)) + " faults " + std::to_string(faults);
    });
  };
  constexpr Raw kMax = std::numeric_limits<Raw>::max();
  for (int i = 0; i < 200000; ++i) {
    const Raw a = anyMagnitudeRaw<Fx>(g);
    check(a < 0 ? Raw(-(a + 1)) : a);
  }
  for (int i = 0; i < 100000; ++i) check(Raw(g() & uint64_t(kMax)));
  for (int i = 0; i < 100000; ++i) check(static_cast<Raw>(std::abs(typicalRaw<Fx>(g))));
  for (Raw r = 0; r < 5000; ++r) check(r);
  for (Raw r = kMax; r > kMax - 5000; --r) check(r);
  EXPECT_TRUE(m.result());
  // Perfect squares: raw j^2 has the exact root j * 2^(F/2); integer squares have integer roots.
  constexpr Raw kHalfScale = Raw(1) << (Fx::kFracBits / 2);
  const int64_t jMax = Fx::kFracBits == 32 ? int64_t(3037000499) : int64_t(46340);  // floor(sqrt(max))
  for (int i = 0; i < 20000; ++i) {
    const int64_t j = std::uniform_int_distribution<int64_t>(0, jMax)(g);
    const Raw raw = static_cast<Raw>(j * j);
    EXPECT_EQ(int64_t(sg::sqrt(Fx::fromRaw(raw)).raw()), j * int64_t(kHalfScale)) << "raw " << int64_t(raw);
    if (::testing::Test::HasFailure()) break;
  }
  EXPECT_EQ(sg::sqrt(Fx(4)), Fx(2));
  EXPECT_EQ(sg::sqrt(Fx(10000)), Fx(100));
  EXPECT_EQ(sg::sqrt(Fx::fromRaw(Fx::kOneRaw / 4)), Fx::fromRaw(Fx::kOneRaw / 2));  // sqrt(1/4) = 1/2
  EXPECT_EQ(sg::sqrt(Fx(0)), Fx(0));
  EXPECT_EQ(sg::sqrt(Fx(1)), Fx(1));
}
TEST_F(FixedSqrt, Fx32IsNearest) {
  sqrtSamples<Fx32>(51);
  // sqrt(eps) = 2^-16 exactly. sqrt(max): nearest root of (2^63 - 1) 2^32, from Python's
  // math.isqrt (floor 199032864766430, remainder below the root, so no round-up).
  EXPECT_EQ(sg::sqrt(Fx32::epsilon()).raw(), int64_t(1) << 16);
  EXPECT_EQ(sg::sqrt(Fx32::max()).raw(), 199032864766430);
  // sqrt(2) in Q32.32: round(2^32 * 1.41421356237309504880) = 6074001000 (2^32 sqrt 2 = 6074000999.95).
  EXPECT_EQ(sg::sqrt(Fx32(2)).raw(), 6074001000);
  EXPECT_EQ(sg::sqrt(Fx32::fromRaw(Fx32::kOneRaw / 2)).raw(), 3037000500);  // sqrt(0.5)
}
TEST_F(FixedSqrt, Fx16IsNearest) {
  sqrtSamples<Fx16>(52);
  EXPECT_EQ(sg::sqrt(Fx16::epsilon()).raw(), 1 << 8);
  EXPECT_EQ(sg::sqrt(Fx16(2)).raw(), 92682);  // 65536 sqrt 2 = 92681.9
  // sqrt(32767.99998) * 65536 = 11863283.2: n = (2^31 - 1) 2^16 = 140737488289792.
  EXPECT_EQ(sg::sqrt(Fx16::max()).raw(), 11863283);
}

/// floor root: r^2 <= n < (r + 1)^2, written overflow-free as r^2 <= n and n - r^2 <= 2r
/// ((r + 1)^2 - r^2 = 2r + 1; r < 2^64, so r^2 and 2r fit in 128 bits).
bool isFloorRoot(U128 n, uint64_t r) {
  const U128 sq = U128(r) * r;
  return sq <= n && n - sq <= 2 * U128(r);
}

TEST_F(FixedIsqrt, FloorAndNearestOverAll128BitInputs) {
  std::mt19937_64 g(61);
  Mismatches floorM, nearM;
  constexpr U128 kAll = ~U128(0);
  constexpr uint64_t kR = ~uint64_t(0);  // 2^64 - 1
  // The largest n whose nearest root is still < 2^64: (2^64 - 1)^2 + (2^64 - 1).
  const U128 nearestLimit = U128(kR) * kR + kR;
  auto check = [&](U128 n) {
    const uint64_t r = sg::isqrtFloor(n);
    floorM.check(isFloorRoot(n, r), [&] { return "isqrtFloor(" + str(n) + ") = " + str(U128(r)); });
    if (n <= nearestLimit) {
      const uint64_t rn = sg::isqrtNearest(n);
      nearM.check(isNearestRoot(n, rn), [&] { return "isqrtNearest(" + str(n) + ") = " + str(U128(rn)); });
    }
  };
  auto rand128 = [&] { return (U128(g()) << 64) | g(); };
  for (int i = 0; i < 200000; ++i) check(rand128() >> (g() % 128));  // every bit length
  for (int i = 0; i < 50000; ++i) check(rand128());                  // mostly near the top
  for (U128 n = 0; n < 20000; ++n) check(n);
  for (U128 k = 0; k < 2000; ++k) {
    check(kAll - k);           // near 2^128 - 1
    check(U128(kR) * kR + k);  // around (2^64 - 1)^2
    check(U128(kR) * kR - k);
    check((U128(1) << 104) + k);  // the estimate's switch-over point
    check((U128(1) << 104) - k);
    check((U128(1) << 64) + k);
    check((U128(1) << 64) - k);
    check((U128(1) << 106) - k);
    check(nearestLimit - k);
  }
  for (int j = 0; j < 128; ++j) {
    check(U128(1) << j);
    check((U128(1) << j) - 1);
    check((U128(1) << j) + 1);
  }
  for (int i = 0; i < 50000; ++i) {  // perfect squares and their neighbours, every size
    const uint64_t k = g() >> (g() % 64);
    const U128 sq = U128(k) * k;
    check(sq);
    check(sq - 1);
    check(sq + 1);
    check(sq + 2 * U128(k));  // (k + 1)^2 - 1
  }
  EXPECT_TRUE(floorM.result()) << "isqrtFloor";
  EXPECT_TRUE(nearM.result()) << "isqrtNearest";
  // Hand-checked anchors.
  EXPECT_EQ(sg::isqrtFloor(kAll), kR);
  EXPECT_EQ(sg::isqrtFloor(U128(kR) * kR), kR);
  EXPECT_EQ(sg::isqrtFloor(U128(kR) * kR - 1), kR - 1);
  EXPECT_EQ(sg::isqrtFloor(U128(1) << 104), uint64_t(1) << 52);
  EXPECT_EQ(sg::isqrtFloor((U128(1) << 104) - 1), (uint64_t(1) << 52) - 1);
  EXPECT_EQ(sg::isqrtFloor(U128(1) << 64), uint64_t(1) << 32);
  EXPECT_EQ(sg::isqrtFloor((U128(1) << 64) - 1), (uint64_t(1) << 32) - 1);
  EXPECT_EQ(sg::isqrtFloor(0), 0u);
  EXPECT_EQ(sg::isqrtFloor(3), 1u);
  EXPECT_EQ(sg::isqrtNearest(2), 1u);  // 1.414
  EXPECT_EQ(sg::isqrtNearest(3), 2u);  // 1.732
  EXPECT_EQ(sg::isqrtNearest(6), 2u);  // 2.449
  EXPECT_EQ(sg::isqrtNearest(7), 3u);  // 2.646
  EXPECT_EQ(sg::isqrtNearest(nearestLimit), kR);
}

// ---- length3 -------------------------------------------------------------------------------

template <class Fx>
void length3Samples(uint64_t seed) {
  using Raw = typename Fx::RawType;
  std::mt19937_64 g(seed);
  Mismatches m;
  auto sq = [](Raw v) {
    const U128 a = v < 0 ? U128(0) - U128(I128(v)) : U128(v);
    return a * a;
  };
  auto check = [&](Raw x, Raw y, Raw z) {
    sg::takeFixedFaults();
    const Raw got = sg::length3(Fx::fromRaw(x), Fx::fromRaw(y), Fx::fromRaw(z)).raw();
    const uint32_t faults = sg::takeFixedFaults();
    const U128 s = sq(x) + sq(y) + sq(z);  // < 3 * 2^(2 bits - 2) < 2^(2 bits): exact
    // The rounded root, recovered from the wrapped raw: the true root is < 2^(bits + 1).
    using U = std::make_unsigned_t<Raw>;
    const U128 r = U128(U(got));
    const bool over = r > U128(std::numeric_limits<Raw>::max());
    m.check(isNearestRoot(s, r) && faults == (over ? uint32_t(sg::kFixedFaultOverflow) : 0u), [&] {
      return "length3(raw " + str(I128(x)) + ", " + str(I128(y)) + ", " + str(I128(z)) + ") = raw " + str(I128(got)) +
             " faults " + std::to_string(faults);
    });
  };
  for (int i = 0; i < 100000; ++i) check(typicalRaw<Fx>(g), typicalRaw<Fx>(g), typicalRaw<Fx>(g));
  for (int i = 0; i < 100000; ++i) check(anyMagnitudeRaw<Fx>(g), anyMagnitudeRaw<Fx>(g), anyMagnitudeRaw<Fx>(g));
  for (int i = 0; i < 50000; ++i) check(fullRaw<Fx>(g), fullRaw<Fx>(g), fullRaw<Fx>(g));
  constexpr Raw kMin = std::numeric_limits<Raw>::min(), kMax = std::numeric_limits<Raw>::max();
  check(kMin, kMin, kMin);  // the largest sum of squares: 3 * 2^(2 bits - 2)
  check(kMax, kMax, kMax);
  check(kMax, 0, 0);
  check(kMax, 1, 0);
  check(kMax / 2, kMax / 2, kMax / 2);
  EXPECT_TRUE(m.result());

  // Axis vectors are exact: (0, y, 0), (y, 0, 0), (0, 0, y) have length exactly |y|.
  Mismatches axis;
  for (int i = 0; i < 100000; ++i) {
    Raw y = (i & 1) ? anyMagnitudeRaw<Fx>(g) : typicalRaw<Fx>(g);
    if (y == kMin) y = kMin + 1;
    const Fx fy = Fx::fromRaw(y), z = Fx(0), ay = sg::abs(fy);
    axis.check(sg::length3(z, fy, z) == ay && sg::length3(fy, z, z) == ay && sg::length3(z, z, fy) == ay,
               [&] { return "axis raw " + str(I128(y)); });
  }
  EXPECT_TRUE(axis.result());
  EXPECT_EQ(sg::takeFixedFaults(), 0u);
  (void)sg::length3(Fx(0), Fx::min(), Fx(0));  // |min| = 2^(bits-1) does not fit
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultOverflow));

  // Pythagorean quadruples with negative components: exact integers.
  EXPECT_EQ(sg::length3(Fx(-3), Fx(-4), Fx(0)), Fx(5));
  EXPECT_EQ(sg::length3(Fx(1), Fx(-2), Fx(2)), Fx(3));
  EXPECT_EQ(sg::length3(Fx(-2), Fx(3), Fx(-6)), Fx(7));
  EXPECT_EQ(sg::length3(Fx(-1), Fx(-4), Fx(-8)), Fx(9));
  EXPECT_EQ(sg::length3(Fx(0), Fx(0), Fx(0)), Fx(0));
  EXPECT_EQ(sg::takeFixedFaults(), 0u);
}
TEST_F(FixedLength3, Fx32IsNearestRootOfExactSumOfSquares) { length3Samples<Fx32>(71); }
TEST_F(FixedLength3, Fx16IsNearestRootOfExactSumOfSquares) { length3Samples<Fx16>(72); }

TEST_F(FixedLength3, SingleRoundingBeatsSqrtOfRoundedSquares) {
  // (eps, eps, 0): exact length sqrt(2) ulps -> 1 ulp. sqrt(eps*eps + eps*eps) = sqrt(0 + 0) = 0.
  EXPECT_EQ(sg::length3(Fx32::epsilon(), Fx32::epsilon(), Fx32(0)).raw(), 1);
  EXPECT_EQ(sg::length3(Fx32::epsilon(), Fx32::epsilon(), Fx32::epsilon()).raw(), 2);  // sqrt(3) = 1.73
  EXPECT_EQ(sg::length3(Fx16::fromRaw(-3), Fx16::fromRaw(4), Fx16(0)).raw(), 5);
}

// ---- conversions -----------------------------------------------------------------------------

/// Reference nearest raw for a double: s = v * 2^F is exact (power-of-two scaling), floor(s) is
/// exact, and the remainder s - floor(s) is exact in double: compare it with 1/2.
template <class Fx>
int64_t refFromDouble(double v) {
  const double s = std::ldexp(v, Fx::kFracBits);
  const double f = std::floor(s);
  const double rem = s - f;
  int64_t q = static_cast<int64_t>(f);
  if (rem > 0.5 || (rem == 0.5 && s > 0)) ++q;
  return q;
}

template <class Fx>
void conversionSamples(uint64_t seed) {
  using Raw = typename Fx::RawType;
  std::mt19937_64 g(seed);
  constexpr int64_t kMaxInt = int64_t(std::numeric_limits<Raw>::max() >> Fx::kFracBits);
  constexpr int64_t kMinInt = int64_t(std::numeric_limits<Raw>::min() >> Fx::kFracBits);
  Mismatches ints, toD, fromD, round;
  for (int i = 0; i < 100000; ++i) {
    const int64_t k = std::uniform_int_distribution<int64_t>(kMinInt, kMaxInt)(g);
    const Fx f(k);
    ints.check(int64_t(f.raw()) == k * int64_t(Fx::kOneRaw) && f.toDouble() == double(k),
               [&] { return "Fx(" + std::to_string(k) + ")"; });
  }
  for (int i = 0; i < 200000; ++i) {
    const Raw raw = (i & 1) ? fullRaw<Fx>(g) : anyMagnitudeRaw<Fx>(g);
    const double d = Fx::fromRaw(raw).toDouble();
    // Q16.16 values have at most 31 significant bits: toDouble is exact. Q32.32 values are exact
    // below 2^53 ulps and otherwise the nearest double (int64 -> double rounds to nearest).
    const bool exact = Fx::kFracBits == 16 || (raw > -(int64_t(1) << 53) && raw < (int64_t(1) << 53));
    const double want = std::ldexp(static_cast<double>(raw), -Fx::kFracBits);
    toD.check(d == want && (!exact || static_cast<long double>(d) * Fx::kOneRaw == static_cast<long double>(raw)),
              [&] { return "toDouble(raw " + str(I128(raw)) + ")"; });
    if (exact) {
      round.check(Fx::fromDouble(d).raw() == raw, [&] { return "fromDouble(toDouble(raw " + str(I128(raw)) + "))"; });
    }
  }
  const double range = std::ldexp(1.0, int(sizeof(Raw) * 8 - 1 - Fx::kFracBits));  // 2^31 or 2^15
  for (int i = 0; i < 200000; ++i) {
    // Doubles of every magnitude below the range, with all 53 mantissa bits random.
    const double unit = std::ldexp(double(g() >> 11), -53);  // [0, 1), full mantissa
    const double v = (g() & 1 ? -1 : 1) * unit * std::ldexp(range, -int(g() % 48)) * 0.999;
    const int64_t want = refFromDouble<Fx>(v);
    sg::takeFixedFaults();
    const Raw got = Fx::fromDouble(v).raw();
    fromD.check(int64_t(got) == want && sg::takeFixedFaults() == 0, [&] {
      std::ostringstream o;
      o.precision(17);
      o << "fromDouble(" << v << ") want raw " << want << " got " << int64_t(got);
      return o.str();
    });
  }
  EXPECT_TRUE(ints.result()) << "Fx(int)";
  EXPECT_TRUE(toD.result()) << "toDouble";
  EXPECT_TRUE(round.result()) << "fromDouble(toDouble(x)) == x";
  EXPECT_TRUE(fromD.result()) << "fromDouble nearest";
}
TEST_F(FixedConversion, Fx32) { conversionSamples<Fx32>(81); }
TEST_F(FixedConversion, Fx16) { conversionSamples<Fx16>(82); }

TEST_F(FixedConversion, FromDoubleTiesAndOverflow) {
  // Ties in ulps round away from zero.
  EXPECT_EQ(Fx32::fromDouble(std::ldexp(2.5, -32)).raw(), 3);
  EXPECT_EQ(Fx32::fromDouble(std::ldexp(-2.5, -32)).raw(), -3);
  EXPECT_EQ(Fx32::fromDouble(std::ldexp(0.5, -32)).raw(), 1);
  EXPECT_EQ(Fx32::fromDouble(std::ldexp(-0.5, -32)).raw(), -1);
  EXPECT_EQ(Fx32::fromDouble(std::ldexp(0.49999999999999994, -32)).raw(), 0);  // just below the tie
  EXPECT_EQ(Fx16::fromDouble(std::ldexp(1.5, -16)).raw(), 2);
  EXPECT_EQ(Fx16::fromDouble(std::ldexp(-1.5, -16)).raw(), -2);
  EXPECT_EQ(Fx16::fromDouble(0.1).raw(), 6554);           // 6553.6
  EXPECT_EQ(Fx32::fromDouble(0.1).raw(), 429496730);      // 429496729.6 (0.1 as a double is 0.1000000000000000055)
  EXPECT_EQ(Fx32::fromDouble(-0.97).raw(), -4166118277);  // 4166118277.12
  EXPECT_EQ(sg::takeFixedFaults(), 0u);
  // Out of range raises overflow and saturates.
  EXPECT_EQ(Fx32::fromDouble(1e10), Fx32::max());
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultOverflow));
  EXPECT_EQ(Fx32::fromDouble(-1e10), Fx32::min());
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultOverflow));
  EXPECT_EQ(Fx16::fromDouble(40000.0), Fx16::max());
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultOverflow));
  EXPECT_EQ(Fx32::fromDouble(2147483648.0), Fx32::max());  // 2^31: one past the range
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultOverflow));
  (void)Fx32::fromDouble(std::nan(""));
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultOverflow));
  EXPECT_EQ(Fx16::fromDouble(-std::numeric_limits<double>::infinity()), Fx16::min());
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultOverflow));
  EXPECT_EQ(Fx32::fromDouble(std::numeric_limits<double>::infinity()), Fx32::max());
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultOverflow));
  EXPECT_EQ(Fx32::fromDouble(1e300), Fx32::max());  // beyond every integer type: no cast may happen
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultOverflow));
  EXPECT_EQ(Fx16::fromDouble(-1e300), Fx16::min());
  EXPECT_EQ(sg::takeFixedFaults(), uint32_t(sg::kFixedFaultOverflow));
}

/// The ends of the range are representable, so converting them must not raise a fault.
TEST_F(FixedConversion, FromDoubleAtRangeEndsIsExactAndFaultFree) {
  // Q16.16: max = 32767.9999847412109375 and min = -32768 are exact doubles.
  EXPECT_EQ(Fx16::fromDouble(Fx16::max().toDouble()), Fx16::max());
  EXPECT_EQ(sg::takeFixedFaults(), 0u) << "fromDouble(Fx16::max().toDouble())";
  EXPECT_EQ(Fx16::fromDouble(-32768.0), Fx16::min());
  EXPECT_EQ(sg::takeFixedFaults(), 0u) << "fromDouble(-32768.0) for Fx16";
  // 32767.99999 * 65536 = 2147483647.34: rounds to max, which fits.
  EXPECT_EQ(Fx16::fromDouble(32767.99999), Fx16::max());
  EXPECT_EQ(sg::takeFixedFaults(), 0u) << "fromDouble(32767.99999) for Fx16";
  // Q32.32: min = -2^31 is an exact double.
  EXPECT_EQ(Fx32::fromDouble(-2147483648.0), Fx32::min());
  EXPECT_EQ(sg::takeFixedFaults(), 0u) << "fromDouble(-2147483648.0) for Fx32";
}

// ---- mulDiv ------------------------------------------------------------------------------------

template <class Fx>
void mulDivSamples(uint64_t seed) {
  using Raw = typename Fx::RawType;
  std::mt19937_64 g(seed);
  Mismatches m;
  auto check = [&](Raw a, Raw b, Raw c) {
    if (c == 0) return;
    sg::takeFixedFaults();
    const Raw got = Fx::mulDiv(Fx::fromRaw(a), Fx::fromRaw(b), Fx::fromRaw(c)).raw();
    const uint32_t faults = sg::takeFixedFaults();
    // raw result = round(a * b / c): (a 2^-F)(b 2^-F)/(c 2^-F) = (a b / c) 2^-F.
    const I128 want = refRoundDiv(I128(a) * I128(b), I128(c));
    const uint32_t wantFaults = fits<Fx>(want) ? 0u : uint32_t(sg::kFixedFaultOverflow);
    m.check(got == static_cast<Raw>(want) && faults == wantFaults, [&] {
      return "mulDiv(raw " + str(I128(a)) + ", " + str(I128(b)) + ", " + str(I128(c)) + ") want " + str(want) +
             " got " + str(I128(got)) + " faults " + std::to_string(faults);
    });
  };
  for (int i = 0; i < 100000; ++i) check(fullRaw<Fx>(g), fullRaw<Fx>(g), fullRaw<Fx>(g));
  for (int i = 0; i < 100000; ++i) check(anyMagnitudeRaw<Fx>(g), anyMagnitudeRaw<Fx>(g), anyMagnitudeRaw<Fx>(g));
  for (int i = 0; i < 100000; ++i) check(typicalRaw<Fx>(g), typicalRaw<Fx>(g), typicalRaw<Fx>(g));
  for (auto a : edgeRaws<Fx>())
    for (auto c : edgeRaws<Fx>()) check(a, Raw(Fx::kOneRaw + 1), c);
  EXPECT_TRUE(m.result());
}
TEST_F(FixedMulDiv, Fx32MatchesExactSingleRounding) { mulDivSamples<Fx32>(91); }
TEST_F(FixedMulDiv, Fx16MatchesExactSingleRounding) { mulDivSamples<Fx16>(92); }

TEST_F(FixedMulDiv, OneRoundingNotTwo) {
  const Fx32 quarter = Fx32::fromRaw(Fx32::kOneRaw / 4);
  // eps * 1/4 / (1/4): the exact value is eps; rounding the product first loses it.
  EXPECT_EQ(Fx32::mulDiv(Fx32::epsilon(), quarter, quarter), Fx32::epsilon());
  EXPECT_EQ((Fx32::epsilon() * quarter) / quarter, Fx32(0));
  // A product far beyond the range whose quotient fits: 2e9 * 2e9 / 4e9... via 30000 in Fx16.
  EXPECT_EQ(Fx16::mulDiv(Fx16(30000), Fx16(30000), Fx16(30000)), Fx16(30000));
  EXPECT_EQ(Fx32::mulDiv(Fx32::fromRaw(1), Fx32::fromRaw(1), Fx32::fromRaw(2)).raw(), 1);  // 0.5 -> 1
  EXPECT_EQ(Fx32::mulDiv(Fx32::fromRaw(-1), Fx32::fromRaw(1), Fx32::fromRaw(2)).raw(), -1);
  EXPECT_EQ(Fx32::mulDiv(Fx32(1), Fx32(1), Fx32(3)).raw(), 1431655765);
  EXPECT_EQ(sg::takeFixedFaults(), 0u);
}

// ---- limits and comparisons ----------------------------------------------------------------

TEST_F(FixedCompare, LimitsAndConstants) {
  EXPECT_EQ(Fx32::max().raw(), std::numeric_limits<int64_t>::max());
  EXPECT_EQ(Fx32::min().raw(), std::numeric_limits<int64_t>::min());
  EXPECT_EQ(Fx32::epsilon().raw(), 1);
  EXPECT_EQ(Fx32::kOneRaw, int64_t(1) << 32);
  EXPECT_EQ(Fx32::kFracBits, 32);
  EXPECT_EQ(Fx16::max().raw(), std::numeric_limits<int32_t>::max());
  EXPECT_EQ(Fx16::min().raw(), std::numeric_limits<int32_t>::min());
  EXPECT_EQ(Fx16::epsilon().raw(), 1);
  EXPECT_EQ(Fx16::kOneRaw, 65536);
  EXPECT_EQ(Fx16::kFracBits, 16);
  EXPECT_EQ(Fx16::max().toDouble(), 32767.9999847412109375);
  EXPECT_EQ(Fx16::min().toDouble(), -32768.0);
  EXPECT_EQ(Fx32::min().toDouble(), -2147483648.0);
  EXPECT_EQ(Fx32::epsilon().toDouble(), std::ldexp(1.0, -32));
  EXPECT_EQ(Fx32().raw(), 0);
  EXPECT_EQ(Fx16().raw(), 0);
  static_assert(sizeof(Fx32) == 8 && sizeof(Fx16) == 4);
}

template <class Fx>
void comparisons(uint64_t seed) {
  std::mt19937_64 g(seed);
  Mismatches m;
  using Raw = typename Fx::RawType;
  using U = std::make_unsigned_t<Raw>;
  for (int i = 0; i < 100000; ++i) {
    const Raw ra = (i & 1) ? fullRaw<Fx>(g) : typicalRaw<Fx>(g, 3);
    Raw rb;
    switch (i % 3) {
      case 0:
        rb = fullRaw<Fx>(g);
        break;
      case 1:
        rb = typicalRaw<Fx>(g, 3);
        break;
      default:
        rb = static_cast<Raw>(U(ra) + U(g() & 1));
        break;  // equal or one ulp apart
    }
    const Fx a = Fx::fromRaw(ra), b = Fx::fromRaw(rb);
    const auto x = a.raw(), y = b.raw();
    m.check((a < b) == (x < y) && (a <= b) == (x <= y) && (a > b) == (x > y) && (a >= b) == (x >= y) &&
                (a == b) == (x == y) && (a != b) == (x != y) && sg::min(a, b).raw() == std::min(x, y) &&
                sg::max(a, b).raw() == std::max(x, y),
            [&] { return "raw " + str(I128(x)) + " vs " + str(I128(y)); });
  }
  EXPECT_TRUE(m.result());
  EXPECT_LT(Fx::min(), Fx(-1));
  EXPECT_LT(Fx(-1), -Fx::epsilon());
  EXPECT_LT(-Fx::epsilon(), Fx(0));
  EXPECT_LT(Fx(0), Fx::epsilon());
  EXPECT_LT(Fx::epsilon(), Fx(1));
  EXPECT_LT(Fx(1), Fx::max());
  EXPECT_GT(Fx(2), Fx::fromRaw(2 * Fx::kOneRaw - 1));
  EXPECT_EQ(sg::min(Fx(-3), Fx(2)), Fx(-3));
  EXPECT_EQ(sg::max(Fx(-3), Fx(2)), Fx(2));
  EXPECT_EQ(sg::abs(Fx(-3)), Fx(3));
  EXPECT_EQ(sg::abs(Fx::max()), Fx::max());
  EXPECT_EQ(sg::abs(-Fx::max()), Fx::max());
  Fx c(5);
  c += Fx(2);
  EXPECT_EQ(c, Fx(7));
  c -= Fx(10);
  EXPECT_EQ(c, Fx(-3));
  c *= Fx(-4);
  EXPECT_EQ(c, Fx(12));
  c /= Fx(8);
  EXPECT_EQ(c, Fx::fromRaw(3 * Fx::kOneRaw / 2));
  EXPECT_EQ(+c, c);
  EXPECT_EQ(sg::takeFixedFaults(), 0u);
}
TEST_F(FixedCompare, Fx32OperatorsFollowRawOrder) { comparisons<Fx32>(101); }
TEST_F(FixedCompare, Fx16OperatorsFollowRawOrder) { comparisons<Fx16>(102); }

}  // namespace

namespace sg {
namespace {
// floorOfProduct: floor(a * b) as an integer where the product does not fit the scalar (a lattice
// index far from the origin in Q16.16), and the same integer as floorToInt(a * b) where it does.
TEST(FixedFloorOfProduct, BeyondTheRangeAndEqualWithin) {
  const Fx16 far = Fx16::fromRaw(int32_t(8199) << 16 | (1 << 14));  // 8199.25 m
  EXPECT_EQ(floorOfProduct(far, Fx16(4)), 32797);                   // beyond Q16.16's 32767.99
  EXPECT_EQ(floorOfProduct(Fx16(-far), Fx16(4)), -32797);
  EXPECT_EQ(takeFixedFaults(), 0u) << "no overflow raised";
  uint64_t state = 0x9e3779b97f4a7c15ULL;
  for (int i = 0; i < 20000; ++i) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    const Fx16 a = Fx16::fromRaw(int32_t(uint32_t(state >> 32)) >> 9);  // |a| < 64
    const Fx16 b = Fx16::fromRaw(int32_t(uint32_t(state)) >> 9);
    ASSERT_EQ(floorOfProduct(a, b), floorToInt(a * b)) << a.toDouble() << " x " << b.toDouble();
    const Fx32 c = Fx32::fromRaw(int64_t(state) >> 20), e = Fx32::fromRaw(int64_t(state * 31) >> 22);
    ASSERT_EQ(floorOfProduct(c, e), floorToInt(c * e)) << c.toDouble() << " x " << e.toDouble();
  }
  EXPECT_EQ(takeFixedFaults(), 0u);
}
}  // namespace
}  // namespace sg
