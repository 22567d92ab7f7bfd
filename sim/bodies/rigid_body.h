// Rigid bodies: spheres, oriented boxes and compounds of them (thesis §4 "Rigid bodies"; the
// thesis names the lack of compounds as a limit, a mower is one). Plain data; the stages that
// move them live in sim/bodies/integrate_bodies.h and sim/collision/.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/collision/contact.h"
#include "sim/scenario/scenario.h"

namespace sg {

template <class S>
struct BodyPart {
  ShapeType type = ShapeType::Sphere;
  S radius{};                             ///< m (sphere)
  Vec3<S> halfExtents = Vec3<S>::Zero();  ///< m (box)
  Vec3<S> offset = Vec3<S>::Zero();  ///< m, centre in the body frame, from the centre of mass (not the author's origin)
  S boundingRadius{};                ///< m, around the part centre
};

template <class S>
struct RigidBody {
  // --- constant properties -------------------------------------------------------------------
  std::vector<BodyPart<S>> parts;
  S invMass{};                                          ///< 1/kg
  Vec3<S> invInertiaLocal = Vec3<S>::Zero();            ///< principal inverse inertia (body axes), 1/(kg m^2)
  Vec3<S> inertiaLocal = Vec3<S>::Zero();               ///< principal inertia (body axes), kg m^2 (gyroscopic term)
  S linearDampingPerTick{1}, angularDampingPerTick{1};  ///< damping^dt
  S restitution{}, friction{};
  S boundingRadius{};  ///< m, around the centre of mass: covers every part
  /// m, body frame: the centre of mass relative to the origin the scenario placed the parts
  /// around (0 for a single shape and a symmetric compound). `position` is the centre of mass; a
  /// scenario position, a teleport and a spawn name the origin.
  Vec3<S> centreOfMassLocal = Vec3<S>::Zero();
  bool mower = false;
  bool canSleep = true;
  // --- state (saved, hashed) -----------------------------------------------------------------
  Vec3<S> position = Vec3<S>::Zero();         ///< centre of mass (m)
  Quat<S> orientation = Quat<S>::Identity();  ///< unit quaternion, body -> world
  Vec3<S> velocity = Vec3<S>::Zero();         ///< m/s
  Vec3<S> angularVelocity = Vec3<S>::Zero();  ///< rad/s, world frame
  int32_t stillTicks = 0;                     ///< consecutive ticks below the sleep thresholds
  bool asleep = false;                        ///< skips gravity and integration until woken
  bool bladeOn = true;                        ///< a mower cuts only while on (MowerOn/MowerOff)
  // --- per tick, not state: set by the response stage, read by the sleep test of the same tick --
  /// False when this body's contacts slid this tick (friction reached mu x normal impulse) or
  /// overlap deeper than the slop (being pushed out): its contacts do not hold it where it is,
  /// however slowly it moves, so it may not fall asleep.
  bool heldThisTick = true;
  // --- derived from the state (recomputed by updateDerived) ----------------------------------
  Mat3<S> rotation = Mat3<S>::Identity();
  Mat3<S> invInertiaWorld = Mat3<S>::Zero();

  /// Rotation matrix and world inverse inertia R diag(I^-1) R^T from the orientation.
  void updateDerived() {
    updateRotation();
    updateInvInertiaWorld();
  }
  /// The rotation matrix alone (each sub-step: the contact anchors and the gyroscopic term read it).
  void updateRotation() { rotation = orientation.toRotationMatrix(); }
  /// R diag(I^-1) R^T from `rotation` (read only when contacts are prepared, once a tick).
  void updateInvInertiaWorld() { invInertiaWorld = rotation * invInertiaLocal.asDiagonal() * rotation.transpose(); }
  Pose<S> partPose(size_t i) const {
    // A part at the centre of mass (every single-part body) skips the rotation: R 0 is exactly 0.
    if (parts[i].offset == Vec3<S>::Zero()) return Pose<S>{position, rotation};
    return Pose<S>{position + rotation * parts[i].offset, rotation};
  }
};

/// Builds a body from its scenario description. Mass properties are exact fractions, rounded
/// once into S: the thesis formulas (sphere 2/5 m r^2, box m/12 (dy^2 + dz^2), ...); a compound's
/// mass split over its parts by volume (pi as 355/113, only in that ratio); the parallel-axis
/// theorem about the centre of mass, which is computed from the parts (the offsets may be around
/// any origin). A compound's principal axes are taken to be the body axes (true for the symmetric
/// layouts in scenarios/; off-diagonal products of inertia are dropped). `path` names the body
/// in errors (ScenarioError when a value cannot be combined exactly).
template <class S>
RigidBody<S> makeBody(const BodySpec& spec, const Rational& timeStep, const std::string& sourceName,
                      const std::string& path);

/// Normalises a quaternion with the deterministic sqrt (the identity if it is zero).
template <class S>
Quat<S> normalizedQuat(const Quat<S>& q);

}  // namespace sg
