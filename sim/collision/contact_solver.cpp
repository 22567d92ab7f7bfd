#include "sim/collision/contact_solver.h"

#include <algorithm>

#include "sim/bodies/gyroscopic.h"
#include "sim/bodies/integrate_bodies.h"
#include "sim/math/scalar_ops.h"

namespace sg {
namespace {

/// A unit vector orthogonal to n, chosen by a fixed rule (no trigonometry).
template <class S>
Vec3<S> tangentOf(const Vec3<S>& n) {
  const Vec3<S> axis = abs(n.x()) < S(1) / S(2) ? Vec3<S>::UnitX() : Vec3<S>::UnitY();
  const Vec3<S> t = n.cross(axis);
  return t / length3(t.x(), t.y(), t.z());
}

/// m/s: a contact whose bodies slide past each other faster than this at prepare takes its
/// first friction axis along that sliding (Bullet does the same). The cone (solveContacts) is
/// round whatever the axes, but the sweep is not: t1 takes its impulse before t2 sees it, and
/// the projection scales that pair, so with fixed axes 45 deg to the slide a box slid 1.5 % too
/// far and drifted 1.6 cm sideways in a metre. Slower contacts (resting ones) keep the fixed
/// axes, so warm-started static friction does not turn with rounding noise. 1 cm/s: 655 units
/// of fx16, a clean direction. A slide must also outrun a tick of its kinetic friction
/// (turnSlidingPairs) before its axes turn.
template <class S>
S slidingAxisSpeed() {
  return S(1) / S(100);
}

/// The first friction axis of a contact: along the tangential part of A's velocity against B's
/// (or the ground's) when that slides (*sliding = true, *slideSpeed its speed), else tangentOf(n). The centres'
/// velocities, not the contact points': every contact of a pair then turns its axes on the same
/// tick and the same way (per point, corners crossing the speed on different ticks mixed axes
/// and set a sliding box spinning). Only while the bodies' turning moves their surfaces less
/// than half as fast as the centres slide (|w| times the bounding radius): a spinning box's
/// corners slip across its drift, and with t1 along the drift first they got the whole cone the
/// wrong way (a 10 rad/s box drifting at 2 cm/s lost its spin 0.65 times as fast as it should).
template <class S>
Vec3<S> frictionDirection(const Vec3<S>& n, const RigidBody<S>& A, const RigidBody<S>* B, bool* sliding,
                          S* slideSpeed) {
  Vec3<S> v = A.velocity;
  if (B) v -= B->velocity;
  const Vec3<S> tangential = v - n * n.dot(v);
  *sliding = false;
  const S speed = slidingAxisSpeed<S>();
  if (abs(tangential.x()) < speed && abs(tangential.y()) < speed && abs(tangential.z()) < speed) return tangentOf(n);
  const S length = length3(tangential.x(), tangential.y(), tangential.z());
  if (!(length > speed)) return tangentOf(n);
  S turning = length3(A.angularVelocity.x(), A.angularVelocity.y(), A.angularVelocity.z()) * A.boundingRadius;
  if (B) turning += length3(B->angularVelocity.x(), B->angularVelocity.y(), B->angularVelocity.z()) * B->boundingRadius;
  if (!(turning + turning < length)) return tangentOf(n);
  *sliding = true;
  *slideSpeed = length;
  return tangential / length;
}

/// A friction impulse given along axes (a1, a2) expressed along (b1, b2), both pairs orthonormal
/// in the same tangent plane (warm starting between fixed and sliding axes).
template <class S>
void turnFriction(const Vec3<S>& a1, const Vec3<S>& a2, S along1, S along2, const Vec3<S>& b1, const Vec3<S>& b2,
                  S* out1, S* out2) {
  const Vec3<S> friction = a1 * along1 + a2 * along2;
  *out1 = friction.dot(b1);
  *out2 = friction.dot(b2);
}

/// sqrt of a non-negative v (0 for a rounding-negative one).
template <class S>
S sqrtS(S v) {
  using std::sqrt;
  return v > S(0) ? S(sqrt(v)) : S(0);
}

/// fx16 only: an upper bound, in raw Q16.16 units, of |r x dir|^T I^-1 |r x dir| as makeAxis forms
/// it (every product and partial sum in magnitude, so no step of the real computation exceeds it).
template <class S>
uint64_t angularTermBound(const Mat3<S>& invInertiaWorld, const Vec3<S>& arm) {
  constexpr uint64_t kOne = uint64_t(1) << 16;
  uint64_t a[3], turn[3];
  for (int k = 0; k < 3; ++k) a[k] = uint64_t(arm[k].raw() < 0 ? -int64_t(arm[k].raw()) : int64_t(arm[k].raw()));
  for (int k = 0; k < 3; ++k) {
    uint64_t sum = 0;  // three products below 2^62 each: below 2^64
    for (int l = 0; l < 3; ++l) {
      const int64_t m = invInertiaWorld(k, l).raw();
      sum += uint64_t(m < 0 ? -m : m) * a[l];
    }
    turn[k] = sum / kOne + 1;
    if (turn[k] >= (uint64_t(1) << 31)) return UINT64_MAX;  // the turn itself would not fit
  }
  uint64_t dot = 0;
  for (int k = 0; k < 3; ++k) dot += a[k] * turn[k];
  return dot / kOne + 1;
}

/// The axis `dir` of a contact at arms rA (and rB unless B is the terrain).
template <class S>
ContactAxis<S> makeAxis(const Vec3<S>& dir, const RigidBody<S>& A, Vec3<S> rA, const RigidBody<S>* B, Vec3<S> rB) {
  if constexpr (ScalarTraits<S>::kind == ScalarKind::Fx16) {
    // A speculative row's point may lie far out in the gap a fast pair will close this tick (a box
    // pair's midpoint; a sphere's surface seen from a box), and a light, thin body's angular
    // terms |r x n|^2 / I at that arm overflow Q16.16 (a 1.8 g plate at 700 m/s, a property
    // test). The load check (fx16_envelope.h) keeps them in range at arms within the bodies;
    // beyond that, the arm is halved towards the body's centre until the terms fit: the row
    // then acts at a point nearer the body, where the surfaces will meet. Every arm that fits
    // is used as it is (the same bits as before).
    constexpr uint64_t kLimit = (uint64_t(1) << 31) - 4;
    for (int halvings = 0; halvings < 40; ++halvings) {
      const uint64_t termA = angularTermBound(A.invInertiaWorld, Vec3<S>(rA.cross(dir)));
      const uint64_t termB = B ? angularTermBound(B->invInertiaWorld, Vec3<S>(rB.cross(dir))) : 0;
      const uint64_t masses = uint64_t(A.invMass.raw()) + (B ? uint64_t(B->invMass.raw()) : 0);
      if (termA < kLimit && termB < kLimit && masses + termA + termB < kLimit) break;
      if (termA >= termB) {
        rA = Vec3<S>(S::fromRaw(rA.x().raw() / 2), S::fromRaw(rA.y().raw() / 2), S::fromRaw(rA.z().raw() / 2));
      } else {
        rB = Vec3<S>(S::fromRaw(rB.x().raw() / 2), S::fromRaw(rB.y().raw() / 2), S::fromRaw(rB.z().raw() / 2));
      }
    }
  }
  ContactAxis<S> x;
  x.dir = dir;
  x.armA = rA.cross(dir);
  x.turnA = A.invInertiaWorld * x.armA;
  S k = A.invMass + x.armA.dot(x.turnA);
  if (B) {
    x.armB = rB.cross(dir);
    x.turnB = B->invInertiaWorld * x.armB;
    k += B->invMass + x.armB.dot(x.turnB);
  }
  x.invMass = k;
  x.mass = k > S(0) ? S(1) / k : S(0);
  return x;
}

/// Relative velocity of A against B along the axis (m/s).
// Inlined (with applyAxisImpulse and dot3): called three times per row in every sweep, 16 sweeps
// a tick by default; as calls they were a quarter of 1,000 rolling balls' instructions.
template <class S>
[[gnu::always_inline]] inline S axisVelocity(const std::vector<RigidBody<S>>& bodies, const ContactRow<S>& row,
                                             const ContactAxis<S>& x) {
  const RigidBody<S>& A = bodies[size_t(row.a)];
  S v = dot3(A.velocity, x.dir) + dot3(A.angularVelocity, x.armA);
  if (row.b != kTerrainBody) {
    const RigidBody<S>& B = bodies[size_t(row.b)];
    v -= dot3(B.velocity, x.dir) + dot3(B.angularVelocity, x.armB);
  }
  return v;
}

/// The largest angular speed component a solve may hold in fx16 (rad/s): a quarter of Q16.16's
/// range, so that w x r stays in range for arms up to 4 m.
inline constexpr int32_t kFx16SpinLimitRaw = 8191 << 16;

/// w += turn x p. In fx16 each component is held within +-8191 rad/s: within a solve a light,
/// small body's rows can turn it far faster than the quarter turn per sub-step the integration
/// caps it to (a 1 kg, 2 cm cube clipping a wall's edge at 500 m/s turned at 75,000 rad/s between
/// two rows, beyond Q16.16), and the cap then takes it down to 377 rad/s at 60 Hz x 4 anyway.
/// A sum within the limit is exactly w + turn x p rounded as Fixed rounds it (the same bits).
template <class S>
[[gnu::always_inline]] inline void turnBy(Vec3<S>& w, const Vec3<S>& turn, S p) {
  if constexpr (ScalarTraits<S>::kind == ScalarKind::Fx16) {
    for (int k = 0; k < 3; ++k) {
      const int64_t product = int64_t(turn[k].raw()) * int64_t(p.raw());              // below 2^62
      const int64_t change = (product + (int64_t(1) << 15) + (product >> 63)) >> 16;  // Fixed's rounding
      const int64_t sum = std::clamp<int64_t>(int64_t(w[k].raw()) + change, -kFx16SpinLimitRaw, kFx16SpinLimitRaw);
      w[k] = S::fromRaw(int32_t(sum));
    }
  } else {
    addScaled(w, turn, p);
  }
}

/// Applies an impulse p (N s) along the axis: +p to A, -p to B.
template <class S>
[[gnu::always_inline]] inline void applyAxisImpulse(std::vector<RigidBody<S>>& bodies, const ContactRow<S>& row,
                                                    const ContactAxis<S>& x, S p) {
  // No impulse, no change: in fixed point adding the zero products leaves every bit as it was
  // (a speculative row that does not close, warm-started at zero, is most of a pile's rows). Not
  // for float and double, where -0 + 0 is +0: their bits stay those of the sum.
  if constexpr (ScalarTraits<S>::isFixed)
    if (p == S(0)) return;
  RigidBody<S>& A = bodies[size_t(row.a)];
  addScaled(A.velocity, x.dir, S(p * row.invMassA));
  turnBy(A.angularVelocity, x.turnA, p);
  if (row.b == kTerrainBody) return;
  RigidBody<S>& B = bodies[size_t(row.b)];
  subtractScaled(B.velocity, x.dir, S(p * row.invMassB));
  turnBy(B.angularVelocity, x.turnB, S(-p));
}

}  // namespace

template <class S>
void sortContacts(std::vector<Contact<S>>& contacts) {
  std::stable_sort(contacts.begin(), contacts.end(), [](const Contact<S>& x, const Contact<S>& y) {
    if (x.bodyA != y.bodyA) return x.bodyA < y.bodyA;
    if (x.bodyB != y.bodyB) return x.bodyB < y.bodyB;
    if (x.featureA != y.featureA) return x.featureA < y.featureA;
    return x.featureB < y.featureB;
  });
}

template <class S>
bool keyLess(const CachedImpulse<S>& x, const Contact<S>& y) {
  if (x.bodyA != y.bodyA) return x.bodyA < y.bodyA;
  if (x.bodyB != y.bodyB) return x.bodyB < y.bodyB;
  if (x.featureA != y.featureA) return x.featureA < y.featureA;
  return x.featureB < y.featureB;
}
template <class S>
bool sameKey(const CachedImpulse<S>& x, const Contact<S>& y) {
  return x.bodyA == y.bodyA && x.bodyB == y.bodyB && x.featureA == y.featureA && x.featureB == y.featureB;
}

template <class S>
Softness<S> makeSoftness(S hertz, S zeta, S h, S pi) {
  if (!(hertz > S(0))) return Softness<S>{S(0), S(1), S(0)};
  const S omega = S(2) * pi * hertz;
  const S a1 = S(2) * zeta + h * omega;
  const S a2 = h * omega * a1;
  const S a3 = S(1) / (S(1) + a2);
  return Softness<S>{omega / a1, a2 * a3, a3};
}

namespace {

/// Last tick's impulses for each row: the same key first, then the nearest point of the same
/// body pair within 1 cm; every cached entry serves at most one contact. Rows [begin, end) hold
/// whole body pairs (an entry can serve only a row of its own pair), so ranges match apart.
template <class S>
void matchCachedImpulses(const std::vector<Contact<S>>& contacts, const std::vector<CachedImpulse<S>>& cache,
                         std::vector<ContactRow<S>>& rows, size_t begin, size_t end) {
  std::vector<uint8_t> used(cache.size(), 0);
  std::vector<size_t> match(end - begin, cache.size());  // row i's entry: match[i - begin]
  for (size_t i = begin; i < end; ++i) {
    auto hit = std::lower_bound(cache.begin(), cache.end(), contacts[i],
                                [](const CachedImpulse<S>& x, const Contact<S>& y) { return keyLess(x, y); });
    if (hit != cache.end() && sameKey(*hit, contacts[i])) {
      match[i - begin] = size_t(hit - cache.begin());
      used[match[i - begin]] = 1;
    }
  }
  const S tolerance = S(1) / S(100);  // 1 cm
  for (size_t i = begin; i < end; ++i) {
    size_t& m = match[i - begin];
    if (m != cache.size()) continue;
    const Contact<S>& c = contacts[i];
    auto first = std::lower_bound(cache.begin(), cache.end(), c, [](const CachedImpulse<S>& x, const Contact<S>& y) {
      return x.bodyA != y.bodyA ? x.bodyA < y.bodyA : x.bodyB < y.bodyB;
    });
    S best = tolerance * tolerance;
    for (auto it = first; it != cache.end() && it->bodyA == c.bodyA && it->bodyB == c.bodyB; ++it) {
      const size_t k = size_t(it - cache.begin());
      if (used[k]) continue;
      const Vec3<S> d = it->point - c.point;
      if (abs(d.x()) >= tolerance || abs(d.y()) >= tolerance || abs(d.z()) >= tolerance) continue;
      const S d2 = d.squaredNorm();
      if (d2 < best) {
        best = d2;
        m = k;
      }
    }
    if (m != cache.size()) used[m] = 1;
  }
  for (size_t i = begin; i < end; ++i) {
    if (match[i - begin] == cache.size()) continue;
    const CachedImpulse<S>& hit = cache[match[i - begin]];
    rows[i].normal.impulse = hit.normal;
    rows[i].t1.impulse = hit.tangent1;
    rows[i].t2.impulse = hit.tangent2;
  }
}

/// Turns the rows of each body pair whose centres slide past each other onto sliding axes (t1
/// along the slide, frictionDirection), but only where the slide outruns what a tick of the
/// pair's kinetic friction can take off it: mu x the pair's warm-started normal impulses x
/// (1/mA + 1/mB) x substeps (m/s). Slower, the axis fixed for the tick overshoots: friction along
/// a slide direction with a small sideways part took more than that sideways speed off in one
/// tick and reversed it, x(1 - mu g cos dt / v) per tick. A box 0.25 deg past its friction angle on
/// a 27 deg slope switched at 1 cm/s, its sideways speed grew 4-fold a tick, and friction along
/// the swinging axis let it gain 4 cm/s in four ticks (a slide 27 % too long; 44 % at 45 deg).
template <class S>
void turnSlidingPairs(const std::vector<uint8_t>& slides, const std::vector<S>& slideSpeed,
                      const std::vector<Vec3<S>>& slideDir, const std::vector<RigidBody<S>>& bodies,
                      const std::vector<Contact<S>>& contacts, int substeps, std::vector<ContactRow<S>>& rows,
                      size_t begin, size_t end) {
  // slides, slideSpeed and slideDir hold rows [begin, end): row i at i - begin.
  for (size_t first = begin; first < end;) {
    size_t last = first;
    S capacity(0);  // m/s per sub-step, then per tick
    for (; last < end && rows[last].a == rows[first].a && rows[last].b == rows[first].b; ++last)
      capacity += rows[last].friction * rows[last].normal.impulse * (rows[last].invMassA + rows[last].invMassB);
    capacity *= S(substeps);
    for (size_t i = first; i < last; ++i) {
      ContactRow<S>& row = rows[i];
      if (!slides[i - begin] || !(slideSpeed[i - begin] > capacity)) continue;
      const RigidBody<S>& A = bodies[size_t(row.a)];
      const RigidBody<S>* B = row.b == kTerrainBody ? nullptr : &bodies[size_t(row.b)];
      const Vec3<S> rA = contacts[i].point - A.position;
      const Vec3<S> rB = B ? Vec3<S>(contacts[i].point - B->position) : Vec3<S>(Vec3<S>::Zero());
      const Vec3<S>& n = row.normal.dir;
      const S fixed1 = row.t1.impulse, fixed2 = row.t2.impulse;
      const Vec3<S> fixedDir1 = row.t1.dir, fixedDir2 = row.t2.dir;
      const Vec3<S>& along = slideDir[i - begin];
      row.t1 = makeAxis(along, A, rA, B, rB);
      row.t2 = makeAxis(Vec3<S>(n.cross(along)), A, rA, B, rB);
      // The cache holds the fixed axes' impulses: turn them onto the sliding axes.
      turnFriction(fixedDir1, fixedDir2, fixed1, fixed2, row.t1.dir, row.t2.dir, &row.t1.impulse, &row.t2.impulse);
      row.slidingAxes = true;
    }
    first = last;
  }
}

/// A's anchor minus B's anchor in the world now. The terrain does not move: its anchor is a
/// constant that cancels against ContactRow::anchorGap, so it is left out.
template <class S>
[[gnu::always_inline]] inline Vec3<S> anchorDifference(const std::vector<RigidBody<S>>& bodies,
                                                       const ContactRow<S>& row) {
  const RigidBody<S>& A = bodies[size_t(row.a)];
  Vec3<S> d = A.position + times3(A.rotation, row.localA);
  if (row.b == kTerrainBody) return d;
  const RigidBody<S>& B = bodies[size_t(row.b)];
  return d - (B.position + times3(B.rotation, row.localB));
}

}  // namespace

template <class S>
void prepareContacts(const std::vector<RigidBody<S>>& bodies, const std::vector<Contact<S>>& contacts,
                     const std::vector<CachedImpulse<S>>& cache, int substeps, std::vector<ContactRow<S>>& rows,
                     size_t begin, size_t end) {
  using std::sqrt;
  const size_t n = end - begin;
  std::vector<uint8_t> slides(n, 0);
  std::vector<S> slideSpeed(n, S(0));
  std::vector<Vec3<S>> slideDir(n, Vec3<S>::Zero());
  for (size_t i = begin; i < end; ++i) {
    const Contact<S>& c = contacts[i];
    ContactRow<S>& row = rows[i];
    row = ContactRow<S>{};
    row.a = c.bodyA;
    row.b = c.bodyB;
    const RigidBody<S>& A = bodies[size_t(c.bodyA)];
    const RigidBody<S>* B = c.bodyB == kTerrainBody ? nullptr : &bodies[size_t(c.bodyB)];
    const Vec3<S> rA = c.point - A.position;
    const Vec3<S> rB = B ? Vec3<S>(c.point - B->position) : Vec3<S>(Vec3<S>::Zero());
    row.localA = A.rotation.transpose() * rA;
    if (B) row.localB = B->rotation.transpose() * rB;
    bool sliding = false;
    slideDir[i - begin] = frictionDirection(c.normal, A, B, &sliding, &slideSpeed[i - begin]);
    slides[i - begin] = sliding ? 1 : 0;
    const Vec3<S> t1 = tangentOf(c.normal);  // fixed axes; turnSlidingPairs turns sliding pairs
    row.normal = makeAxis(c.normal, A, rA, B, rB);
    row.t1 = makeAxis(t1, A, rA, B, rB);
    row.t2 = makeAxis(Vec3<S>(c.normal.cross(t1)), A, rA, B, rB);
    row.separation = -c.penetration;
    row.invMassA = A.invMass;
    row.restitution = A.restitution;
    row.friction = A.friction;
    if (B) {
      row.invMassB = B->invMass;
      row.restitution = A.restitution < B->restitution ? B->restitution : A.restitution;
      row.friction = sqrt(A.friction * B->friction);
    }
    row.anchorGap = anchorDifference(bodies, row);  // the separation's reference: s is exact at prepare
  }
  matchCachedImpulses(contacts, cache, rows, begin, end);
  turnSlidingPairs(slides, slideSpeed, slideDir, bodies, contacts, substeps, rows, begin, end);
}

template <class S>
size_t nextPairStart(const std::vector<Contact<S>>& contacts, size_t i) {
  while (i > 0 && i < contacts.size() && contacts[i].bodyA == contacts[i - 1].bodyA &&
         contacts[i].bodyB == contacts[i - 1].bodyB)
    ++i;
  return std::min(i, contacts.size());
}

namespace {

/// Applies the island's rows' accumulated impulses (the start of each sub-step).
template <class S>
void warmStartContacts(std::vector<RigidBody<S>>& bodies, const std::vector<ContactRow<S>>& rows,
                       std::span<const int32_t> order) {
  for (const int32_t i : order) {
    const ContactRow<S>& row = rows[size_t(i)];
    for (const ContactAxis<S>* x : {&row.normal, &row.t1, &row.t2}) applyAxisImpulse(bodies, row, *x, x->impulse);
  }
}

/// Sets the island's rows' separationNow from their bodies' present poses: once before the solve
/// sweeps and once before the relax sweeps of a sub-step, the only places the poses have moved
/// (the sweeps change velocities only), instead of once per row in every sweep.
template <class S>
void updateSeparations(const std::vector<RigidBody<S>>& bodies, std::vector<ContactRow<S>>& rows,
                       std::span<const int32_t> order) {
  // The anchors moved with their bodies since prepare.
  for (const int32_t i : order) {
    ContactRow<S>& row = rows[size_t(i)];
    row.separationNow = row.separation + dot3(Vec3<S>(anchorDifference(bodies, row) - row.anchorGap), row.normal.dir);
  }
}

/// The normal row of one contact (soft when `useBias`); false when the row sits this sweep out (a
/// speculative row in the relax).
// Inlined into the sweep (as they were when the sweep ran over all rows at once): called per row
// from solveIsland's loops, GCC kept them as calls, +5 % instructions on 1,000 rolling balls.
template <class S>
[[gnu::always_inline]] inline bool solveNormal(std::vector<RigidBody<S>>& bodies, ContactRow<S>& row,
                                               const SolverSettings<S>& settings, bool useBias) {
  ContactAxis<S>& n = row.normal;
  const S s = row.separationNow;
  S bias(0), massScale(1), impulseScale(0);
  if (s > S(0)) {
    // Speculative: close at most the gap in this sub-step. Only in the solve, which the
    // position integration follows; in the relax it would act on the *next* sub-step's motion
    // (a ball 2 cm above the ground at the tick's end bounced there, a centimetre early, and
    // lost m g x that gap of energy per bounce).
    if (!useBias) return false;
    bias = s * settings.invSubstep;
  } else if (useBias) {
    const Softness<S>& soft = row.b == kTerrainBody ? settings.staticSoftness : settings.bodySoftness;
    bias = maxS(soft.biasRate * s, -settings.maxPushVelocity);
    massScale = soft.massScale;
    impulseScale = soft.impulseScale;
  }
  // Normal: push apart until the bodies stop closing (faster than the bias allows); never pull.
  const S vn = axisVelocity(bodies, row, n);
  // A speculative contact that will not close in this sub-step lets go of all its impulse. Said
  // in velocities (the impulse's own velocity change against the margin), because the product
  // mass x (vn + s / h) of a heavy fast body overflows fx16 long before any impulse does.
  const bool released = s > S(0) && vn + bias > S(0) && !(n.impulse * n.invMass > vn + bias);
  const S lambda = released ? S(0) : S(-n.mass * massScale * (vn + bias) - impulseScale * n.impulse);
  const S total = released ? S(0) : maxS(n.impulse + lambda, S(0));
  applyAxisImpulse(bodies, row, n, S(total - n.impulse));
  n.impulse = total;
  // The fastest approach any push met. Not just the first: a ball that left the ground at V
  // comes back down through the same discrete positions (the integrator is time-reversible)
  // and lands exactly on the surface, where rounding makes a push of ~1e-16 one sub-step
  // before the real one; taking that approach (V - g h) lost g h of speed per bounce.
  if (total > S(0) && vn < row.impactVelocity) {
    row.impactVelocity = vn;
    row.impactGap = maxS(s, S(0));
  }
  row.maxImpulseN = maxS(row.maxImpulseN, total);
  return true;
}

/// The friction rows of one contact, within the cone of its normal impulse so far.
template <class S>
[[gnu::always_inline]] inline void solveFriction(std::vector<RigidBody<S>>& bodies, ContactRow<S>& row) {
  const ContactAxis<S>& n = row.normal;
  // A row without a normal impulse and without friction impulses ends this sweep without them:
  // both branches below clamp to a cone of radius 0, so every total is 0 and nothing is applied.
  // Fixed point skips the work (the speculative rows of a pile that do not close); float and
  // double do it, as their clamped zeros may be -0.
  if constexpr (ScalarTraits<S>::isFixed)
    if (n.impulse == S(0) && row.t1.impulse == S(0) && row.t2.impulse == S(0)) return;
  // Friction: stop the sliding velocity, the tangent impulse kept inside the Coulomb cone
  // |t| <= mu x normal impulse. Per-axis clamps (a pyramid) gave up to sqrt(2) mu N along the
  // diagonals and not opposite the velocity: a box on a slope 27 deg off its tangent axes slid
  // along one axis only, and a box 45 deg off held at 1.3 times its friction angle.
  const S limit = row.friction * n.impulse;
  const S velocity1 = axisVelocity(bodies, row, row.t1);
  const S wanted1 = row.t1.impulse - velocity1 * row.t1.mass;
  if (row.slidingAxes) {
    // Sliding: t1 is along the slide and comes first, up to the whole cone; t2 (across) gets
    // what is left. Scaling the pair instead let the corners of a sliding box keep sideways
    // impulses that cancel between them (nothing in the sweep removes those) at 6 % of the
    // cone: the box slid with 94 % of its kinetic friction, 4 times too far near the
    // friction angle.
    const S total1 = std::clamp(wanted1, S(-limit), limit);
    applyAxisImpulse(bodies, row, row.t1, S(total1 - row.t1.impulse));
    row.t1.impulse = total1;
    const S wanted2 = row.t2.impulse - axisVelocity(bodies, row, row.t2) * row.t2.mass;
    const S used = abs(total1);
    // sqrt(limit^2 - t1^2) as a product of roots: (limit - |t1|)(limit + |t1|) of an 8 t block's
    // impulses overflows fx16.
    const S left = sqrtS(S(limit - used)) * sqrtS(S(limit + used));
    const S total2 = std::clamp(wanted2, S(-left), left);
    applyAxisImpulse(bodies, row, row.t2, S(total2 - row.t2.impulse));
    row.t2.impulse = total2;
    return;
  }
  // At rest (fixed axes): both axes' targets from the same velocity (a sequential t1 then t2
  // turns the pair's direction towards t1, which near the friction angle let a box slip 6 %
  // further on the diagonal), the pair scaled onto the cone (Jolt clamps the pair the same way).
  const S velocity2 = axisVelocity(bodies, row, row.t2);
  const S wanted2 = row.t2.impulse - velocity2 * row.t2.mass;
  S total1 = wanted1, total2 = wanted2;
  const S length = length3(wanted1, wanted2, S(0));
  if (length > limit) {
    // Slipping: the cone's whole impulse, opposite the slip. The targets above stop each axis
    // with its own mass, so their pair points along (m1 v1, m2 v2), not along the slip (v1, v2):
    // a slip diagonal to the axes at a corner whose arms give the two axes different masses kept
    // a friction at an angle to it, a few per cent short of mu N along it. A box a quarter degree
    // inside its friction angle, with the slope and its edges 45 degrees off the world axes, slid
    // on at 5.7 cm/s (too slow to turn the axes along the slide: a tick of its kinetic friction);
    // square to the axes it held (an independent pass, 2026-11-28). One mass for both axes, the
    // smaller (it overshoots neither), points the step along the slip: the friction then turns
    // towards opposing it, as Coulomb's law has it, over the sweeps.
    const S common = std::min(row.t1.mass, row.t2.mass);
    const S slip1 = row.t1.impulse - velocity1 * common;
    const S slip2 = row.t2.impulse - velocity2 * common;
    total1 = slip1, total2 = slip2;
    const S slipLength = length3(slip1, slip2, S(0));
    if (slipLength > limit) {
      const S scale = limit / slipLength;  // slipLength > limit >= 0: scale < 1
      total1 = slip1 * scale;
      total2 = slip2 * scale;
    }
  }
  applyAxisImpulse(bodies, row, row.t1, S(total1 - row.t1.impulse));
  row.t1.impulse = total1;
  applyAxisImpulse(bodies, row, row.t2, S(total2 - row.t2.impulse));
  row.t2.impulse = total2;
}

/// One sweep over the island's rows (after updateSeparations): the normal (soft when `useBias`;
/// speculative rows always limit the approach to their current gap per sub-step), then Coulomb
/// friction on two tangents within mu x normal impulse.
template <class S>
void solveContacts(std::vector<RigidBody<S>>& bodies, std::vector<ContactRow<S>>& rows, std::span<const int32_t> order,
                   const SolverSettings<S>& settings, bool useBias) {
  for (const int32_t i : order) {
    ContactRow<S>& row = rows[size_t(i)];
    if (solveNormal(bodies, row, settings, useBias)) solveFriction(bodies, row);
  }
}

}  // namespace

template <class S>
void solveIsland(std::vector<RigidBody<S>>& bodies, std::vector<ContactRow<S>>& rows,
                 std::span<const int32_t> islandBodies, std::span<const int32_t> islandRows,
                 const SolverSettings<S>& settings, const IslandStep<S>& step) {
  // A body alone settles against the terrain in a few sweeps; touching bodies pass a correction on
  // one contact per sweep, and a heavy or wide body on a lighter one needs more (physics-notes.md,
  // "A wide load on a narrower, lighter support"). Chosen per island from what it holds, never from
  // the thread that solves it, so the bits stay the sequence's.
  const int solveSweeps = islandBodies.size() > 1 ? settings.islandSolveIterations : settings.solveIterations;
  for (int sub = 0; sub < settings.substeps; ++sub) {
    for (const int32_t b : islandBodies) {
      RigidBody<S>& body = bodies[size_t(b)];
      applyGravity(body, step.gravityH);
      clampAngularSpeed(body, step.maxAngularSpeed);
      applyGyroscopicTerm(body, step.h);
    }
    warmStartContacts(bodies, rows, islandRows);
    updateSeparations(bodies, rows, islandRows);
    for (int it = 0; it < solveSweeps; ++it) solveContacts(bodies, rows, islandRows, settings, true);
    for (const int32_t b : islandBodies) integrateBodyPosition(bodies[size_t(b)], step.h);
    updateSeparations(bodies, rows, islandRows);
    for (int it = 0; it < settings.relaxIterations; ++it) solveContacts(bodies, rows, islandRows, settings, false);
  }
  // The sub-steps turned the awake bodies' rotations only; their world inverse inertia is read at
  // the next prepare (contact Jacobians), so it is computed once here, not in every sub-step.
  for (const int32_t b : islandBodies)
    if (!bodies[size_t(b)].asleep) bodies[size_t(b)].updateInvInertiaWorld();
}

template <class S>
void applyRestitution(std::vector<RigidBody<S>>& bodies, std::vector<ContactRow<S>>& rows,
                      const SolverSettings<S>& settings) {
  // Against the fastest approach a pushing solve met (before its impulse), and only where the
  // contact pushed (a contact that merely grazed bounces nothing).
  // Which bodies something holds up this tick: a body with a pushing row whose partner is not the
  // one it bounces on (the ground, or another body) does not fall with gravity over the gap below.
  // Rows are in canonical order, so a pair's rows are consecutive.
  std::vector<int32_t> pushingRows(bodies.size(), 0);
  for (const ContactRow<S>& row : rows) {
    if (!(row.maxImpulseN > S(0))) continue;
    ++pushingRows[size_t(row.a)];
    if (row.b != kTerrainBody) ++pushingRows[size_t(row.b)];
  }
  int32_t pairPushing = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    ContactRow<S>& row = rows[i];
    if (i == 0 || rows[i - 1].a != row.a || rows[i - 1].b != row.b) {
      pairPushing = 0;
      for (size_t k = i; k < rows.size() && rows[k].a == row.a && rows[k].b == row.b; ++k)
        if (rows[k].maxImpulseN > S(0)) ++pairPushing;
    }
    if (!(row.maxImpulseN > S(0)) || !(row.impactVelocity < -settings.restitutionThreshold)) continue;
    if (row.restitution == S(0)) continue;
    ContactAxis<S>& n = row.normal;
    // A speculative push stopped the body `impactGap` short of where it would have met the
    // surface (it then rests on it for the rest of the tick): gravity would have sped the pair's
    // approach up over that gap, so the impact speed gets the gain of v^2 = V^2 + 2 g_n gap
    // (first order: V + g_n gap / V; gap <= V h keeps the neglected term below (g h / V)^2 / 2 of
    // V, 0.08 % at the 1 m/s threshold and 60 Hz x 4). Without it an elastic ball lost m g_n gap,
    // half a sub-step of fall on average, every bounce (a third of its height in a minute). g_n is
    // the pair's relative pull: gravity on each body that falls freely, none on the terrain or on
    // a body another contact holds up. Two free bodies fall alike (no gain); a ball on a slab
    // resting on the ground gets the whole pull (without it, 31 % of its height in a minute).
    S impactSpeed = -row.impactVelocity;
    if (row.impactGap > S(0)) {
      const bool heldA = pushingRows[size_t(row.a)] > pairPushing;
      const bool heldB = row.b == kTerrainBody || pushingRows[size_t(row.b)] > pairPushing;
      if (heldA != heldB) {
        // The relative acceleration of A against B along n: +g.n when only A falls, -g.n when only B.
        const S pull = heldB ? S(-settings.gravity.dot(n.dir)) : settings.gravity.dot(n.dir);  // m/s^2, closing
        if (pull > S(0)) impactSpeed += pull * row.impactGap / impactSpeed;
      }
    }
    const S vn = axisVelocity(bodies, row, n);
    const S lambda = -(vn - row.restitution * impactSpeed) * n.mass;
    const S total = maxS(n.impulse + lambda, S(0));
    applyAxisImpulse(bodies, row, n, S(total - n.impulse));
    n.impulse = total;
  }
}

template <class S>
void storeImpulses(std::vector<RigidBody<S>>& bodies, const std::vector<Contact<S>>& contacts,
                   const std::vector<ContactRow<S>>& rows, const SolverSettings<S>& settings,
                   std::vector<CachedImpulse<S>>& cache) {
  // Sliding: a body with a partner (a body, or the ground) whose contacts' friction, added up as a
  // vector, reached the sum of their Coulomb limits (every contact with that partner at its
  // limit, all pulling the same way). Such a body is not held: a box a quarter degree past its
  // friction angle accelerates at 4 cm/s^2, slow enough for the speed test, yet it must slide on.
  // Per partner: a box sliding on the ground under a box it holds counted the upper box's unused
  // friction limit too and fell asleep on the slope. As a vector, because the corners of a resting
  // box may carry friction that cancels between them (the solver has no reason to remove it, and
  // fx16 rounding grows it to the corners' limits) while the body is held with a margin. Within
  // 1/256 of the sum counts as at it: fx16 rounds a saturated box's sum to 0.9984..1.0016 of it,
  // and a box held a quarter degree inside its friction angle (needing 97 %) to at most 0.987.
  // In velocity units (impulse / mass of A): the sums of a heavy body's many deep contacts in
  // N s overflowed fx16. Rows are in canonical order, so a partner's rows are consecutive.
  // Overlapping deeper than the slop plus the give under its load: still being pushed out, however
  // small its velocity.
  std::vector<uint8_t> sliding(bodies.size(), 0), deep(bodies.size(), 0);
  // Rolling: a body that one contact point holds, and whose point carries friction, is turned by
  // that friction about its centre, whatever the friction limit (a ball on a 0.5 degree slope
  // needs 2/7 tan 0.5 deg of its normal impulse and rolls at 5/7 g sin 0.5 deg: 3 cm/s after the
  // half second the speed test waits, so it fell asleep; an independent pass, 2026-11-28). A
  // point that holds a body without turning it carries no friction (a ball on level ground: its
  // friction is exactly 0, gravity having no tangential part). More than 1/4096 of the normal
  // impulse counts: slopes above 0.05 degrees. Whether the tick sped the body up does not decide it:
  // a ball rolling slowly up a slope slows to its turning point there, and would be frozen on the
  // slope. The price: a ball rocking in a shallow dip (there is no rolling resistance, so it does
  // rock for ever) stays awake (docs/physics-notes.md).
  std::vector<int32_t> pushingPoints(bodies.size(), 0);
  std::vector<uint8_t> pointTurns(bodies.size(), 0);
  for (const ContactRow<S>& row : rows) {
    if (!(row.normal.impulse > S(0))) continue;
    const bool turns = length3(row.t1.impulse, row.t2.impulse, S(0)) > row.normal.impulse / S(4096);
    for (const int32_t body : {row.a, row.b}) {
      if (body == kTerrainBody) continue;
      ++pushingPoints[size_t(body)];
      pointTurns[size_t(body)] = turns;
    }
  }
  for (size_t i = 0; i < bodies.size(); ++i)
    if (pushingPoints[i] == 1 && pointTurns[i]) sliding[i] = 1;
  for (size_t first = 0; first < rows.size();) {
    size_t last = first;
    Vec3<S> friction = Vec3<S>::Zero();
    S limit(0);
    for (; last < rows.size() && rows[last].a == rows[first].a && rows[last].b == rows[first].b; ++last) {
      const ContactRow<S>& row = rows[last];
      // The give of a soft contact under its own load (P / (m h omega^2)) is where it rests, not
      // a push-out: a column of 40 cubes overlaps its bottom joint by 5.5 mm at 60 Hz and never
      // slept, then walked over (docs/physics-notes.md, "Tall columns"). In velocity units first
      // (P / m), as above: P alone of a heavy body overflows fx16.
      const S giveTime = row.b == kTerrainBody ? settings.staticGiveTime : settings.bodyGiveTime;
      const S give = row.normal.impulse * row.normal.invMass * giveTime;
      if (row.separation < -(settings.linearSlop + give)) {
        deep[size_t(row.a)] = 1;
        if (row.b != kTerrainBody) deep[size_t(row.b)] = 1;
      }
      friction += (row.t1.dir * row.t1.impulse + row.t2.dir * row.t2.impulse) * row.invMassA;
      limit += row.friction * row.normal.impulse * row.invMassA;
    }
    if (limit > S(0) && !(length3(friction.x(), friction.y(), friction.z()) < limit - limit / S(256))) {
      sliding[size_t(rows[first].a)] = 1;
      if (rows[first].b != kTerrainBody) sliding[size_t(rows[first].b)] = 1;
    }
    first = last;
  }
  for (size_t i = 0; i < bodies.size(); ++i) bodies[i].heldThisTick = !sliding[i] && !deep[i];
  cache.clear();
  for (size_t i = 0; i < rows.size(); ++i) {
    const ContactRow<S>& row = rows[i];
    S tangent1 = row.t1.impulse, tangent2 = row.t2.impulse;
    if (row.slidingAxes) {  // back onto the fixed axes, which the next tick's rows start from
      const Vec3<S> fixed1 = tangentOf(row.normal.dir);
      turnFriction(row.t1.dir, row.t2.dir, row.t1.impulse, row.t2.impulse, fixed1,
                   Vec3<S>(row.normal.dir.cross(fixed1)), &tangent1, &tangent2);
    }
    cache.push_back(CachedImpulse<S>{contacts[i].bodyA, contacts[i].bodyB, contacts[i].featureA, contacts[i].featureB,
                                     row.normal.impulse, tangent1, tangent2, contacts[i].point});
  }
}

#define SG_INSTANTIATE(S)                                                                                            \
  template Softness<S> makeSoftness(S, S, S, S);                                                                     \
  template void sortContacts(std::vector<Contact<S>>&);                                                              \
  template void prepareContacts(const std::vector<RigidBody<S>>&, const std::vector<Contact<S>>&,                    \
                                const std::vector<CachedImpulse<S>>&, int, std::vector<ContactRow<S>>&, size_t,      \
                                size_t);                                                                             \
  template size_t nextPairStart(const std::vector<Contact<S>>&, size_t);                                             \
  template void solveIsland(std::vector<RigidBody<S>>&, std::vector<ContactRow<S>>&, std::span<const int32_t>,       \
                            std::span<const int32_t>, const SolverSettings<S>&, const IslandStep<S>&);               \
  template void applyRestitution(std::vector<RigidBody<S>>&, std::vector<ContactRow<S>>&, const SolverSettings<S>&); \
  template void storeImpulses(std::vector<RigidBody<S>>&, const std::vector<Contact<S>>&,                            \
                              const std::vector<ContactRow<S>>&, const SolverSettings<S>&,                           \
                              std::vector<CachedImpulse<S>>&);
SG_FOR_EACH_SCALAR(SG_INSTANTIATE)
#undef SG_INSTANTIATE
}  // namespace sg
