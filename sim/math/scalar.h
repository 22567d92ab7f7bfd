// The four scalar types the core is written over, and what the core needs to know about each.
//
//   fx32   Q32.32  reference for bit-exact replay (default)
//   fx16   Q16.16  fast variant, range about +-32 km, resolution 1.5e-5
//   float  IEEE binary32   comparison
//   double IEEE binary64   accuracy reference
// float/double reproduce across builds and architectures only under the build's rules
// (-ffp-contract=off, EIGEN_DONT_VECTORIZE, SSE2 on i686): docs/determinism.md.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string_view>
#include <type_traits>

#include "sim/math/fixed.h"
#include "sim/math/rational.h"

namespace sg {

enum class ScalarKind : uint8_t { Fx32 = 0, Fx16 = 1, Float = 2, Double = 3 };

const char* scalarName(ScalarKind kind);
std::optional<ScalarKind> parseScalarKind(std::string_view name);

template <class S>
struct ScalarTraits;

namespace detail {
template <class Fx, ScalarKind K>
struct FixedTraits {
  static constexpr ScalarKind kind = K;
  static constexpr bool isFixed = true;
  /// Largest coordinate magnitude a scenario may use: a quarter of the range, so that sums and
  /// differences of two coordinates (and a rod length) can never overflow.
  static constexpr double maxCoordinate =
      double(std::numeric_limits<typename Fx::RawType>::max() >> Fx::kFracBits) / 4.0;
  static std::optional<Fx> fromRational(const Rational& r) {
    const auto v = r.toScaledInteger(Fx::kFracBits);
    using Raw = typename Fx::RawType;
    if (!v || *v > Int128(std::numeric_limits<Raw>::max()) || *v < Int128(std::numeric_limits<Raw>::min()))
      return std::nullopt;
    return Fx::fromRaw(static_cast<Raw>(*v));
  }
  static double toDouble(Fx v) { return v.toDouble(); }
  static bool faultPending() { return pendingFixedFaults() != 0; }
  static bool isFinite(Fx) { return true; }
  static bool inStateRange(Fx) { return true; }  ///< every fixed-point value can be saved
  using Bits = std::make_unsigned_t<typename Fx::RawType>;
  static Bits bits(Fx v) { return static_cast<Bits>(v.raw()); }
  static Fx fromBits(Bits b) { return Fx::fromRaw(static_cast<typename Fx::RawType>(b)); }
};
template <class F, ScalarKind K, class B>
struct FloatTraits {
  static constexpr ScalarKind kind = K;
  static constexpr bool isFixed = false;
  /// Largest magnitude a float or double state may hold (m, m/s, rad/s, N s), saved or stepped:
  /// 2^48, small enough that a step's integer cell lookups (floorToInt of a position over a
  /// spacing) cannot overflow int64. The world faults a body that leaves it (World::bodiesFaulted)
  /// and a saved state beyond it is refused, so every state a run reaches can be saved and read.
  static constexpr double maxStateMagnitude = 281474976710656.0;  // 2^48
  /// Largest value a scenario may give: 1e14, below maxStateMagnitude with room for motion (a
  /// body loaded at 5e14 m, inside the former 1e15, recorded a state no replay could read).
  static constexpr double maxCoordinate = 1e14;
  static std::optional<F> fromRational(const Rational& r) { return F(r.toDouble()); }
  static double toDouble(F v) { return double(v); }
  static bool faultPending() { return false; }
  static bool isFinite(F v) { return std::isfinite(v); }
  /// Finite and within +-maxStateMagnitude: what a saved state may hold (NaN fails the compare).
  /// The particle stages fault on anything else, as World::bodiesFaulted does for bodies: a
  /// particle accelerated past 2^48 was stepped on and recorded into snapshots no replay could
  /// read (an independent pass, 2026-11-28).
  static bool inStateRange(F v) { return std::fabs(double(v)) <= maxStateMagnitude; }
  using Bits = B;
  static Bits bits(F v) {
    Bits b;
    std::memcpy(&b, &v, sizeof b);
    return b;
  }
  static F fromBits(Bits b) {
    F v;
    std::memcpy(&v, &b, sizeof v);
    return v;
  }
};
}  // namespace detail

template <>
struct ScalarTraits<Fx32> : detail::FixedTraits<Fx32, ScalarKind::Fx32> {};
template <>
struct ScalarTraits<Fx16> : detail::FixedTraits<Fx16, ScalarKind::Fx16> {};
template <>
struct ScalarTraits<float> : detail::FloatTraits<float, ScalarKind::Float, uint32_t> {};
template <>
struct ScalarTraits<double> : detail::FloatTraits<double, ScalarKind::Double, uint64_t> {};

// float/double counterparts of the fixed-point free functions, so kernels are written once.
// sqrt is IEEE correctly rounded (and an instruction with -fno-math-errno): deterministic.
inline float abs(float v) { return std::fabs(v); }
inline double abs(double v) { return std::fabs(v); }
inline float length3(float x, float y, float z) { return std::sqrt(x * x + y * y + z * z); }
inline double length3(double x, double y, double z) { return std::sqrt(x * x + y * y + z * z); }
/// Whether length3(x, y, z) >= r (floating point: the square root itself, so the same answer).
template <class F>
requires std::is_floating_point_v<F>
inline bool length3AtLeast(F x, F y, F z, F r) { return length3(x, y, z) >= r; }

/// Expands M(S) once per scalar type: explicit template instantiations in the .cpp files.
#define SG_FOR_EACH_SCALAR(M) M(::sg::Fx32) M(::sg::Fx16) M(float) M(double)

/// Calls f.template operator()<S>() with the C++ type of a runtime scalar kind.
template <class F>
decltype(auto) dispatchScalar(ScalarKind kind, F&& f) {
  switch (kind) {
    case ScalarKind::Fx16:
      return f.template operator()<Fx16>();
    case ScalarKind::Float:
      return f.template operator()<float>();
    case ScalarKind::Double:
      return f.template operator()<double>();
    case ScalarKind::Fx32:
      break;
  }
  return f.template operator()<Fx32>();
}

}  // namespace sg
