// Body-body broad phase (thesis: all pairs, only three bodies) and the narrow-phase dispatch over
// compound parts. "brute" tests every pair i < j; "sap" sorts bounding intervals along x and
// sweeps. Both return the pairs whose bounding spheres, each grown by the body's reach this tick,
// overlap, sorted (i, j): identical lists.
#pragma once

#include <algorithm>
#include <utility>
#include <vector>

#include "sim/bodies/rigid_body.h"
#include "sim/collision/box_box.h"
#include "sim/collision/primitives.h"
#include "sim/collision/swept_spheres.h"
#include "sim/collision/terrain_contacts.h"

namespace sg {

/// `reachA`, `reachB` (m): how far beyond its bounding sphere each body may touch this tick.
template <class S>
bool boundingSpheresOverlap(const RigidBody<S>& a, const RigidBody<S>& b, S reachA, S reachB) {
  const Vec3<S> d = a.position - b.position;
  const S reach = a.boundingRadius + b.boundingRadius + reachA + reachB;
  if (abs(d.x()) > reach || abs(d.y()) > reach || abs(d.z()) > reach) return false;
  return length3(d.x(), d.y(), d.z()) <= reach;
}

/// `reach[i]` (m, >= 0; empty: all 0) grows body i's bounding sphere (speculative contacts).
template <class S>
std::vector<std::pair<int32_t, int32_t>> bodyPairs(const std::vector<RigidBody<S>>& bodies, BodyBroadphase kind,
                                                   const std::vector<S>& reach = {}) {
  std::vector<std::pair<int32_t, int32_t>> pairs;
  const int32_t n = int32_t(bodies.size());
  auto grown = [&](int32_t i) { return reach.empty() ? S(0) : reach[size_t(i)]; };
  auto overlap = [&](int32_t i, int32_t j) {
    return boundingSpheresOverlap(bodies[size_t(i)], bodies[size_t(j)], grown(i), grown(j));
  };
  if (kind == BodyBroadphase::Brute) {
    for (int32_t i = 0; i < n; ++i)
      for (int32_t j = i + 1; j < n; ++j)
        if (overlap(i, j)) pairs.emplace_back(i, j);
    return pairs;
  }
  // Sweep and prune along x: order by interval start (id breaks ties), scan forward while the
  // next interval starts before this one ends.
  std::vector<int32_t> order(static_cast<size_t>(n));
  std::vector<S> lo(static_cast<size_t>(n)), hi(static_cast<size_t>(n));  // each body's x interval, formed once
  for (int32_t i = 0; i < n; ++i) {
    order[size_t(i)] = i;
    const RigidBody<S>& b = bodies[size_t(i)];
    lo[size_t(i)] = b.position.x() - b.boundingRadius - grown(i);
    hi[size_t(i)] = b.position.x() + b.boundingRadius + grown(i);
  }
  std::stable_sort(order.begin(), order.end(), [&](int32_t a, int32_t b) { return lo[size_t(a)] < lo[size_t(b)]; });
  for (size_t x = 0; x < order.size(); ++x)
    for (size_t y = x + 1; y < order.size() && !(lo[size_t(order[y])] > hi[size_t(order[x])]); ++y) {
      const int32_t i = std::min(order[x], order[y]), j = std::max(order[x], order[y]);
      if (overlap(i, j)) pairs.emplace_back(i, j);
    }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

/// Whether the contacts of a sphere part pair (part `a` of A at pose pa, part `b` of B at pb; one
/// of them a sphere) can close this tick: false when the sphere's path relative to the other
/// part stays farther than the sweep's margin from it.
template <class S>
bool sphereCanMeet(const BodyPart<S>& a, const Pose<S>& pa, const BodyPart<S>& b, const Pose<S>& pb,
                   const PairSweep<S>& sweep) {
  if (a.type == ShapeType::Sphere && b.type == ShapeType::Sphere)
    return segmentPointDistance(pa.position, sweep.displacement, pb.position) - a.radius - b.radius <= sweep.margin;
  if (a.type == ShapeType::Sphere) {
    const Vec3<S> path = pb.rotation.transpose() * sweep.displacement;
    return segmentBoxDistance(pb.toLocal(pa.position), path, b.halfExtents) - a.radius <= sweep.margin;
  }
  const Vec3<S> path = pa.rotation.transpose() * Vec3<S>(-sweep.displacement);  // B's sphere against A's box
  return segmentBoxDistance(pa.toLocal(pb.position), path, a.halfExtents) - b.radius <= sweep.margin;
}

/// Contacts between bodies i < j over all their parts; features carry the part index in the
/// upper 16 bits. Every contact has bodyA = i, bodyB = j. Parts up to `speculative` (m) apart
/// get speculative contacts (primitives.h); with a `sweep`, a sphere part's speculative contact
/// farther than its margin is kept only if the sphere's path this tick can reach the other part.
template <class S>
void collideBodies(int32_t i, const RigidBody<S>& A, int32_t j, const RigidBody<S>& B, std::vector<Contact<S>>& out,
                   S speculative = S(0), const PairSweep<S>* sweep = nullptr) {
  for (size_t pi = 0; pi < A.parts.size(); ++pi)
    for (size_t pj = 0; pj < B.parts.size(); ++pj) {
      const BodyPart<S>& a = A.parts[pi];
      const BodyPart<S>& b = B.parts[pj];
      const Pose<S> pa = A.partPose(pi), pb = B.partPose(pj);
      const size_t first = out.size();
      if (a.type == ShapeType::Sphere && b.type == ShapeType::Sphere) {
        collideSphereSphere(i, pa.position, a.radius, j, pb.position, b.radius, out, speculative);
      } else if (a.type == ShapeType::Sphere) {
        collideSphereBox(i, pa.position, a.radius, j, b.halfExtents, pb, out, speculative);
      } else if (b.type == ShapeType::Sphere) {
        // Box A, sphere B: solve as sphere-box with the roles swapped, then swap back.
        collideSphereBox(j, pb.position, b.radius, i, a.halfExtents, pa, out, speculative);
        for (size_t k = first; k < out.size(); ++k) {
          std::swap(out[k].bodyA, out[k].bodyB);
          std::swap(out[k].featureA, out[k].featureB);
          out[k].normal = -out[k].normal;
        }
      } else {
        collideBoxBox(i, a.halfExtents, pa, j, b.halfExtents, pb, out, speculative);
      }
      // A sphere part makes one contact; a box pair's manifold is left as it is (no sweep test).
      if (sweep && out.size() == first + 1 && (a.type == ShapeType::Sphere || b.type == ShapeType::Sphere) &&
          -out[first].penetration > sweep->margin && !sphereCanMeet(a, pa, b, pb, *sweep))
        out.resize(first);
      for (size_t k = first; k < out.size(); ++k) {
        out[k].featureA |= uint32_t(pi) << 16;
        out[k].featureB |= uint32_t(pj) << 16;
      }
    }
}

/// Contacts of body i with the terrain over all its parts (speculative up to `speculative` m;
/// with a `sweep`, a lone sphere's or box's heightmap contacts beyond its margin only where its
/// path this tick can reach their features: terrain_contacts.h). Not a compound's parts: one part's
/// contact turns the body within the tick, and the other part's path is then far off its
/// start-of-tick line (a dumbbell of two 10 cm balls at 300 m/s sank 4.6 m into a hill).
template <class S>
void collideBodyTerrain(int32_t i, const RigidBody<S>& A, const Terrain<S>& terrain, std::vector<Contact<S>>& out,
                        S speculative = S(0), const PairSweep<S>* sweep = nullptr) {
  const PairSweep<S>* loneSweep = A.parts.size() == 1 ? sweep : nullptr;
  for (size_t p = 0; p < A.parts.size(); ++p) {
    const size_t first = out.size();
    const Pose<S> pose = A.partPose(p);
    if (A.parts[p].type == ShapeType::Sphere)
      collideSphereTerrain(i, pose.position, A.parts[p].radius, terrain, out, speculative, loneSweep);
    else
      collideBoxTerrain(i, A.parts[p].halfExtents, pose, terrain, out, speculative, loneSweep);
    for (size_t k = first; k < out.size(); ++k) out[k].featureA |= uint32_t(p) << 16;
  }
}

}  // namespace sg
