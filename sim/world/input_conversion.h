// Recorded inputs (Q32.32 raw integers, tick_input.h) rounded into the world's scalar.
#pragma once

#include <cstdint>

#include "sim/math/eigen_support.h"
#include "sim/math/scalar.h"
#include "sim/world/tick_input.h"

namespace sg {

/// raw / 2^32 rounded once into S (0 when it does not fit S: scenario and input validation keep
/// inputs in range).
template <class S>
S inputScalar(int64_t raw) {
  return ScalarTraits<S>::fromRational(Rational{raw, int64_t(1) << 32}).value_or(S(0));
}

template <class S>
Vec3<S> inputVector(const InputVec3& v) {
  return Vec3<S>(inputScalar<S>(v.x), inputScalar<S>(v.y), inputScalar<S>(v.z));
}

}  // namespace sg
