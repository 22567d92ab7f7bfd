// The portable 128-bit integers (sg::portable::Int128 / UInt128, sim/math/int128.h) against the
// builtin __int128, bit for bit, and the fixed-point formats built on them against the builtin
// ones: Fixed<int64_t, portable::Int128, 32> against Fx32, Fx16's square roots with a portable
// radicand against Fx16's own.
//
// The portable types are what i686 and wasm32 builds compute with; x86-64 builds use __int128.
// Both are compiled here in one binary (the portable types always exist), so every operation is
// compared directly. Inputs: RapidCheck properties, 3000 cases each (random seed each run,
// shrinking on failure; RC_PARAMS="seed=..." reproduces) over a generator biased to the edges
// (0, +-1, powers of two, INT128_MIN/MAX, values near 2^64, every bit length), plus fixed-seed
// sweeps of many more.
#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>  // RapidCheck's GoogleTest glue (checkTestable, printResultMessage)

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "sim/math/fixed.h"
#include "sim/math/int128.h"

#if defined(__SIZEOF_INT128__)

namespace {

using I128 = __int128;
using U128 = unsigned __int128;
using P = sg::portable::Int128;
using PU = sg::portable::UInt128;

// Conversions through the limbs only, so the tests do not lean on the portable constructors.
PU toPU(U128 v) { return PU::fromLimbs(uint64_t(v >> 64), uint64_t(v)); }
P toP(I128 v) { return P::fromLimbs(uint64_t(U128(v) >> 64), uint64_t(U128(v))); }
U128 fromPU(PU v) { return (U128(v.hi()) << 64) | v.lo(); }
I128 fromP(P v) { return I128((U128(v.hi()) << 64) | v.lo()); }

std::string hex(U128 v) {
  std::ostringstream o;
  o << "0x" << std::hex << uint64_t(v >> 64) << "'" << uint64_t(v);
  return o.str();
}

/// A generated 128-bit pattern, read as signed or unsigned by each property.
struct W128 {
  uint64_t hi = 0, lo = 0;
  U128 u() const { return (U128(hi) << 64) | lo; }
  I128 s() const { return I128(u()); }
  static W128 of(U128 v) { return W128{uint64_t(v >> 64), uint64_t(v)}; }
};
void showValue(const W128& w, std::ostream& os) { os << hex(w.u()); }

/// The edges of every operation: 0, +-1, +-2, around 2^63, 2^64, 2^127 and their negatives.
std::vector<W128> edgeValues() {
  std::vector<W128> e;
  const U128 kTop = U128(1) << 127;
  for (U128 v : {U128(0), U128(1), U128(2), U128(3), U128(10), U128(1) << 31, U128(1) << 32, U128(1) << 63,
                 U128(1) << 64, U128(1) << 65, U128(1) << 96, U128(1) << 126, kTop, kTop - 1, ~U128(0) >> 64,
                 U128(~uint64_t(0)) << 64, (U128(1) << 64) + (U128(1) << 63)}) {
    e.push_back(W128::of(v));
    e.push_back(W128::of(U128(0) - v));
  }
  return e;
}

/// value with `bits` significant bits (a uniform pattern, top bit forced), optionally negated.
W128 withBitLength(uint64_t hi, uint64_t lo, int bits, bool negate) {
  U128 v = bits == 0 ? 0 : ((U128(hi) << 64 | lo) >> (128 - bits)) | (U128(1) << (bits - 1));
  return W128::of(negate ? U128(0) - v : v);
}

rc::Gen<W128> genW128() {
  using namespace rc;
  static const std::vector<W128> kEdges = edgeValues();
  return gen::weightedOneOf<W128>({
      // Uniform limbs (RapidCheck scales them with its size: small values first).
      {3, gen::construct<W128>(gen::arbitrary<uint64_t>(), gen::arbitrary<uint64_t>())},
      // An edge, or an edge plus a small step.
      {2, gen::apply([](W128 e, int step) { return W128::of(e.u() + U128(I128(step))); }, gen::elementOf(kEdges),
                     gen::inRange(-3, 4))},
      // +-(2^k + {-1, 0, 1}).
      {2, gen::apply(
              [](int k, int step, bool negate) {
                const U128 v = (U128(1) << k) + U128(I128(step));
                return W128::of(negate ? U128(0) - v : v);
              },
              gen::inRange(0, 128), gen::inRange(-1, 2), gen::arbitrary<bool>())},
      // Every bit length 0..128 equally often: divisors and dividends of all sizes.
      {3, gen::apply(withBitLength, gen::arbitrary<uint64_t>(), gen::arbitrary<uint64_t>(), gen::inRange(0, 129),
                     gen::arbitrary<bool>())},
  });
}

/// The same mix for the fixed-seed sweep.
W128 drawW128(std::mt19937_64& g) {
  static const std::vector<W128> kEdges = edgeValues();
  switch (g() % 4) {
    case 0:
      return W128{g(), g()};
    case 1:
      return W128::of(kEdges[g() % kEdges.size()].u() + U128(I128(int(g() % 7) - 3)));
    case 2: {
      const U128 v = (U128(1) << (g() % 128)) + U128(I128(int(g() % 3) - 1));
      return W128::of(g() & 1 ? U128(0) - v : v);
    }
    default: {
      const uint64_t hi = g(), lo = g();
      return withBitLength(hi, lo, int(g() % 129), g() & 1);
    }
  }
}

/// RC_GTEST_PROP, with at least kMinCases cases (RapidCheck's default is 100; these properties
/// take microseconds each, and the generated sizes sweep 0..maxSize over the run). RC_PARAMS
/// still sets the seed, and a larger max_success.
constexpr int kMinCases = 3000;
template <class Property>
void checkManyCases(Property property) {
  using namespace rc::detail;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  TestMetadata metadata;
  metadata.id = std::string(info->test_suite_name()) + "/" + info->name();
  metadata.description = info->name();
  TestParams params = configuration().testParams;
  params.maxSuccess = std::max(params.maxSuccess, kMinCases);
  const auto result = rc::detail::checkProperty(toProperty(property), metadata, params);
  if (!result.template is<SuccessResult>()) {
    std::ostringstream message;
    printResultMessage(result, message);
    FAIL() << message.str();
  }
}
#define INT128_PROP(Suite, Name)                                    \
  void Suite##_##Name##_property();                                 \
  TEST(Suite, Name) { checkManyCases(&Suite##_##Name##_property); } \
  void Suite##_##Name##_property()

#define SAME(got, want, what)                                                                              \
  do {                                                                                                     \
    const U128 got_ = U128(got), want_ = U128(want);                                                       \
    if (got_ != want_) RC_FAIL(std::string(what) + ": portable " + hex(got_) + ", builtin " + hex(want_)); \
  } while (0)

// ---- each operation against the builtin types --------------------------------------------------

INT128_PROP(Int128Portable, AddSubMulNegateWrapLikeBuiltin) {
  const W128 a = *genW128(), b = *genW128();
  SAME(fromPU(toPU(a.u()) + toPU(b.u())), a.u() + b.u(), "u +");
  SAME(fromPU(toPU(a.u()) - toPU(b.u())), a.u() - b.u(), "u -");
  SAME(fromPU(toPU(a.u()) * toPU(b.u())), a.u() * b.u(), "u *");
  SAME(fromPU(-toPU(a.u())), -a.u(), "u unary -");
  // Signed + - * wrap in GCC/Clang's __int128 as two's complement; compute the builtin
  // reference in unsigned so the reference itself has no overflow.
  SAME(fromP(toP(a.s()) + toP(b.s())), a.u() + b.u(), "s +");
  SAME(fromP(toP(a.s()) - toP(b.s())), a.u() - b.u(), "s -");
  SAME(fromP(toP(a.s()) * toP(b.s())), a.u() * b.u(), "s *");
  SAME(fromP(-toP(a.s())), U128(0) - a.u(), "s unary -");
  PU cu = toPU(a.u());
  cu += toPU(b.u());
  SAME(fromPU(cu), a.u() + b.u(), "u +=");
  P cs = toP(a.s());
  cs *= toP(b.s());
  SAME(fromP(cs), a.u() * b.u(), "s *=");
  cs -= toP(b.s());
  SAME(fromP(cs), a.u() * b.u() - b.u(), "s -=");
}

INT128_PROP(Int128Portable, DivisionTruncatesLikeBuiltin) {
  const W128 a = *genW128(), b = *genW128();
  RC_PRE(b.u() != 0);
  SAME(fromPU(toPU(a.u()) / toPU(b.u())), a.u() / b.u(), "u /");
  SAME(fromPU(toPU(a.u()) % toPU(b.u())), a.u() % b.u(), "u %");
  PU r;
  SAME(fromPU(PU::divMod(toPU(a.u()), toPU(b.u()), &r)), a.u() / b.u(), "divMod q");
  SAME(fromPU(r), a.u() % b.u(), "divMod r");
  if (!(a.s() == std::numeric_limits<I128>::min() && b.s() == -1)) {  // the builtin's UB
    SAME(fromP(toP(a.s()) / toP(b.s())), a.s() / b.s(), "s /");
    SAME(fromP(toP(a.s()) % toP(b.s())), a.s() % b.s(), "s %");
    P q = toP(a.s());
    q /= toP(b.s());
    SAME(fromP(q), a.s() / b.s(), "s /=");
  }
}

INT128_PROP(Int128Portable, DivisionBy64BitDivisorsLikeBuiltin) {
  // The 128/64 paths (one or two divlu steps) with every divisor size up to 64 bits.
  const W128 a = *genW128();
  const int bits = *rc::gen::inRange(1, 65);
  const uint64_t d = (*rc::gen::arbitrary<uint64_t>() >> (64 - bits)) | (uint64_t(1) << (bits - 1));
  SAME(fromPU(toPU(a.u()) / PU(d)), a.u() / d, "u / d64");
  SAME(fromPU(toPU(a.u()) % PU(d)), a.u() % d, "u % d64");
  SAME(fromP(toP(a.s()) / P(int64_t(d))), a.s() / I128(int64_t(d)), "s / d64");
  SAME(fromP(toP(a.s()) % P(int64_t(d))), a.s() % I128(int64_t(d)), "s % d64");
}

INT128_PROP(Int128Portable, ShiftsLikeBuiltin) {
  const W128 a = *genW128();
  const int n = *rc::gen::inRange(0, 128);
  SAME(fromPU(toPU(a.u()) << n), a.u() << n, "u <<");
  SAME(fromPU(toPU(a.u()) >> n), a.u() >> n, "u >>");
  SAME(fromP(toP(a.s()) << n), a.u() << n, "s <<");
  SAME(fromP(toP(a.s()) >> n), a.s() >> n, "s >> (arithmetic)");
  P c = toP(a.s());
  c >>= n;
  SAME(fromP(c), a.s() >> n, "s >>=");
  PU d = toPU(a.u());
  d <<= n;
  SAME(fromPU(d), a.u() << n, "u <<=");
}

INT128_PROP(Int128Portable, BitwiseLikeBuiltin) {
  const W128 a = *genW128(), b = *genW128();
  SAME(fromPU(toPU(a.u()) & toPU(b.u())), a.u() & b.u(), "u &");
  SAME(fromPU(toPU(a.u()) | toPU(b.u())), a.u() | b.u(), "u |");
  SAME(fromPU(toPU(a.u()) ^ toPU(b.u())), a.u() ^ b.u(), "u ^");
  SAME(fromPU(~toPU(a.u())), ~a.u(), "u ~");
  SAME(fromP(toP(a.s()) & toP(b.s())), a.s() & b.s(), "s &");
  SAME(fromP(toP(a.s()) | toP(b.s())), a.s() | b.s(), "s |");
  SAME(fromP(~toP(a.s())), ~a.s(), "s ~");
}

INT128_PROP(Int128Portable, ComparisonsLikeBuiltin) {
  const W128 a = *genW128();
  // Half the time compare with a neighbour, so equal and adjacent values come up often.
  const W128 b = *rc::gen::oneOf(genW128(), rc::gen::just(a), rc::gen::just(W128::of(a.u() + 1)));
  const PU pu = toPU(a.u()), qu = toPU(b.u());
  const P ps = toP(a.s()), qs = toP(b.s());
  RC_ASSERT((pu == qu) == (a.u() == b.u()));
  RC_ASSERT((pu != qu) == (a.u() != b.u()));
  RC_ASSERT((pu < qu) == (a.u() < b.u()));
  RC_ASSERT((pu <= qu) == (a.u() <= b.u()));
  RC_ASSERT((pu > qu) == (a.u() > b.u()));
  RC_ASSERT((pu >= qu) == (a.u() >= b.u()));
  RC_ASSERT((ps == qs) == (a.s() == b.s()));
  RC_ASSERT((ps < qs) == (a.s() < b.s()));
  RC_ASSERT((ps <= qs) == (a.s() <= b.s()));
  RC_ASSERT((ps > qs) == (a.s() > b.s()));
  RC_ASSERT((ps >= qs) == (a.s() >= b.s()));
  // Against builtin operands converted implicitly, as the ported code writes them (x < 0).
  RC_ASSERT((ps < 0) == (a.s() < 0));
  RC_ASSERT((ps > int64_t(a.lo)) == (a.s() > I128(int64_t(a.lo))));
  RC_ASSERT((pu > a.lo) == (a.u() > U128(a.lo)));
  RC_ASSERT(static_cast<bool>(ps) == (a.s() != 0));
}

INT128_PROP(Int128Portable, ConversionsLikeBuiltin) {
  const W128 a = *genW128();
  // Narrowing is modular (C++20), widening value-preserving / sign-extending.
  RC_ASSERT(static_cast<int64_t>(toP(a.s())) == static_cast<int64_t>(a.s()));
  RC_ASSERT(static_cast<uint64_t>(toP(a.s())) == static_cast<uint64_t>(a.s()));
  RC_ASSERT(static_cast<int32_t>(toP(a.s())) == static_cast<int32_t>(a.s()));
  RC_ASSERT(static_cast<uint32_t>(toPU(a.u())) == static_cast<uint32_t>(a.u()));
  RC_ASSERT(static_cast<int8_t>(toPU(a.u())) == static_cast<int8_t>(a.u()));
  RC_ASSERT(static_cast<uint64_t>(toPU(a.u())) == static_cast<uint64_t>(a.u()));
  SAME(static_cast<U128>(toPU(a.u())), a.u(), "to unsigned __int128");
  SAME(static_cast<I128>(toP(a.s())), a.s(), "to __int128");
  SAME(fromPU(PU(toP(a.s()))), U128(a.s()), "Int128 -> UInt128");
  SAME(fromP(P(toPU(a.u()))), I128(a.u()), "UInt128 -> Int128");
  const int64_t s64 = int64_t(a.lo);
  const int32_t s32 = int32_t(a.lo);
  const int16_t s16 = int16_t(a.lo);
  SAME(fromP(P(s64)), I128(s64), "from int64");
  SAME(fromP(P(s32)), I128(s32), "from int32");
  SAME(fromP(P(s16)), I128(s16), "from int16");
  SAME(fromP(P(a.lo)), I128(a.lo), "from uint64");
  SAME(fromPU(PU(s64)), U128(s64), "unsigned from negative int64 (wraps)");
  SAME(fromPU(PU(a.lo)), U128(a.lo), "unsigned from uint64");
  SAME(fromP(P(a.s())), a.s(), "from __int128");
  SAME(fromPU(PU(a.u())), a.u(), "from unsigned __int128");
}

INT128_PROP(Int128Portable, CheckedArithmeticLikeBuiltins) {
  const W128 a = *genW128(), b = *genW128();
  I128 want;
  P got;
  bool wantOverflow = __builtin_add_overflow(a.s(), b.s(), &want);
  RC_ASSERT(sg::addOverflow(toP(a.s()), toP(b.s()), &got) == wantOverflow);
  SAME(fromP(got), want, "addOverflow result");
  wantOverflow = __builtin_mul_overflow(a.s(), b.s(), &want);
  RC_ASSERT(sg::mulOverflow(toP(a.s()), toP(b.s()), &got) == wantOverflow);
  SAME(fromP(got), want, "mulOverflow result");
  // And the native overloads the alias build uses are the builtins themselves.
  I128 n;
  RC_ASSERT(sg::mulOverflow(a.s(), b.s(), &n) == wantOverflow);
}

TEST(Int128Portable, CheckedArithmeticAtTheLimits) {
  // Products and sums right at the limits, where random inputs rarely land: a magnitude of
  // exactly 2^127 fits when negative only.
  const I128 kMax = std::numeric_limits<I128>::max(), kMin = std::numeric_limits<I128>::min();
  const I128 k63 = I128(1) << 63, k64 = I128(1) << 64;
  const std::pair<I128, I128> kPairs[] = {{-k64, k63}, {k64, k63},   {k64, -k63}, {-k64, -k63},    {kMin, 1},
                                          {kMin, -1},  {-1, kMin},   {kMax, 1},   {kMax, -1},      {kMax, 2},
                                          {kMin, 0},   {kMax, kMin}, {k63, k63},  {-k63, k63 * 2}, {kMin, kMin}};
  for (const auto& [a, b] : kPairs) {
    I128 want;
    P got;
    bool wantOverflow = __builtin_mul_overflow(a, b, &want);
    EXPECT_EQ(sg::mulOverflow(toP(a), toP(b), &got), wantOverflow) << hex(U128(a)) << " * " << hex(U128(b));
    EXPECT_EQ(fromP(got), want) << hex(U128(a)) << " * " << hex(U128(b));
    wantOverflow = __builtin_add_overflow(a, b, &want);
    EXPECT_EQ(sg::addOverflow(toP(a), toP(b), &got), wantOverflow) << hex(U128(a)) << " + " << hex(U128(b));
    EXPECT_EQ(fromP(got), want) << hex(U128(a)) << " + " << hex(U128(b));
  }
}

/// a * b as 8 32-bit digits by schoolbook, independent of mulFull's 64-bit limb structure.
std::array<uint32_t, 8> product256(U128 a, U128 b) {
  std::array<uint32_t, 8> r{};
  for (int i = 0; i < 4; ++i) {
    uint64_t carry = 0;
    const uint64_t ai = uint32_t(a >> (32 * i));
    for (int j = 0; j < 4; ++j) {
      const uint64_t t = ai * uint32_t(b >> (32 * j)) + r[size_t(i + j)] + carry;
      r[size_t(i + j)] = uint32_t(t);
      carry = t >> 32;
    }
    r[size_t(i + 4)] = uint32_t(carry);
  }
  return r;
}

INT128_PROP(Int128Portable, FullProductMatchesSchoolbook) {
  const W128 a = *genW128(), b = *genW128();
  const auto want = product256(a.u(), b.u());
  auto join = [](const std::array<uint32_t, 8>& d, int from) {
    U128 v = 0;
    for (int k = 3; k >= 0; --k) v = (v << 32) | d[size_t(from + k)];
    return v;
  };
  U128 hi;
  const U128 lo = sg::mulFull(a.u(), b.u(), &hi);
  SAME(lo, join(want, 0), "mulFull builtin low");
  SAME(hi, join(want, 4), "mulFull builtin high");
  PU phi;
  const PU plo = sg::mulFull(toPU(a.u()), toPU(b.u()), &phi);
  SAME(fromPU(plo), join(want, 0), "mulFull portable low");
  SAME(fromPU(phi), join(want, 4), "mulFull portable high");
}

INT128_PROP(Int128Portable, IntegerSquareRootLikeBuiltin) {
  const W128 a = *genW128();
  RC_ASSERT(sg::isqrtFloor(toPU(a.u())) == sg::isqrtFloor(a.u()));
  if (a.u() <= ~U128(0) - ~uint64_t(0)) RC_ASSERT(sg::isqrtNearest(toPU(a.u())) == sg::isqrtNearest(a.u()));
}

TEST(Int128Portable, OutsideTheBuiltinPreconditionsNoUndefinedBehaviour) {
  // The builtin types leave these undefined; the portable ones define them (documented in
  // int128.h) so that a bad input cannot become UB on i686.
  const P kMin = sg::kInt128Min;
  EXPECT_EQ(fromP(P(7) / P(0)), 0);
  EXPECT_EQ(fromP(P(7) % P(0)), 7);
  EXPECT_EQ(fromPU(PU(7) / PU(0)), 0u);
  EXPECT_EQ(fromP(kMin / P(-1)), std::numeric_limits<I128>::min());
  EXPECT_EQ(fromP(kMin % P(-1)), 0);
  EXPECT_EQ(fromPU(PU(1) << 128), 1u) << "counts are taken modulo 128";
  EXPECT_EQ(fromPU(PU(6) >> 129), 3u);
}

TEST(Int128Portable, LimitsAndConstants) {
  EXPECT_EQ(fromP(std::numeric_limits<P>::max()), std::numeric_limits<I128>::max());
  EXPECT_EQ(fromP(std::numeric_limits<P>::min()), std::numeric_limits<I128>::min());
  EXPECT_EQ(fromPU(std::numeric_limits<PU>::max()), ~U128(0));
  EXPECT_EQ(fromPU(std::numeric_limits<PU>::min()), 0u);
  EXPECT_TRUE(std::numeric_limits<P>::is_signed);
  EXPECT_FALSE(std::numeric_limits<PU>::is_signed);
  EXPECT_EQ(sg::kInt128Max, std::numeric_limits<sg::Int128>::max());
  EXPECT_EQ(sg::kInt128Min, std::numeric_limits<sg::Int128>::min());
  EXPECT_EQ(sg::high64(sg::kInt128Min), uint64_t(1) << 63);
  EXPECT_EQ(sg::low64(sg::Int128(-2)), ~uint64_t(1));
  EXPECT_EQ(sg::high64(sg::Int128(-2)), ~uint64_t(0));
  EXPECT_EQ(sg::high64(P(-2)), ~uint64_t(0));
  // The production alias is the builtin type on this (x86-64) build: zero cost.
#if SIMGRASS_NATIVE_INT128
  static_assert(std::is_same_v<sg::Int128, __int128> && std::is_same_v<sg::UInt128, unsigned __int128>);
#endif
  // Everything is constexpr, like the builtin operations the fixed-point code uses in constants.
  static_assert(P::fromLimbs(1, 0) / P(3) == P::fromLimbs(0, 0x5555555555555555u));
  static_assert((P(-5) >> 1) == P(-3) && (P(-5) / P(2)) == P(-2) && (P(-5) % P(2)) == P(-1));
  static_assert(PU(~uint64_t(0)) * PU(~uint64_t(0)) == PU::fromLimbs(~uint64_t(1), 1));
  // Layout: on a little-endian host the bytes are the builtin's, so hashes of raw bytes agree.
  static_assert(sizeof(P) == 16 && sizeof(PU) == 16);
}

TEST(Int128Sweep, EveryOperationOnAFixedSeedSample) {
  // Many more samples than the properties, same mix, deterministic: a failure here reproduces.
  std::mt19937_64 g(128);
  constexpr int kN = 300000;
  int mismatches = 0;
  std::string first;
  auto check = [&](bool ok, const char* what, W128 a, W128 b) {
    if (ok) return;
    if (mismatches++ < 5) first += std::string("\n  ") + what + " " + hex(a.u()) + ", " + hex(b.u());
  };
  for (int i = 0; i < kN; ++i) {
    const W128 a = drawW128(g), b = drawW128(g);
    const PU pa = toPU(a.u()), pb = toPU(b.u());
    const P sa = toP(a.s()), sb = toP(b.s());
    const int n = int(g() % 128);
    check(fromPU(pa * pb) == a.u() * b.u(), "*", a, b);
    check(fromPU(pa + pb) == a.u() + b.u() && fromPU(pa - pb) == a.u() - b.u(), "+-", a, b);
    check(fromPU(pa << n) == a.u() << n && fromPU(pa >> n) == a.u() >> n && fromP(sa >> n) == a.s() >> n, "shift", a,
          b);
    check((pa < pb) == (a.u() < b.u()) && (sa < sb) == (a.s() < b.s()), "<", a, b);
    if (b.u() != 0) {
      check(fromPU(pa / pb) == a.u() / b.u() && fromPU(pa % pb) == a.u() % b.u(), "u / %", a, b);
      if (!(a.s() == std::numeric_limits<I128>::min() && b.s() == -1))
        check(fromP(sa / sb) == a.s() / b.s() && fromP(sa % sb) == a.s() % b.s(), "s / %", a, b);
    }
    I128 want;
    P got;
    const bool mo = __builtin_mul_overflow(a.s(), b.s(), &want);
    check(sg::mulOverflow(sa, sb, &got) == mo && fromP(got) == want, "mulOverflow", a, b);
    const bool ao = __builtin_add_overflow(a.s(), b.s(), &want);
    check(sg::addOverflow(sa, sb, &got) == ao && fromP(got) == want, "addOverflow", a, b);
    if (i % 8 == 0) check(sg::isqrtFloor(pa) == sg::isqrtFloor(a.u()), "isqrtFloor", a, b);
  }
  EXPECT_EQ(mismatches, 0) << first;
}

// ---- the fixed-point formats on the portable type -----------------------------------------------

using PFx32 = sg::Fixed<int64_t, P, 32>;
using sg::Fx16;
using sg::Fx32;

/// Raw values biased to the edges of the formats and spread over every bit length (so that
/// quotients take both of divRound's paths, and products overflow or not).
template <class Raw>
rc::Gen<Raw> genRaw() {
  using namespace rc;
  constexpr int kBits = int(sizeof(Raw) * 8);
  using U = std::make_unsigned_t<Raw>;
  constexpr Raw kOne = Raw(1) << (kBits / 2);
  return gen::weightedOneOf<Raw>({
      {2, gen::arbitrary<Raw>()},
      {1, gen::element<Raw>(0, 1, -1, kOne, Raw(-kOne), kOne / 2, std::numeric_limits<Raw>::max(),
                            std::numeric_limits<Raw>::min(), Raw(std::numeric_limits<Raw>::min() + 1))},
      {3, gen::apply(
              [](U bits, int length, bool negate) {
                const U v = length == 0 ? 0 : (bits >> (kBits - length)) | (U(1) << (length - 1));
                return negate ? Raw(U(0) - v) : Raw(v);  // modular: defined
              },
              gen::arbitrary<U>(), gen::inRange(0, kBits + 1), gen::arbitrary<bool>())},
  });
}

/// Raw value and the fault bits one operation raised.
template <class F>
auto withFaults(F&& op) {
  sg::takeFixedFaults();
  const auto raw = op().raw();
  return std::pair{raw, sg::takeFixedFaults()};
}

INT128_PROP(Int128Fixed, Fx32OnThePortableTypeIsBitIdentical) {
  const int64_t a = *genRaw<int64_t>(), b = *genRaw<int64_t>(), c = *genRaw<int64_t>();
  const Fx32 x = Fx32::fromRaw(a), y = Fx32::fromRaw(b), z = Fx32::fromRaw(c);
  const PFx32 px = PFx32::fromRaw(a), py = PFx32::fromRaw(b), pz = PFx32::fromRaw(c);
  RC_ASSERT(withFaults([&] { return px * py; }) == withFaults([&] { return x * y; }));
  RC_ASSERT(withFaults([&] { return px / py; }) == withFaults([&] { return x / y; }));
  RC_ASSERT(withFaults([&] { return PFx32::mulDiv(px, py, pz); }) == withFaults([&] { return Fx32::mulDiv(x, y, z); }));
  RC_ASSERT(withFaults([&] { return sg::sqrt(px); }) == withFaults([&] { return sg::sqrt(x); }));
  RC_ASSERT(withFaults([&] { return sg::length3(px, py, pz); }) == withFaults([&] { return sg::length3(x, y, z); }));
  RC_ASSERT(withFaults([&] { return px + py; }) == withFaults([&] { return x + y; }));
}

INT128_PROP(Int128Fixed, Fx16SquareRootsOnThePortableTypeAreBitIdentical) {
  // Fx16's products and quotients are int64_t everywhere; only its radicands are 128-bit.
  const int32_t a = *genRaw<int32_t>(), b = *genRaw<int32_t>(), c = *genRaw<int32_t>();
  const Fx16 x = Fx16::fromRaw(a), y = Fx16::fromRaw(b), z = Fx16::fromRaw(c);
  RC_ASSERT(withFaults([&] { return sg::detail::sqrtWith<PU>(x); }) == withFaults([&] { return sg::sqrt(x); }));
  RC_ASSERT(withFaults([&] { return sg::detail::length3With<PU>(x, y, z); }) ==
            withFaults([&] { return sg::length3(x, y, z); }));
  // The builtin-radicand instantiation is what sg::sqrt uses on this build.
  RC_ASSERT(sg::detail::sqrtWith<U128>(x) == sg::sqrt(x));
}

TEST(Int128Fixed, Fx32SweepOnAFixedSeedSample) {
  std::mt19937_64 g(3232);
  auto raw = [&g]() -> int64_t {
    switch (g() % 3) {
      case 0:
        return int64_t(g());
      case 1: {
        const int len = int(g() % 65);
        const uint64_t v = len == 0 ? 0 : (g() >> (64 - len)) | (uint64_t(1) << (len - 1));
        return int64_t(g() & 1 ? uint64_t(0) - v : v);
      }
      default: {
        constexpr int64_t kEdges[] = {0,         1,         -1,           int64_t(1) << 32, -(int64_t(1) << 32),
                                      INT64_MAX, INT64_MIN, INT64_MIN + 1};
        return kEdges[g() % 8];
      }
    }
  };
  int mismatches = 0;
  std::string first;
  for (int i = 0; i < 200000; ++i) {
    const int64_t a = raw(), b = raw(), c = raw();
    const Fx32 x = Fx32::fromRaw(a), y = Fx32::fromRaw(b), z = Fx32::fromRaw(c);
    const PFx32 px = PFx32::fromRaw(a), py = PFx32::fromRaw(b), pz = PFx32::fromRaw(c);
    const bool ok =
        withFaults([&] { return px * py; }) == withFaults([&] { return x * y; }) &&
        withFaults([&] { return px / py; }) == withFaults([&] { return x / y; }) &&
        withFaults([&] { return PFx32::mulDiv(px, py, pz); }) == withFaults([&] { return Fx32::mulDiv(x, y, z); }) &&
        withFaults([&] { return sg::sqrt(px); }) == withFaults([&] { return sg::sqrt(x); }) &&
        withFaults([&] { return sg::length3(px, py, pz); }) == withFaults([&] { return sg::length3(x, y, z); });
    if (!ok && mismatches++ < 5)
      first += "\n  raws " + std::to_string(a) + ", " + std::to_string(b) + ", " + std::to_string(c);
  }
  EXPECT_EQ(mismatches, 0) << first;
}

}  // namespace

#else  // no __int128 to compare with (i686, wasm32): nothing to run here

TEST(Int128Portable, NeedsTheBuiltinTypeToCompareWith) { GTEST_SKIP() << "no __int128 on this target"; }

#endif
