// Recorded inputs (Q32.32 raw integers, tick_input.h) rounded into the world's scalar.
#pragma once

#include <cstdint>

#include "sim/math/eigen_support.h"
#include "sim/math/scalar.h"
#include "sim/world/tick_input.h"

namespace sg {

/// raw / 2^32 rounded once into S. Scenario and input-track validation keep inputs in range; an
/// input that still does not fit S (a recording replayed with a narrower scalar) raises a
/// fixed-point overflow fault, which the input stage reports as a simulation error naming the
/// body - never a silent 0. The value returned then is S's extreme of the input's sign.
template <class S>
S inputScalar(int64_t raw) {
  if (const auto v = ScalarTraits<S>::fromRational(Rational{raw, int64_t(1) << 32})) return *v;
  if constexpr (ScalarTraits<S>::isFixed) {
    detail::raiseFixedFault(kFixedFaultOverflow);
    return raw < 0 ? S::min() : S::max();
  } else {
    return S(0);  // unreachable: a float or double takes every Q32.32 value
  }
}

template <class S>
Vec3<S> inputVector(const InputVec3& v) {
  return Vec3<S>(inputScalar<S>(v.x), inputScalar<S>(v.y), inputScalar<S>(v.z));
}

}  // namespace sg
