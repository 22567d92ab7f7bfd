#include "sim/math/fixed.h"

#include <cmath>

namespace sg {
namespace detail {
__thread uint32_t tlsFixedFaults __attribute__((tls_model("initial-exec"))) = 0;
void raiseFixedFault(uint32_t fault) noexcept { tlsFixedFaults |= fault; }
}  // namespace detail

const char* fixedFaultName(uint32_t faults) noexcept {
  if (faults & kFixedFaultDivideByZero) return "division by zero";
  if (faults & kFixedFaultDomain) return "square root of a negative number";
  if (faults & kFixedFaultOverflow) return "fixed-point overflow";
  return "none";
}

namespace {
/// One algorithm for both unsigned 128-bit types (builtin and portable): same integer steps.
template <class U>
uint64_t isqrtFloorImpl(U n) noexcept {
  if (n == 0) return 0;
  // A double estimate, then exact integer correction: only the corrected integer is kept, so
  // the result is exact and identical on every machine whatever the estimate's rounding.
  // Normalise so that the estimate is good to < 1 ulp of the result for any input size.
  const uint64_t hi = uint64_t(n >> 64), lo = uint64_t(n);
  const double approx = std::sqrt(double(hi) * 18446744073709551616.0 + double(lo));
  uint64_t r = approx >= 18446744073709551615.0 ? ~uint64_t(0) : uint64_t(approx);
  if (hi >= (uint64_t(1) << 40)) {
    // Above 2^104 the double estimate can be off by more than a few units: one Newton step
    // (integer, exact) brings it within one.
    if (r == 0) r = 1;
    const U q = n / r;
    const U next = (U(r) + q) >> 1;
    r = next > U(~uint64_t(0)) ? ~uint64_t(0) : uint64_t(next);
  }
  while (U(r) * r > n) --r;
  // (r+1)^2 <= n, guarding r+1 == 2^64 (then (r+1)^2 = 2^128 > any n).
  while (r != ~uint64_t(0) && (U(r) + 1) * (U(r) + 1) <= n) ++r;
  return r;
}
}  // namespace

uint64_t isqrtFloor(UInt128 n) noexcept { return isqrtFloorImpl(n); }
#if SIMGRASS_NATIVE_INT128
uint64_t isqrtFloor(portable::UInt128 n) noexcept { return isqrtFloorImpl(n); }
#endif
}  // namespace sg
