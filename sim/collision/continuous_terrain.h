// Continuous collision of fast spheres with a heightmap, after the solve (Box2D v3's
// b2SolveContinuous, Jolt's LinearCast motion quality): a sphere's speculative terrain contacts
// are chosen where it is at the tick's start, and a slope that turns a fast fall into a fast
// slide within the tick sends it on, sideways, into ground that had no contact. A 10 cm ball
// dropped at 500 m/s onto hills ended ticks 20 cm inside the rising ground beside its landing
// point, and a 5 cm one wholly under it. So each fast sphere's motion over the tick is swept
// against the terrain (the narrow phase at points of the path, a quarter radius apart) and the
// sphere is moved back to the last point before it would overlap by more than the slop; its
// velocity is kept (the next tick's contacts take it), as Box2D keeps it at the time of impact.
#pragma once

#include <algorithm>
#include <vector>

#include "sim/bodies/rigid_body.h"
#include "sim/collision/terrain_contacts.h"

namespace sg {

/// Most points of a path the sweep tests (a 5 cm ball at 500 m/s over a 60 Hz tick moves 8.3 m,
/// 667 quarter radii: past this the points lie further apart than a quarter radius).
inline constexpr int64_t kMaxSweepPoints = 256;

/// The deepest overlap (m) of a sphere at `centre` with the terrain; 0 when it touches nothing.
template <class S>
S deepestTerrainOverlap(const Vec3<S>& centre, S radius, const Terrain<S>& terrain, std::vector<Contact<S>>& scratch) {
  scratch.clear();
  collideSphereTerrain(0, centre, radius, terrain, scratch, S(0));
  S deepest(0);
  for (const Contact<S>& c : scratch) deepest = maxS(deepest, c.penetration);
  return deepest;
}

/// Moves every awake single-sphere body that moved more than half its radius since `start` back
/// along its straight path to the last tested point where it overlaps the heightmap by no more
/// than `slop` (m). A body that already overlapped by more at the start is left to its contacts.
template <class S>
void sweepFastSpheresAgainstTerrain(std::vector<RigidBody<S>>& bodies, const std::vector<Vec3<S>>& start,
                                    const Terrain<S>& terrain, S slop) {
  if (terrain.flat()) return;  // a plane: the speculative contact is exact, whatever the path
  std::vector<Contact<S>> scratch;
  for (size_t i = 0; i < bodies.size(); ++i) {
    RigidBody<S>& b = bodies[i];
    if (b.asleep || b.parts.size() != 1 || b.parts[0].type != ShapeType::Sphere) continue;
    const S radius = b.parts[0].radius;
    const Vec3<S> moved = b.position - start[i];
    const S half = radius / S(2);
    if (!(abs(moved.x()) > half) && !(abs(moved.y()) > half) && !(abs(moved.z()) > half)) continue;
    if (deepestTerrainOverlap(start[i], radius, terrain, scratch) > slop) continue;
    const S length = length3(moved.x(), moved.y(), moved.z());
    const S quarter = radius / S(4);
    int64_t points = kMaxSweepPoints;
    if (length / quarter < S(kMaxSweepPoints - 1)) points = 1 + int64_t(ScalarTraits<S>::toDouble(length / quarter));
    for (int64_t k = 1; k <= points; ++k) {
      const Vec3<S> p = start[i] + moved * (S(k) / S(points));
      if (!(deepestTerrainOverlap(p, radius, terrain, scratch) > slop)) continue;
      b.position = start[i] + moved * (S(k - 1) / S(points));
      break;
    }
  }
}

}  // namespace sg
