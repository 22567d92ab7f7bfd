// Narrow phase for spheres (thesis §4 "Collision detection"). Box-box is in box_box.h, bodies
// against the terrain in terrain_contacts.h. Every routine appends contacts with the conventions of contact.h (normal
// from B to A) and never divides by zero: coincident centres get a fixed normal. `speculative` (m, >= 0): shapes up to
// that far apart get a contact too, with a negative penetration (the gap). The solver lets such a contact close at most
// its gap per step (speculative contacts, Box2D v3), so a body that would pass through within a tick stops at the
// surface instead; the world sets it from the bodies' speeds (sim/collision/world_contacts.cpp).
#pragma once

#include <vector>

#include "sim/collision/contact.h"
#include "sim/math/scalar_ops.h"

namespace sg {

/// Sphere A (centre ca, radius ra) against sphere B.
template <class S>
int collideSphereSphere(int32_t a, const Vec3<S>& ca, S ra, int32_t b, const Vec3<S>& cb, S rb,
                        std::vector<Contact<S>>& out, S speculative = S(0));

/// Sphere A against box B (half extents hb, pose pb). Closest point on the box in box space;
/// a centre inside the box is pushed out through the nearest face.
template <class S>
int collideSphereBox(int32_t a, const Vec3<S>& ca, S ra, int32_t b, const Vec3<S>& hb, const Pose<S>& pb,
                     std::vector<Contact<S>>& out, S speculative = S(0));

}  // namespace sg
