// Box-box narrow phase: see box_box.h for the rules. Layout follows Box2D's manifold.c:
// separating-axis test, choice of the axis, then the contact points for a face or an edge pair.
//
// Frames: the test runs in A's frame (B's rotation relative to A is R = Ra^T Rb, so R(i, j) =
// a_i . b_j, and t = Ra^T (pb - pa) is B's centre seen from A). Face contacts run in the
// reference box's frame, where the reference face is axis aligned and clipping against its side
// planes is a comparison of one coordinate. Every length is in metres.
//
// Arithmetic: +, -, *, / and sqrt (through length3) only. The divisors are |a_i x b_j| >=
// sin_min > 0 and, in the clipping, dp - dq with dp and dq of opposite signs: never zero.
#include "sim/collision/box_box.h"

#include <array>
#include <cmath>
#include <utility>

#include "sim/math/scalar.h"

namespace sg {
namespace {

// ---- constants -------------------------------------------------------------------------

/// 2^-n, exact in every scalar (n <= 16 for fx16).
template <class S>
S pow2neg(int n) {
  if constexpr (ScalarTraits<S>::isFixed) {
    return S::fromRaw(typename S::RawType(1) << (S::kFracBits - n));
  } else {
    return S(1.0 / double(uint64_t(1) << n));
  }
}

template <class S>
struct Tolerances {
  S roundoff;    ///< bound on the rounding error of an entry of Ra^T Rb: 16 units in the last place
  S edgeMinSin;  ///< |a_i x b_j| below this: near-parallel edges, the axis never makes contacts
  S faceRel;     ///< a face of B must beat the best face of A by this fraction ...
  S edgeRel;     ///< ... and an edge axis the best face by this one (both plus the margin)
};

template <class S>
Tolerances<S> tolerances() {
  Tolerances<S> t;
  switch (ScalarTraits<S>::kind) {
    case ScalarKind::Fx32:
      t.roundoff = pow2neg<S>(28);
      break;  // ulp 2^-32
    case ScalarKind::Fx16:
      t.roundoff = pow2neg<S>(12);
      break;  // ulp 2^-16
    case ScalarKind::Float:
      t.roundoff = pow2neg<S>(19);
      break;  // ulp(1) 2^-23
    case ScalarKind::Double:
      t.roundoff = pow2neg<S>(48);
      break;  // ulp(1) 2^-52
  }
  // The edge contact point errs by about ulp / sin^2 (the closest-point formula divides a
  // rounded dot product by |L|^2): fx16 needs a larger floor to keep that below ~5 mm.
  t.edgeMinSin = ScalarTraits<S>::kind == ScalarKind::Fx16 ? pow2neg<S>(4) : pow2neg<S>(10);
  t.faceRel = pow2neg<S>(6);  // 1.6 %, cf. Box2D 2.x k_relativeTol = 0.98
  t.edgeRel = pow2neg<S>(4);  // 6.25 %, cf. ODE's fudge factor 1.05 on edge axes
  return t;
}

/// x is smaller than y by more than the tolerance: x + |x| rel + absTol < y (m). |x|: a
/// speculative (negative) overlap must be clearly smaller too, not clearly larger.
template <class S>
bool clearlyLess(S x, S y, S rel, S absTol) {
  return x + abs(x) * rel + absTol < y;
}

template <class S>
S halfOf(S v) {
  if constexpr (ScalarTraits<S>::isFixed) {
    return v * S::fromRaw(S::kOneRaw >> 1);  // rounds to nearest, ties away from zero
  } else {
    return v * S(0.5);  // exact
  }
}

// ---- separating-axis test ----------------------------------------------------------------

/// B seen from A.
template <class S>
struct Relative {
  Mat3<S> R;     ///< R(i, j) = a_i . b_j
  Mat3<S> absR;  ///< |R(i, j)|
  Vec3<S> t;     ///< centre of B minus centre of A, in A's frame (m)
};

template <class S>
Relative<S> relative(const Pose<S>& pa, const Pose<S>& pb) {
  using std::abs;
  Relative<S> rel;
  rel.R = pa.rotation.transpose() * pb.rotation;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) rel.absR(i, j) = abs(rel.R(i, j));
  rel.t = pa.toLocal(pb.position);
  return rel;
}

/// A candidate axis. index: 0..2 face of A, 3..5 face of B, 6 + 3 i + j edge pair a_i x b_j.
template <class S>
struct Axis {
  int index = -1;  ///< -1: none
  S pen{};         ///< overlap of the two boxes along the unit axis (m)
};

/// The edge-pair axis L = a_i x b_j in A's frame, not normalised (|L| = sin of the angle).
template <class S>
struct EdgeAxis {
  Vec3<S> L;
  S len;       ///< |L|
  S dist;      ///< t . L: centre distance along L, times |L| (m)
  S overlapU;  ///< rA + rB - |dist|: overlap along L, times |L| (m)
};

/// Ericson, Real-Time Collision Detection 4.4.1: with L = e_i x b_j in A's frame,
/// L = (0, -R(2,j), R(1,j)) for i = 0 (cyclic for the others), so every projection is a sum of
/// two products of R entries. rB uses b_j1 . L = R(i, j2) and b_j2 . L = -R(i, j1) (det R = +1).
template <class S>
EdgeAxis<S> edgeAxis(const Relative<S>& rel, const Vec3<S>& ha, const Vec3<S>& hb, int i, int j) {
  using std::abs;
  const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
  EdgeAxis<S> e;
  e.L = Vec3<S>::Zero();
  e.L[i1] = -rel.R(i2, j);
  e.L[i2] = rel.R(i1, j);
  e.len = length3(e.L.x(), e.L.y(), e.L.z());
  e.dist = rel.t[i2] * rel.R(i1, j) - rel.t[i1] * rel.R(i2, j);
  const S rA = ha[i1] * rel.absR(i2, j) + ha[i2] * rel.absR(i1, j);
  const S rB = hb[j1] * rel.absR(i, j2) + hb[j2] * rel.absR(i, j1);
  e.overlapU = rA + rB - abs(e.dist);
  return e;
}

template <class S>
struct SatResult {
  bool separated = false;
  Axis<S> faceA, faceB, edge;  ///< best of each group (edge: only non-parallel pairs)
};

template <class S>
SatResult<S> separatingAxisTest(const Relative<S>& rel, const Vec3<S>& ha, const Vec3<S>& hb, S margin, S edgeMinSin,
                                S speculative) {
  using std::abs;
  SatResult<S> r;
  // Faces of A: axis a_i. B's projection radius is sum_j hb_j |a_i . b_j|.
  for (int i = 0; i < 3; ++i) {
    const S rB = hb[0] * rel.absR(i, 0) + hb[1] * rel.absR(i, 1) + hb[2] * rel.absR(i, 2);
    const S pen = ha[i] + rB - abs(rel.t[i]);
    if (pen < -speculative) return {true, {}, {}, {}};
    if (r.faceA.index < 0 || pen < r.faceA.pen) r.faceA = {i, pen};
  }
  // Faces of B: axis b_j.
  for (int j = 0; j < 3; ++j) {
    const S rA = ha[0] * rel.absR(0, j) + ha[1] * rel.absR(1, j) + ha[2] * rel.absR(2, j);
    const S dist = rel.t[0] * rel.R(0, j) + rel.t[1] * rel.R(1, j) + rel.t[2] * rel.R(2, j);
    const S pen = hb[j] + rA - abs(dist);
    if (pen < -speculative) return {true, {}, {}, {}};
    if (r.faceB.index < 0 || pen < r.faceB.pen) r.faceB = {3 + j, pen};
  }
  // Edge pairs. The unnormalised test |dist| > rA + rB is exact for L = 0 in exact arithmetic
  // but not under rounding, so it gets the margin (Ericson pads |R| by an epsilon for the same
  // reason): for boxes that pass the face tests |t_i| <= sum of half extents, so rounding of R
  // moves dist and rA + rB by less than roundoff * (sum of half extents).
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const EdgeAxis<S> e = edgeAxis(rel, ha, hb, i, j);
      if (e.overlapU + margin + speculative * e.len < S(0)) return {true, {}, {}, {}};
      if (e.len < edgeMinSin) continue;  // (near) parallel edges: no contact axis
      // len >= edgeMinSin > 0. A gap counts only as a speculative contact; without one, rounding
      // below zero is a touch.
      const S pen = (e.overlapU < S(0) && speculative == S(0) ? S(0) : e.overlapU) / e.len;
      if (r.edge.index < 0 || pen < r.edge.pen) r.edge = {6 + 3 * i + j, pen};
    }
  return r;
}

// ---- face contact: clip the incident face against the reference face's side planes --------

/// A vertex of the clipped incident face, in the reference box's frame.
template <class S>
struct ClipVertex {
  Vec3<S> p;
  uint8_t id = 0;       ///< clip id (box_box.h): corner 0..3 or 4 + 4 * edge + plane
  uint8_t outEdge = 0;  ///< polygon edge leaving this vertex: 0..3 incident edge, 4 + plane
};

/// A convex polygon. Clipping a quad by four planes gives at most 8 vertices; the room for 16
/// covers rounding that makes a polygon very slightly non-convex (extra vertices are dropped).
template <class S>
struct ClipPolygon {
  std::array<ClipVertex<S>, 16> v;
  int n = 0;
  void push(const ClipVertex<S>& x) {
    if (n < int(v.size())) v[size_t(n++)] = x;
  }
};

/// Sutherland-Hodgman against one side plane: keeps coordinate `axis` * (negative ? -1 : 1)
/// <= h. Points exactly on the plane are kept and never duplicated.
template <class S>
ClipPolygon<S> clipAgainstPlane(const ClipPolygon<S>& in, int axis, bool negative, S h, uint8_t plane) {
  ClipPolygon<S> out;
  const S boundary = negative ? -h : h;
  auto outside = [&](const Vec3<S>& p) { return (negative ? -p[axis] : p[axis]) - h; };  // m, > 0 cut
  for (int k = 0; k < in.n; ++k) {
    const ClipVertex<S>& p = in.v[size_t(k)];
    const ClipVertex<S>& q = in.v[size_t((k + 1) % in.n)];
    const S dp = outside(p.p), dq = outside(q.p);
    if (dp <= S(0)) {
      ClipVertex<S> kept = p;
      if (dp == S(0) && dq > S(0)) kept.outEdge = uint8_t(4 + plane);  // leaves along the plane
      out.push(kept);
    }
    const bool exits = dp < S(0) && dq > S(0), enters = dp > S(0) && dq < S(0);
    if (exits || enters) {
      // dp and dq have opposite signs, so dp - dq != 0 and f = dp / (dp - dq) is in (0, 1).
      const S f = dp / (dp - dq);
      ClipVertex<S> x;
      x.p = p.p + (q.p - p.p) * f;
      x.p[axis] = boundary;  // exactly on the plane, whatever the rounding of f
      x.id = uint8_t(4 + 4 * p.outEdge + plane);
      x.outEdge = exits ? uint8_t(4 + plane) : p.outEdge;
      out.push(x);
    }
  }
  return out;
}

/// Face contacts with the reference face (axis k, outward sign) of box `ref` and the incident
/// box `inc`; the incident face is the one most anti-parallel to the reference normal. Vertices
/// up to `slack` above the face (rounding) still count, with penetration 0: boxes that touch
/// within rounding get contacts whatever the rounding of each corner. Vertices further above,
/// up to `speculative`, are speculative contacts (penetration = minus the gap).
template <class S>
int faceContacts(int32_t refBody, const Vec3<S>& hr, const Pose<S>& pr, int32_t incBody, const Vec3<S>& hi,
                 const Pose<S>& pi, int k, bool negative, bool refIsA, S slack, S speculative,
                 std::vector<Contact<S>>& out) {
  const Relative<S> rel = relative(pr, pi);  // incident box in the reference frame
  // Incident face: axis m with the largest |R(k, m)| (lowest index on ties), on the side facing
  // the reference face.
  int m = 0;
  for (int c = 1; c < 3; ++c)
    if (rel.absR(k, c) > rel.absR(k, m)) m = c;
  const bool incNegative = (rel.R(k, m) > S(0)) != negative;  // its normal . ref normal < 0
  const int m1 = (m + 1) % 3, m2 = (m + 2) % 3;
  const Vec3<S> centre = rel.t + rel.R.col(m) * (incNegative ? -hi[m] : hi[m]);
  const Vec3<S> u = rel.R.col(m1) * hi[m1], v = rel.R.col(m2) * hi[m2];
  ClipPolygon<S> poly;
  const Vec3<S> corners[4] = {centre + u + v, centre - u + v, centre - u - v, centre + u - v};
  for (uint8_t c = 0; c < 4; ++c) poly.push({corners[c], c, c});

  // Side planes of the reference face: +u, -u, +v, -v with u = axis k+1, v = axis k+2.
  const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
  poly = clipAgainstPlane(poly, k1, false, hr[k1], 0);
  poly = clipAgainstPlane(poly, k1, true, hr[k1], 1);
  poly = clipAgainstPlane(poly, k2, false, hr[k2], 2);
  poly = clipAgainstPlane(poly, k2, true, hr[k2], 3);

  // Keep the vertices below the reference face. The contact point is halfway between the vertex
  // and its projection on the face, so it does not depend on which box is the reference.
  const S faceCoord = negative ? -hr[k] : hr[k];
  const Vec3<S> refNormal = negative ? Vec3<S>(-pr.rotation.col(k)) : Vec3<S>(pr.rotation.col(k));
  const uint32_t refFeature = uint32_t(2 * k + (negative ? 1 : 0));
  const uint32_t incFace = uint32_t(2 * m + (incNegative ? 1 : 0));
  int added = 0;
  for (int c = 0; c < poly.n && added < 8; ++c) {
    const Vec3<S>& p = poly.v[size_t(c)].p;
    const S depth = negative ? p[k] + hr[k] : hr[k] - p[k];  // m below the face
    if (depth < -(slack + speculative)) continue;
    Vec3<S> mid = p;
    // Speculative (further above the face than rounding): the incident vertex itself, on the
    // incident box, so its arm stays the size of the box however wide the gap.
    if (depth >= -slack) mid[k] = depth < S(0) ? faceCoord : halfOf(p[k] + faceCoord);
    Contact<S> ct;
    ct.bodyA = refIsA ? refBody : incBody;
    ct.bodyB = refIsA ? incBody : refBody;
    const uint32_t incFeature = kBoxIncidentFaceStride * incFace + poly.v[size_t(c)].id;
    ct.featureA = refIsA ? refFeature : incFeature;
    ct.featureB = refIsA ? incFeature : refFeature;
    ct.point = pr.toWorld(mid);
    ct.normal = refIsA ? Vec3<S>(-refNormal) : refNormal;  // the reference normal points at the incident box
    ct.penetration = depth < -slack || depth >= S(0) ? depth : S(0);
    out.push_back(ct);
    ++added;
  }
  return added;
}

// ---- edge contact -----------------------------------------------------------------------

template <class S>
struct EdgeContact {
  Contact<S> contact;
  bool onBothEdges;  ///< the closest points of the two lines lie on the edges (within slack)
};

/// The contact for the edge pair (a_i, b_j): midpoint of the closest points of the two edges
/// that support the boxes along the axis. `pen` is the axis overlap from the test.
template <class S>
EdgeContact<S> edgeContact(int32_t a, const Vec3<S>& ha, const Pose<S>& pa, int32_t b, const Vec3<S>& hb,
                           const Relative<S>& rel, int i, int j, S pen, S slack) {
  const EdgeAxis<S> e = edgeAxis(rel, ha, hb, i, j);
  const Vec3<S> toB = e.dist < S(0) ? Vec3<S>(-e.L) : e.L;  // from A towards B (not unit)
  // A's edge furthest along toB and B's edge furthest against it, as midpoint + direction.
  const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
  Vec3<S> pA = Vec3<S>::Zero();
  pA[i1] = toB[i1] < S(0) ? -ha[i1] : ha[i1];
  pA[i2] = toB[i2] < S(0) ? -ha[i2] : ha[i2];
  Vec3<S> qB = Vec3<S>::Zero();  // in B's frame
  qB[j1] = toB.dot(rel.R.col(j1)) > S(0) ? -hb[j1] : hb[j1];
  qB[j2] = toB.dot(rel.R.col(j2)) > S(0) ? -hb[j2] : hb[j2];
  const Vec3<S> pB = rel.t + rel.R * qB;
  const Vec3<S> dirA = Vec3<S>::Unit(i), dirB = rel.R.col(j);

  // Closest points pA + s dirA, pB + u dirB of the two lines: their difference is parallel to
  // L, so s |L|^2 = ((pB - pA) x dirB) . L and u |L|^2 = ((pB - pA) x dirA) . L. Divided by |L|
  // twice (|L| >= sin_min) rather than by a rounded |L|^2. The numerators are small products,
  // each rounded, so s and u err by about ulp / |L|^2; clamping keeps the points on the edges.
  const Vec3<S> w = pB - pA;
  S s = w.cross(dirB).dot(e.L) / e.len / e.len;
  S u = w.cross(dirA).dot(e.L) / e.len / e.len;
  const bool onBoth = s >= -ha[i] - slack && s <= ha[i] + slack && u >= -hb[j] - slack && u <= hb[j] + slack;
  s = s < -ha[i] ? -ha[i] : (s > ha[i] ? ha[i] : s);
  u = u < -hb[j] ? -hb[j] : (u > hb[j] ? hb[j] : u);
  const Vec3<S> mid = pA + dirA * s + pB + dirB * u;

  Contact<S> c;
  c.bodyA = a;
  c.bodyB = b;
  c.featureA = kBoxEdgeFeature + uint32_t(4 * i + (pA[i1] > S(0) ? 1 : 0) + (pA[i2] > S(0) ? 2 : 0));
  c.featureB = kBoxEdgeFeature + uint32_t(4 * j + (qB[j1] > S(0) ? 1 : 0) + (qB[j2] > S(0) ? 2 : 0));
  c.point = pa.toWorld(Vec3<S>(halfOf(mid.x()), halfOf(mid.y()), halfOf(mid.z())));
  const Vec3<S> nLocal(-toB.x() / e.len, -toB.y() / e.len, -toB.z() / e.len);  // B -> A, unit
  c.normal = pa.rotation * nLocal;
  c.penetration = pen;
  return {c, onBoth};
}

}  // namespace

template <class S>
int collideBoxBox(int32_t a, const Vec3<S>& ha, const Pose<S>& pa, int32_t b, const Vec3<S>& hb, const Pose<S>& pb,
                  std::vector<Contact<S>>& out, S speculative) {
  const Tolerances<S> tol = tolerances<S>();
  const Relative<S> rel = relative(pa, pb);
  // Rounding bound (m) for an overlap built from R: rounding units of R times the lever arms,
  // plus 1 m worth for the absolute rounding of fixed-point products at any size.
  const S margin = tol.roundoff * (ha.sum() + hb.sum() + S(1));
  const SatResult<S> sat = separatingAxisTest(rel, ha, hb, margin, tol.edgeMinSin, speculative);
  if (sat.separated) return 0;

  // Contacts from one candidate axis; 0 when that axis yields none.
  auto contactsFrom = [&](const Axis<S>& axis) -> int {
    if (axis.index < 0) return 0;
    if (axis.index >= 6) {
      // Only when the two edges really cross: closest points off the segments mean the axis won
      // by rounding or sits at a corner, where a face axis gives the right contacts.
      const int i = (axis.index - 6) / 3, j = (axis.index - 6) % 3;
      const EdgeContact<S> edge = edgeContact(a, ha, pa, b, hb, rel, i, j, axis.pen, margin);
      if (!edge.onBothEdges) return 0;
      out.push_back(edge.contact);
      return 1;
    }
    if (axis.index < 3) {
      // A's face towards B: sign of B's centre along a_i (t_i = 0, coincident centres: +).
      const int k = axis.index;
      return faceContacts(a, ha, pa, b, hb, pb, k, rel.t[k] < S(0), true, margin, speculative, out);
    }
    // B's face towards A: A's centre along b_j is -(t . b_j).
    const int k = axis.index - 3;
    return faceContacts(b, hb, pb, a, ha, pa, k, rel.t.dot(rel.R.col(k)) > S(0), false, margin, speculative, out);
  };

  // First choice: least overlap, but B's faces and then the edges must be clearly better
  // (box_box.h); the absolute part of "clearly" is the rounding margin.
  const Axis<S> face = clearlyLess(sat.faceB.pen, sat.faceA.pen, tol.faceRel, margin) ? sat.faceB : sat.faceA;
  const bool edgeFirst = sat.edge.index >= 0 && clearlyLess(sat.edge.pen, face.pen, tol.edgeRel, margin);
  const Axis<S> first = edgeFirst ? sat.edge : face;
  if (const int n = contactsFrom(first)) return n;

  // The first choice can yield nothing: an edge pair whose closest points are off the edges, or
  // a face kept by the tie rule whose incident face is all outside its side planes or above it
  // (another axis overlaps by almost nothing). Then the other two candidates, least overlap
  // first (the lower index on ties).
  Axis<S> rest[2];
  int count = 0;
  for (const Axis<S>& c : {sat.faceA, sat.faceB, sat.edge})
    if (c.index >= 0 && c.index != first.index) rest[count++] = c;
  if (count == 2 && rest[1].pen < rest[0].pen) std::swap(rest[0], rest[1]);
  for (int k = 0; k < count; ++k)
    if (const int n = contactsFrom(rest[k])) return n;
  return 0;
}

#define SG_INSTANTIATE(S)                                                                                      \
  template int collideBoxBox(int32_t, const Vec3<S>&, const Pose<S>&, int32_t, const Vec3<S>&, const Pose<S>&, \
                             std::vector<Contact<S>>&, S);
SG_INSTANTIATE(Fx32)
SG_INSTANTIATE(Fx16)
SG_INSTANTIATE(float)
SG_INSTANTIATE(double)
#undef SG_INSTANTIATE

}  // namespace sg
