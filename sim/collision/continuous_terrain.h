// Continuous collision of fast bodies with a heightmap, after the solve (Box2D v3's
// b2SolveContinuous, Jolt's LinearCast motion quality): a body's speculative terrain contacts
// are chosen where it is at the tick's start, and a slope that turns a fast fall into a fast
// slide within the tick sends it on, sideways, into ground that had no contact. A 10 cm ball
// dropped at 500 m/s onto hills ended ticks 22 cm inside the rising ground beside its landing
// point, a 5 cm one wholly under it, and cubes 29 cm. So each fast body's motion over
// the tick is swept against the terrain (the narrow phase at points of the path, a quarter of its
// smallest size apart; a box at its end-of-tick rotation) and the body is moved back to the last
// point before it would overlap by more than the slop; its velocity is kept (the next tick's
// contacts take it), as Box2D keeps it at the time of impact. Compound bodies are swept with all
// their parts, a quarter of their smallest part apart.
#pragma once

#include <algorithm>
#include <vector>

#include "sim/bodies/rigid_body.h"
#include "sim/collision/terrain_contacts.h"

namespace sg {

/// Most points of a path the sweep tests (a 5 cm ball at 500 m/s over a 60 Hz tick moves 8.3 m,
/// 667 quarter radii: past this the points lie further apart than a quarter radius).
inline constexpr int64_t kMaxSweepPoints = 256;

/// The deepest overlap (m) with the terrain of body `b` with its centre of mass at `centre` (its
/// present rotation); 0 when it touches nothing.
template <class S>
S deepestTerrainOverlap(const RigidBody<S>& b, const Vec3<S>& centre, const Terrain<S>& terrain,
                        std::vector<Contact<S>>& scratch) {
  scratch.clear();
  for (const BodyPart<S>& part : b.parts) {
    // As RigidBody::partPose, about `centre`: a part at the centre of mass skips the rotation.
    const Vec3<S> at = part.offset == Vec3<S>::Zero() ? centre : Vec3<S>(centre + b.rotation * part.offset);
    if (part.type == ShapeType::Sphere)
      collideSphereTerrain(0, at, part.radius, terrain, scratch, S(0));
    else
      collideBoxTerrain(0, part.halfExtents, Pose<S>{at, b.rotation}, terrain, scratch, S(0));
  }
  S deepest(0);
  for (const Contact<S>& c : scratch) deepest = maxS(deepest, c.penetration);
  return deepest;
}

/// The smallest radius or half extent of any of the body's parts (m).
template <class S>
S smallestPartSize(const RigidBody<S>& b) {
  S smallest = b.parts[0].type == ShapeType::Sphere ? b.parts[0].radius : b.parts[0].halfExtents.x();
  for (const BodyPart<S>& part : b.parts)
    smallest = part.type == ShapeType::Sphere
                   ? minS(smallest, part.radius)
                   : minS(smallest, minS(part.halfExtents.x(), minS(part.halfExtents.y(), part.halfExtents.z())));
  return smallest;
}

/// Moves every awake body (at its end-of-tick rotation) that moved more than half its smallest
/// part size since `start` back along its straight path to the last tested point, a quarter of
/// that size apart, where it overlaps the heightmap by no more than `slop` (m), or than it did at
/// the start where that was more. A body that started the tick inside the ground may come out of
/// it, but never go deeper along its path. (A ball started 6 mm into a bump and fired down past it
/// finds no contact on the flat ground beyond, the concave crease makes no row; when such a body
/// was left to its contacts it ended its tick 1.57 m under the ground. Allowing the start overlap
/// plus the slop instead let a ball sliding over hills at 500 m/s ratchet down a slop a tick.)
/// A body buried deeper than half its smallest part size is left to its contacts: every point of
/// its path may lie deeper than its start, and holding it there froze it while gravity grew its
/// velocity without end (a 1 m box started 3.3 m under a random heightmap overflowed fx16).
template <class S>
void sweepFastBodiesAgainstTerrain(std::vector<RigidBody<S>>& bodies, const std::vector<Vec3<S>>& start,
                                   const Terrain<S>& terrain, S slop) {
  if (terrain.flat()) return;  // a plane: the speculative contact is exact, whatever the path
  std::vector<Contact<S>> scratch;
  for (size_t i = 0; i < bodies.size(); ++i) {
    RigidBody<S>& b = bodies[i];
    if (b.asleep) continue;
    const S size = smallestPartSize(b);
    const Vec3<S> moved = b.position - start[i];
    const S half = size / S(2);
    if (!(abs(moved.x()) > half) && !(abs(moved.y()) > half) && !(abs(moved.z()) > half)) continue;
    const S startOverlap = deepestTerrainOverlap(b, start[i], terrain, scratch);
    if (startOverlap > half) continue;
    const S allowed = maxS(slop, startOverlap);
    const S length = length3(moved.x(), moved.y(), moved.z());
    const S quarter = size / S(4);
    int64_t points = kMaxSweepPoints;
    if (length / quarter < S(kMaxSweepPoints - 1)) points = 1 + int64_t(ScalarTraits<S>::toDouble(length / quarter));
    for (int64_t k = 1; k <= points; ++k) {
      const Vec3<S> p = start[i] + moved * (S(k) / S(points));
      if (!(deepestTerrainOverlap(b, p, terrain, scratch) > allowed)) continue;
      b.position = start[i] + moved * (S(k - 1) / S(points));
      break;
    }
  }
}

}  // namespace sg
