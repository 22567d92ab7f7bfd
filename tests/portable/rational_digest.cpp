// Exercises sg::Rational (sim/math/rational.cpp) on a fixed pseudo-random sample and prints
// every result as text: parse, make, add/sub/mul/div, compare, toDouble (its bits),
// toScaledInteger, roundToInt64, toString and deterministicPow. .ci/i686-core-hashes builds it
// with the portable Int128 (i686, or -DSIMGRASS_PORTABLE_INT128) and with the host's builtin
// __int128, and requires the two outputs to be identical: the exact rationals, ported to
// sg::Int128, give the same bits either way.
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <optional>
#include <random>
#include <string>

#include "sim/math/rational.h"

namespace {
std::mt19937_64 g(20240613);  // fully specified by the standard: the same sequence everywhere

std::string hex(sg::Int128 v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%016" PRIx64 "%016" PRIx64, sg::high64(v), sg::low64(v));
  return buf;
}
std::string show(const std::optional<sg::Rational>& r) {
  return r ? hex(r->num) + "/" + hex(r->den) : std::string("none");
}
std::string show(const std::optional<sg::Int128>& v) { return v ? hex(*v) : std::string("none"); }

/// A value with a uniformly random bit length 1..127, either sign.
sg::Int128 drawWide() {
  const int bits = 1 + int(g() % 127);
  const uint64_t hi = g(), lo = g();
  sg::UInt128 v = (sg::UInt128(hi) << 64) | lo;
  v = (v >> (128 - bits)) | (sg::UInt128(1) << (bits - 1));
  const sg::Int128 s = sg::Int128(v);
  return (g() & 1) ? -s : s;
}
std::string drawDecimal() {
  std::string s = (g() & 1) ? "-" : "";
  const int digits = 1 + int(g() % 30);
  std::string mant;
  for (int k = 0; k < digits; ++k) mant += char('0' + int(g() % 10));
  if (g() & 1) mant.insert(mant.begin() + std::ptrdiff_t(g() % (mant.size() + 1)), '.');
  if (mant.front() == '.') mant.insert(mant.begin(), '0');
  s += mant;
  if (g() % 3 != 0) s += "e" + std::to_string(int(g() % 61) - 30);
  if (g() % 8 == 0) s += "/" + std::to_string(1 + g() % 1000);
  return s;
}
}  // namespace

int main() {
  int lines = 0;
  auto out = [&lines](const std::string& line) {
    std::puts(line.c_str());
    ++lines;
  };
  for (int i = 0; i < 4000; ++i) {
    const std::string text = drawDecimal();
    std::string error;
    const auto a = sg::Rational::parse(text, &error);
    std::string line = text + " " + show(a);
    if (a) {
      uint64_t bits;
      const double d = a->toDouble();
      std::memcpy(&bits, &d, sizeof bits);
      char b[24];
      std::snprintf(b, sizeof b, "%016" PRIx64, bits);
      const auto i64 = a->roundToInt64();
      line += " d=" + std::string(b) + " q32=" + show(a->toScaledInteger(32)) + " q62=" + show(a->toScaledInteger(62)) +
              " i=" + (i64 ? std::to_string(*i64) : std::string("none")) + " s=" + a->toString();
    } else {
      line += " error=" + error;
    }
    out(line);
  }
  for (int i = 0; i < 4000; ++i) {
    // Pairs of every size: small decimal-like fractions and full-width ones. Each draw is its
    // own statement: the order of evaluation of function arguments is unspecified.
    auto draw = [&]() {
      sg::Int128 num, den;
      if (g() % 2) {
        num = int64_t(g()) >> (g() % 60);  // shifts: left operand first (C++17)
        den = 1 + (g() >> (4 + g() % 60));
      } else {
        num = drawWide();
        den = drawWide();
      }
      return sg::Rational::make(num, den);
    };
    const auto a = draw();
    const auto b = draw();
    if (!a || !b) {
      out("make none");
      continue;
    }
    out(show(a) + " " + show(b) + " + " + show(sg::add(*a, *b)) + " - " + show(sg::sub(*a, *b)) + " * " +
        show(sg::mul(*a, *b)) + " / " + show(sg::div(*a, *b)) + " <=> " + std::to_string(sg::compare(*a, *b)));
  }
  for (int i = 0; i < 300; ++i) {
    // damping^dt-like inputs: 0 < base <= 1, exponent >= 0.
    const sg::Int128 baseNum = 1 + g() % 1000000, expNum = g() % 5000, expDen = 1 + g() % 600;
    const auto base = sg::Rational::make(baseNum, sg::Int128(1000000));
    const auto exponent = sg::Rational::make(expNum, expDen);
    out("pow " + show(base) + " " + show(exponent) + " " + show(sg::deterministicPow(*base, *exponent)));
  }
  std::fprintf(stderr, "%d lines\n", lines);
  return 0;
}
