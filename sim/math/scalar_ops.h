// Small scalar helpers used by the stages, written once for all four scalars.
#pragma once

#include <cmath>
#include <cstdint>

#include "sim/math/scalar.h"

namespace sg {

/// floor(v) as an integer (exact for every scalar).
template <class S>
inline int64_t floorToInt(S v) {
  if constexpr (ScalarTraits<S>::isFixed) {
    return int64_t(v.raw() >> S::kFracBits);  // arithmetic shift: floor
  } else {
    return int64_t(std::floor(v));  // floor is exact in IEEE arithmetic
  }
}

/// floor(a * b) as an integer, for an index (a coordinate times an inverse spacing) that may not
/// fit the scalar itself: in Q16.16 a corner 16,000 m from the lattice origin times 4 per metre is
/// 64,000, beyond its 32,767 (the grid broad phase then lost particles brute force found).
template <class S>
inline int64_t floorOfProduct(S a, S b) {
  if constexpr (ScalarTraits<S>::isFixed) {
    return S::floorOfProduct(a, b);
  } else {
    return int64_t(std::floor(a * b));
  }
}

/// v - floor(v), in [0, 1).
template <class S>
inline S fractionalPart(S v) {
  if constexpr (ScalarTraits<S>::isFixed) {
    using Raw = typename S::RawType;
    return S::fromRaw(Raw(v.raw() & (S::kOneRaw - 1)));
  } else {
    return v - std::floor(v);
  }
}

/// A uniform value in [0, 1) from 32 random bits, rounded into S (exact for fx32 and double).
template <class S>
inline S unitFromBits(uint32_t bits) {
  if constexpr (ScalarTraits<S>::isFixed) {
    using Raw = typename S::RawType;
    constexpr int shift = 32 - S::kFracBits;
    if constexpr (shift <= 0) {
      return S::fromRaw(Raw(bits) << -shift);
    } else {
      // Round to nearest; the result may reach exactly 1 for fx16 (documented, harmless).
      return S::fromRaw(Raw((uint64_t(bits) + (uint64_t(1) << (shift - 1))) >> shift));
    }
  } else {
    return S(double(bits) * (1.0 / 4294967296.0));
  }
}

template <class S>
inline S minS(S a, S b) {
  return b < a ? b : a;
}
template <class S>
inline S maxS(S a, S b) {
  return a < b ? b : a;
}

/// a + (b - a) * t: linear interpolation; exact at t = 0 for every scalar.
template <class S>
inline S lerp(S a, S b, S t) {
  return a + (b - a) * t;
}

}  // namespace sg

namespace sg {
/// s * n for an integer n, exact before the final rounding (no overflow of S(n) in fx16).
template <class S>
inline S mulInt(S s, int64_t n) {
  if constexpr (ScalarTraits<S>::isFixed) {
    using W = typename S::WideType;
    return S::fromRaw(S::narrow(W(s.raw()) * W(n)));
  } else {
    return s * S(n);
  }
}
}  // namespace sg
