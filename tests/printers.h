// How GoogleTest prints the core's value types in test names' parameters and in failures:
// readable values instead of the default byte dumps ("64-byte object <F8-70 ...>").
#pragma once

#include <ostream>

#include "sim/math/fixed.h"
#include "sim/math/rational.h"
#include "sim/math/scalar.h"

namespace sg {

/// "1.5 (raw 6442450944)": the value and its exact bits.
template <class R, class W, int F>
void PrintTo(const Fixed<R, W, F>& v, std::ostream* os) {
  *os << v.toDouble() << " (raw " << int64_t(v.raw()) << ")";
}

inline void PrintTo(ScalarKind kind, std::ostream* os) { *os << scalarName(kind); }

inline void PrintTo(const Rational& r, std::ostream* os) { *os << r.toString(); }

}  // namespace sg
