// Football-field markings as a pure function of lattice coordinates (thesis §5, "Football
// field"): a patch shows the white marking tuft when its un-jittered lattice position lies on a
// line. Because it depends only on (i, j) and the scenario, the markings survive any regeneration
// (the thesis lost them when the field moved).
#pragma once

#include "sim/math/scalar_ops.h"

namespace sg {

template <class S>
struct FieldMarkings {
  bool enabled = false;
  S centerX{}, centerZ{};
  S halfLength{}, halfWidth{}, halfLine{}, circleRadius{};

  /// Is world point (x, z) on a line: boundary, halfway line or centre circle?
  bool onLine(S x, S z) const {
    if (!enabled) return false;
    const S dx = abs(x - centerX), dz = abs(z - centerZ);
    const bool insideOuter = dx <= halfLength + halfLine && dz <= halfWidth + halfLine;
    if (!insideOuter) return false;
    if (abs(dx - halfLength) <= halfLine || abs(dz - halfWidth) <= halfLine) return true;  // boundary
    if (dx <= halfLine) return true;                                                       // halfway line
    // Centre circle: compare squared distances (no square root): (r - w)^2 <= d^2 <= (r + w)^2.
    if (dx > circleRadius + halfLine || dz > circleRadius + halfLine) return false;
    const S d2 = dx * dx + dz * dz;
    const S inner = maxS(circleRadius - halfLine, S(0)), outer = circleRadius + halfLine;
    return d2 >= inner * inner && d2 <= outer * outer;
  }
};

}  // namespace sg
