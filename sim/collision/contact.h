// A contact between a rigid body and another body or the terrain, as the narrow phase reports it
// and the solver consumes it.
//
// Conventions (the same in every narrow-phase routine):
//   * `normal` is a unit vector pointing from B towards A: moving A along it separates them;
//   * `penetration` > 0 is the overlap depth along the normal (m);
//   * `point` is a world-space point on the contact (between the surfaces);
//   * `featureA/featureB` identify the features that touch (corner index, edge index, face
//     index, sample index; 0 for spheres) so contacts can be sorted canonically: the solver's
//     result never depends on the order in which the narrow phase found them.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/math/eigen_support.h"

namespace sg {

/// Index meaning "the terrain" in Contact::bodyB.
inline constexpr int32_t kTerrainBody = -1;

template <class S>
struct Contact {
  int32_t bodyA = 0;
  int32_t bodyB = kTerrainBody;
  uint32_t featureA = 0;
  uint32_t featureB = 0;
  Vec3<S> point = Vec3<S>::Zero();
  Vec3<S> normal = Vec3<S>::UnitY();
  S penetration{};
};

/// Where a primitive is in the world: position and rotation matrix (columns = local axes).
template <class S>
struct Pose {
  Vec3<S> position = Vec3<S>::Zero();
  Mat3<S> rotation = Mat3<S>::Identity();
  Vec3<S> toLocal(const Vec3<S>& world) const { return rotation.transpose() * (world - position); }
  Vec3<S> toWorld(const Vec3<S>& local) const { return position + rotation * local; }
};

/// The face of a box (half extents h) nearest to a local point inside it: returns the axis and
/// sets *gap = h[axis] - |local[axis]| (the distance to that face) and *sign = +-1 (which side).
/// The lowest axis wins ties, so the choice is deterministic.
template <class S>
int nearestFaceAxis(const Vec3<S>& local, const Vec3<S>& h, S* gap, S* sign) {
  using std::abs;
  int axis = 0;
  *gap = h[0] - abs(local[0]);
  for (int k = 1; k < 3; ++k) {
    const S g = h[k] - abs(local[k]);
    if (g < *gap) {
      *gap = g;
      axis = k;
    }
  }
  *sign = local[axis] < S(0) ? S(-1) : S(1);
  return axis;
}

}  // namespace sg
