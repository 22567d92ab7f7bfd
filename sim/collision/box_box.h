// Narrow phase between two oriented boxes: separating-axis test over the 15 candidate axes, then
// a face contact (incident face clipped against the reference face's side planes) or one
// edge-edge contact. Conventions of contact.h: normal from B to A, penetration >= 0 (m).
//
// Axis choice (deterministic; "pen" is the overlap along a unit axis, in m):
//   * candidates in order: faces of A (x, y, z), faces of B (x, y, z), edge pairs a_i x b_j
//     (i major, j minor). Within each group the smallest pen wins, the lowest index on ties;
//   * a face of B replaces the best face of A only if  penB * (1 + 1/64) + margin < penA;
//   * the best edge axis replaces that face only if  penE * (1 + 1/16) + margin < penFace.
//   margin is the rounding bound of an overlap: 16 units in the last place of a rotation entry
//   (2^-28 fx32, 2^-12 fx16, 2^-19 float, 2^-48 double) times (sum of the six half extents +
//   1 m). The relative parts keep the reference face from flipping between near-equal
//   candidates (cf. Box2D 2.x's 0.98, ODE's fudge factor 1.05 on edge axes); the margin keeps
//   rounding noise from deciding exact ties (a box resting on a box: A's face wins).
//   If the chosen axis yields no contact (an edge pair whose closest points lie off the edges;
//   a face whose clipped incident face lies wholly above it), the other two candidates are tried,
//   least pen first.
// Parallel edges: an edge axis with |a_i x b_j| < sin_min (2^-10; 2^-4 for fx16, whose contact
// point errs by about 2^-16 / sin^2) never makes contacts. Every edge axis is still tested for
// separation, but only separates when |t . L| > rA + rB + margin, so a (near) zero cross
// product can never report a false separation (Ericson pads |R| by an epsilon for the same
// reason). Incident vertices up to margin above the reference face count, with penetration 0.
//
// Features (all below 2^16; body_pairs.h puts the part index in the upper bits):
//   * face contact: the reference box gets its face index f = 2 * axis + (normal negative), 0..5;
//     the incident box gets 0x100 * incidentFace + clipId, clipId 0..3 = incident face corner,
//     4 + 4 * e + p = polygon edge e (0..3 incident face edge, 4..7 reference side plane e - 4)
//     crossing reference side plane p (0..3: +u, -u, +v, -v of the reference face);
//   * edge contact: kBoxEdgeFeature + edge index on each box, edge = 4 * axis + code, code bit 0 =
//     the next axis ((axis + 1) % 3) positive, bit 1 = the one after positive.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/collision/contact.h"

namespace sg {

/// featureA/featureB of an edge-edge box contact: kBoxEdgeFeature + edge index (0..11).
inline constexpr uint32_t kBoxEdgeFeature = 0x1000;
/// Incident-box feature of a face contact: 0x100 * incident face + clip id.
inline constexpr uint32_t kBoxIncidentFaceStride = 0x100;

/// Contacts between two oriented boxes (half extents ha, hb; poses pa, pb). Appends 0..8
/// contacts to `out` with bodyA = a, bodyB = b, normal pointing from B to A, and returns how many.
/// Boxes that merely touch (overlap exactly 0 on the best axis) get contacts of penetration 0.
/// Supported inputs (fuzz-tested): box sizes 0.01..100 m (half extents 0.005..50 m), positions
/// within +-1000 m (fx32, float, double) or +-100 m (fx16); rotations proper (det +1) and
/// orthonormal to the scalar's precision. No division by zero, no fixed-point fault there.
/// With `speculative` > 0 (m), boxes up to that far apart get speculative contacts too
/// (penetration = minus the gap, primitives.h): the separating tests allow that gap, incident
/// vertices up to it above the reference face count, and an edge pair may be apart by it.
template <class S>
int collideBoxBox(int32_t a, const Vec3<S>& ha, const Pose<S>& pa, int32_t b, const Vec3<S>& hb, const Pose<S>& pb,
                  std::vector<Contact<S>>& out, S speculative = S(0));

}  // namespace sg
