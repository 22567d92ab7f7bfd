#include "sim/collision/contact_solver.h"

#include <algorithm>

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

template <class S>
S inverseMassAlong(const RigidBody<S>& body, const Vec3<S>& r, const Vec3<S>& dir) {
  const Vec3<S> rxd = r.cross(dir);
  return body.invMass + (body.invInertiaWorld * rxd).cross(r).dot(dir);
}

template <class S>
Vec3<S> velocityAt(const RigidBody<S>& body, const Vec3<S>& r) {
  return body.velocity + body.angularVelocity.cross(r);
}

template <class S>
void applyImpulse(RigidBody<S>& body, const Vec3<S>& r, const Vec3<S>& impulse) {
  body.velocity += impulse * body.invMass;
  body.angularVelocity += body.invInertiaWorld * r.cross(impulse);
}

template <class S>
Vec3<S> relativeVelocity(const std::vector<RigidBody<S>>& bodies, const ContactRow<S>& row) {
  Vec3<S> v = velocityAt(bodies[size_t(row.a)], row.rA);
  if (row.b != kTerrainBody) v -= velocityAt(bodies[size_t(row.b)], row.rB);
  return v;
}

template <class S>
void applyPair(std::vector<RigidBody<S>>& bodies, const ContactRow<S>& row, const Vec3<S>& impulse) {
  applyImpulse(bodies[size_t(row.a)], row.rA, impulse);
  if (row.b != kTerrainBody) applyImpulse(bodies[size_t(row.b)], row.rB, Vec3<S>(-impulse));
}

/// 1 / k, or 0 when k is not positive (an immovable direction).
template <class S>
S invertPositive(S k) {
  return k > S(0) ? S(1) / k : S(0);
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
void prepareContactRows(const std::vector<RigidBody<S>>& bodies, const std::vector<Contact<S>>& contacts,
                        std::vector<ContactRow<S>>& rows) {
  using std::sqrt;
  rows.assign(contacts.size(), ContactRow<S>{});
  for (size_t i = 0; i < contacts.size(); ++i) {
    const Contact<S>& c = contacts[i];
    ContactRow<S>& row = rows[i];
    row.a = c.bodyA;
    row.b = c.bodyB;
    const RigidBody<S>& A = bodies[size_t(c.bodyA)];
    row.rA = c.point - A.position;
    row.normal = c.normal;
    row.t1 = tangentOf(c.normal);
    row.t2 = c.normal.cross(row.t1);
    S kN = inverseMassAlong(A, row.rA, row.normal);
    S kT1 = inverseMassAlong(A, row.rA, row.t1);
    S kT2 = inverseMassAlong(A, row.rA, row.t2);
    row.restitution = A.restitution;
    row.friction = A.friction;
    if (c.bodyB != kTerrainBody) {
      const RigidBody<S>& B = bodies[size_t(c.bodyB)];
      row.rB = c.point - B.position;
      kN += inverseMassAlong(B, row.rB, row.normal);
      kT1 += inverseMassAlong(B, row.rB, row.t1);
      kT2 += inverseMassAlong(B, row.rB, row.t2);
      row.restitution = A.restitution < B.restitution ? B.restitution : A.restitution;
      row.friction = sqrt(A.friction * B.friction);
    }
    row.massN = invertPositive(kN);
    row.massT1 = invertPositive(kT1);
    row.massT2 = invertPositive(kT2);
    row.approachVelocity = relativeVelocity(bodies, row).dot(row.normal);
  }
}

template <class S>
void solveContactVelocities(std::vector<RigidBody<S>>& bodies, const std::vector<Contact<S>>& contacts,
                            std::vector<ContactRow<S>>& rows, const SolverSettings<S>& settings,
                            std::vector<CachedImpulse<S>>& cache) {
  // Warm start, in two passes so every cached entry serves at most one contact: first the
  // contacts whose key (bodies and features) is unchanged, then the others by nearest point.
  std::vector<uint8_t> used(cache.size(), 0);
  std::vector<size_t> match(rows.size(), cache.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    auto hit = std::lower_bound(cache.begin(), cache.end(), contacts[i],
                                [](const CachedImpulse<S>& x, const Contact<S>& y) { return keyLess(x, y); });
    if (hit != cache.end() && sameKey(*hit, contacts[i])) {
      match[i] = size_t(hit - cache.begin());
      used[match[i]] = 1;
    }
  }
  const S tolerance = S(1) / S(100);  // 1 cm
  for (size_t i = 0; i < rows.size(); ++i) {
    if (match[i] != cache.size()) continue;
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
        match[i] = k;
      }
    }
    if (match[i] != cache.size()) used[match[i]] = 1;
  }
  for (size_t i = 0; i < rows.size(); ++i) {
    if (match[i] == cache.size()) continue;
    ContactRow<S>& row = rows[i];
    const CachedImpulse<S>& hit = cache[match[i]];
    row.impulseN = hit.normal;
    row.impulseT1 = hit.tangent1;
    row.impulseT2 = hit.tangent2;
    applyPair(bodies, row, Vec3<S>(row.normal * row.impulseN + row.t1 * row.impulseT1 + row.t2 * row.impulseT2));
  }
  for (int it = 0; it < settings.velocityIterations; ++it) {
    for (ContactRow<S>& row : rows) {
      // Normal: push apart until the bodies stop closing; never pull.
      const S vn = relativeVelocity(bodies, row).dot(row.normal);
      S lambda = -vn * row.massN;
      const S total = maxS(row.impulseN + lambda, S(0));
      lambda = total - row.impulseN;
      row.impulseN = total;
      applyPair(bodies, row, Vec3<S>(row.normal * lambda));
      // Friction: stop the sliding velocity, within the Coulomb cone mu * normal impulse.
      const S limit = row.friction * row.impulseN;
      for (int t = 0; t < 2; ++t) {
        const Vec3<S>& dir = t == 0 ? row.t1 : row.t2;
        S& accumulated = t == 0 ? row.impulseT1 : row.impulseT2;
        const S vt = relativeVelocity(bodies, row).dot(dir);
        const S wanted = accumulated - vt * (t == 0 ? row.massT1 : row.massT2);
        const S clamped = wanted < -limit ? -limit : (wanted > limit ? limit : wanted);
        const S delta = clamped - accumulated;
        accumulated = clamped;
        applyPair(bodies, row, Vec3<S>(dir * delta));
      }
    }
  }
  // Restitution: against the approach velocity measured before gravity and the solve, and only
  // where the contact pushed (a contact that merely grazed bounces nothing).
  for (ContactRow<S>& row : rows) {
    if (!(row.approachVelocity < -settings.restitutionThreshold) || !(row.impulseN > S(0))) continue;
    const S vn = relativeVelocity(bodies, row).dot(row.normal);
    S lambda = -(vn + row.restitution * row.approachVelocity) * row.massN;
    const S total = maxS(row.impulseN + lambda, S(0));
    lambda = total - row.impulseN;
    row.impulseN = total;
    applyPair(bodies, row, Vec3<S>(row.normal * lambda));
  }
  // Sliding: a body whose contacts' friction, summed, reached the summed Coulomb limits (a
  // tangent impulse at +-mu x normal impulse is saturated). Such a body is not held by its
  // contacts: a box a quarter degree past its friction angle accelerates at 4 cm/s^2, slow enough
  // for the speed test, yet it must slide on. Summed per body, not per contact: one corner of a
  // resting box may saturate while the others hold it (fx16 rounding did that).
  std::vector<S> friction(bodies.size(), S(0)), limit(bodies.size(), S(0));
  for (const ContactRow<S>& row : rows) {
    const S used = maxS(abs(row.impulseT1), abs(row.impulseT2));
    const S most = row.friction * row.impulseN;
    for (const int32_t id : {row.a, row.b}) {
      if (id == kTerrainBody) continue;
      friction[size_t(id)] += used;
      limit[size_t(id)] += most;
    }
  }
  for (size_t i = 0; i < bodies.size(); ++i) bodies[i].slidingThisTick = limit[i] > S(0) && !(friction[i] < limit[i]);
  cache.clear();
  for (size_t i = 0; i < rows.size(); ++i)
    cache.push_back(CachedImpulse<S>{contacts[i].bodyA, contacts[i].bodyB, contacts[i].featureA, contacts[i].featureB,
                                     rows[i].impulseN, rows[i].impulseT1, rows[i].impulseT2, contacts[i].point});
}

template <class S>
void solveContactPositions(std::vector<RigidBody<S>>& bodies, const std::vector<Contact<S>>& contacts,
                           const std::vector<ContactRow<S>>& rows, S dt, const SolverSettings<S>& settings) {
  const size_t n = contacts.size();
  if (n == 0) return;
  std::vector<S> depth(n);
  for (size_t i = 0; i < n; ++i) {
    const S separating = maxS(relativeVelocity(bodies, rows[i]).dot(rows[i].normal), S(0));
    depth[i] = contacts[i].penetration - separating * dt;  // what integration will not remove
  }
  const size_t iterations = size_t(settings.positionIterationsPerContact) * n;
  for (size_t it = 0; it < iterations; ++it) {
    // The deepest contact first (lowest index on ties: canonical order).
    size_t worst = n;
    S deepest = settings.linearSlop;
    for (size_t i = 0; i < n; ++i)
      if (depth[i] > deepest) {
        deepest = depth[i];
        worst = i;
      }
    if (worst == n) break;
    const Contact<S>& c = contacts[worst];
    const Vec3<S>& normal = c.normal;
    // Leave `linearSlop` of overlap (Box2D): the contact then still exists next tick, so a resting
    // body keeps its support instead of falling g dt^2 and being pushed back every other tick.
    deepest -= settings.linearSlop;
    const int32_t ids[2] = {c.bodyA, c.bodyB};
    const Vec3<S>* arms[2] = {&rows[worst].rA, &rows[worst].rB};  // the arms the velocity pass used
    S linearInertia[2] = {S(0), S(0)}, angularInertia[2] = {S(0), S(0)};
    Vec3<S> angularPerUnit[2] = {Vec3<S>::Zero(), Vec3<S>::Zero()};
    S totalInertia(0);
    for (int k = 0; k < 2; ++k) {
      if (ids[k] == kTerrainBody) continue;
      const RigidBody<S>& body = bodies[size_t(ids[k])];
      angularPerUnit[k] = body.invInertiaWorld * arms[k]->cross(normal);
      angularInertia[k] = angularPerUnit[k].cross(*arms[k]).dot(normal);
      linearInertia[k] = body.invMass;
      totalInertia += linearInertia[k] + angularInertia[k];
    }
    if (!(totalInertia > S(0))) {
      depth[worst] = S(0);
      continue;
    }
    for (int k = 0; k < 2; ++k) {
      if (ids[k] == kTerrainBody) continue;
      RigidBody<S>& body = bodies[size_t(ids[k])];
      const S sign = k == 0 ? S(1) : S(-1);
      S linearMove = sign * deepest * linearInertia[k] / totalInertia;
      S angularMove = sign * deepest * angularInertia[k] / totalInertia;
      // Cyclone: rotating by more than 0.2 |r| per step overshoots; move linearly instead.
      const S limit = arms[k]->norm() / S(5);
      if (abs(angularMove) > limit) {
        const S both = linearMove + angularMove;
        angularMove = angularMove < S(0) ? -limit : limit;
        linearMove = both - angularMove;
      }
      const Vec3<S> dp = normal * linearMove;
      const Vec3<S> dTheta = angularInertia[k] > S(0) ? Vec3<S>(angularPerUnit[k] * (angularMove / angularInertia[k]))
                                                      : Vec3<S>(Vec3<S>::Zero());
      body.position += dp;
      const Quat<S> spin(S(0), dTheta.x(), dTheta.y(), dTheta.z());
      Quat<S> q = body.orientation;
      q.coeffs() += (spin * body.orientation).coeffs() / S(2);
      body.orientation = normalizedQuat(q);
      body.updateDerived();
      // Every contact of this body loses (or gains) the depth this move removed.
      for (size_t i = 0; i < n; ++i) {
        if (contacts[i].bodyA == ids[k]) depth[i] -= (dp + dTheta.cross(rows[i].rA)).dot(contacts[i].normal);
        if (contacts[i].bodyB == ids[k]) depth[i] += (dp + dTheta.cross(rows[i].rB)).dot(contacts[i].normal);
      }
    }
  }
}

#define SG_INSTANTIATE(S)                                                                            \
  template void sortContacts(std::vector<Contact<S>>&);                                              \
  template void prepareContactRows(const std::vector<RigidBody<S>>&, const std::vector<Contact<S>>&, \
                                   std::vector<ContactRow<S>>&);                                     \
  template void solveContactVelocities(std::vector<RigidBody<S>>&, const std::vector<Contact<S>>&,   \
                                       std::vector<ContactRow<S>>&, const SolverSettings<S>&,        \
                                       std::vector<CachedImpulse<S>>&);                              \
  template void solveContactPositions(std::vector<RigidBody<S>>&, const std::vector<Contact<S>>&,    \
                                      const std::vector<ContactRow<S>>&, S, const SolverSettings<S>&);
SG_FOR_EACH_SCALAR(SG_INSTANTIATE)
#undef SG_INSTANTIATE
}  // namespace sg
