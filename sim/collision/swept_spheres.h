// Whether a sphere's straight path over a tick comes near another sphere or a box: the test that
// tells a speculative contact that can close this tick from a "ghost". A speculative contact is
// made between the closest features at the tick's start and stops the pair closing along that
// normal faster than its gap allows; a fast ball passing beside a wall's edge closes that gap
// along the edge's normal while its path stays clear of the wall, and was stopped short of a
// surface it never meets (a 1 cm ball passing 0.29 m beside a wall at 500 m/s came out at
// 17 m/s; an independent pass, 2026-11-28). Box2D v3 keeps its speculative margin at 4 slops and
// sweeps fast bodies instead; here the rows stay, and a row whose sphere's path cannot reach the
// other shape within the margin is dropped. The same for a sphere against the ground's faces,
// edges and vertices: a ball skimming 10 cm over a heightmap ridge at 100 m/s was deflected by the
// plane of the ridge's face, which its path never meets. Linear motion only: what the segment
// does not model (rotation, gravity over the tick) is the caller's margin.
#pragma once

#include <algorithm>

#include "sim/collision/contact.h"
#include "sim/math/scalar.h"  // length3, abs for float and double (found at the template's definition)

namespace sg {

/// The distance (m) between the point p + t d (t in [0, 1]) nearest to `q` and q. Along the unit
/// direction, not d . d: two fx16 bodies closing at 16,000 m/s move 266 m a tick, and 266^2
/// leaves Q16.16's range (every product here is a length times a unit, or a clamped length).
template <class S>
S segmentPointDistance(const Vec3<S>& p, const Vec3<S>& d, const Vec3<S>& q) {
  const Vec3<S> r = p - q;
  const S length = length3(d.x(), d.y(), d.z());
  Vec3<S> nearest = r;
  if (length > S(0)) {
    const Vec3<S> unit = d / length;
    S along = -dot3(r, unit);  // how far along the path the nearest point lies (m)
    along = along < S(0) ? S(0) : (along > length ? length : along);
    nearest = r + unit * along;
  }
  return length3(nearest.x(), nearest.y(), nearest.z());
}

/// The distance (m) from a point (box-local) to the box of half extents h (0 inside).
template <class S>
S pointBoxDistance(const Vec3<S>& local, const Vec3<S>& h) {
  Vec3<S> out;
  for (int k = 0; k < 3; ++k)
    out[k] = local[k] > h[k] ? S(local[k] - h[k]) : (local[k] < -h[k] ? S(-h[k] - local[k]) : S(0));
  return length3(out.x(), out.y(), out.z());
}

/// A body's straight path over the tick, for these tests: how far it moves against the other
/// shape, and the margin that covers what the segment leaves out.
template <class S>
struct PairSweep {
  Vec3<S> displacement;  ///< A's motion against B's (or the terrain) over the tick, v_A dt - v_B dt (m)
  S margin;              ///< the speculative distance, and what the straight path leaves out (m): turning, gravity
};

/// The least of distanceAt(p + t d) over t in [0, 1], for a distance to a convex set (convex in
/// t): a ternary search of a fixed 24 steps (the same steps on every machine) narrows t to
/// (2/3)^24 = 6e-5 of the path, a few tenths of a millimetre at 500 m/s.
template <class S, class DistanceAt>
S leastDistanceAlong(const Vec3<S>& p, const Vec3<S>& d, const DistanceAt& distanceAt) {
  S lo(0), hi(1);
  for (int step = 0; step < 24; ++step) {
    const S third = (hi - lo) / S(3);
    const S m1 = lo + third, m2 = hi - third;
    if (distanceAt(Vec3<S>(p + d * m1)) > distanceAt(Vec3<S>(p + d * m2)))
      lo = m1;
    else
      hi = m2;
  }
  const S ends = std::min(distanceAt(p), distanceAt(Vec3<S>(p + d)));
  return std::min(ends, distanceAt(Vec3<S>(p + d * ((lo + hi) / S(2)))));
}

/// The least distance (m) between the segment p + t d (box-local, t in [0, 1]) and the box of half
/// extents h.
template <class S>
S segmentBoxDistance(const Vec3<S>& p, const Vec3<S>& d, const Vec3<S>& h) {
  return leastDistanceAlong(p, d, [&](const Vec3<S>& q) { return pointBoxDistance<S>(q, h); });
}

/// The distance (m) from q to the triangle a b c whose unit normal is n, for the ground's
/// triangles (their projections on the x-z plane are not degenerate): the distance to its plane
/// when q's foot on the plane lies inside the triangle, else to the nearest of its edges.
template <class S>
S pointTriangleDistance(const Vec3<S>& q, const Vec3<S>& a, const Vec3<S>& b, const Vec3<S>& c, const Vec3<S>& n) {
  const S plane = dot3(Vec3<S>(q - a), n);
  const Vec3<S> foot = q - n * plane;
  // Which side of each edge the foot lies on, seen from above (x-z): inside when all agree (or
  // are zero). The foot, not q: under a steep face q's own x-z can lie inside while its nearest
  // point on the plane is beyond the face.
  const auto side = [&](const Vec3<S>& from, const Vec3<S>& to) {
    return S((to.x() - from.x()) * (foot.z() - from.z()) - (to.z() - from.z()) * (foot.x() - from.x()));
  };
  const S ab = side(a, b), bc = side(b, c), ca = side(c, a);
  const bool inside = (ab >= S(0) && bc >= S(0) && ca >= S(0)) || (ab <= S(0) && bc <= S(0) && ca <= S(0));
  if (inside) return abs(plane);
  return std::min({segmentPointDistance(a, Vec3<S>(b - a), q), segmentPointDistance(b, Vec3<S>(c - b), q),
                   segmentPointDistance(c, Vec3<S>(a - c), q)});
}

}  // namespace sg
