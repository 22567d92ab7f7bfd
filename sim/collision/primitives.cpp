#include "sim/collision/primitives.h"

namespace sg {

template <class S>
int collideSphereSphere(int32_t a, const Vec3<S>& ca, S ra, int32_t b, const Vec3<S>& cb, S rb,
                        std::vector<Contact<S>>& out, S speculative) {
  const Vec3<S> d = ca - cb;
  const S reach = ra + rb;
  const S detect = reach + speculative;
  // Cheap reject on each axis before squaring (keeps fx16 products small).
  if (abs(d.x()) >= detect || abs(d.y()) >= detect || abs(d.z()) >= detect) return 0;
  const S dist = length3(d.x(), d.y(), d.z());
  if (dist >= detect) return 0;
  Contact<S> c;
  c.bodyA = a;
  c.bodyB = b;
  c.normal = dist == S(0) ? Vec3<S>::UnitY() : Vec3<S>(d / dist);
  c.penetration = reach - dist;
  // Overlapping: midway between the surfaces. Speculative: on A's surface, so the arms stay the
  // size of the sphere however wide the gap (a long arm is a huge angular term, and overflows fx16).
  c.point = c.penetration < S(0) ? Vec3<S>(ca - c.normal * ra) : Vec3<S>(cb + c.normal * (rb - c.penetration / S(2)));
  out.push_back(c);
  return 1;
}

template <class S>
int collideSphereBox(int32_t a, const Vec3<S>& ca, S ra, int32_t b, const Vec3<S>& hb, const Pose<S>& pb,
                     std::vector<Contact<S>>& out, S speculative) {
  const Vec3<S> local = pb.toLocal(ca);
  const S detect = ra + speculative;
  if (abs(local.x()) >= hb.x() + detect || abs(local.y()) >= hb.y() + detect || abs(local.z()) >= hb.z() + detect)
    return 0;
  Vec3<S> closest;
  for (int i = 0; i < 3; ++i) closest[i] = local[i] < -hb[i] ? -hb[i] : (local[i] > hb[i] ? hb[i] : local[i]);
  Contact<S> c;
  c.bodyA = a;
  c.bodyB = b;
  if (closest == local) {
    // Centre inside the box: out through the nearest face.
    S best, side;
    const int axis = nearestFaceAxis(local, hb, &best, &side);
    Vec3<S> n = Vec3<S>::Zero();
    n[axis] = side;
    c.normal = pb.rotation * n;
    c.penetration = ra + best;
    c.featureB = uint32_t(2 * axis + (local[axis] < S(0) ? 1 : 0));
    closest[axis] = n[axis] * hb[axis];
    c.point = pb.toWorld(closest);
  } else {
    const Vec3<S> d = local - closest;
    const S dist = length3(d.x(), d.y(), d.z());
    if (dist >= detect) return 0;
    c.normal = pb.rotation * Vec3<S>(d / dist);  // dist > 0: the centre is outside
    c.penetration = ra - dist;
    c.point = dist > ra ? Vec3<S>(ca - c.normal * ra) : pb.toWorld(closest);  // speculative: on the sphere
    c.featureB = 6;
  }
  out.push_back(c);
  return 1;
}

#define SG_INSTANTIATE(S)                                                                                            \
  template int collideSphereSphere(int32_t, const Vec3<S>&, S, int32_t, const Vec3<S>&, S, std::vector<Contact<S>>&, \
                                   S);                                                                               \
  template int collideSphereBox(int32_t, const Vec3<S>&, S, int32_t, const Vec3<S>&, const Pose<S>&,                 \
                                std::vector<Contact<S>>&, S);
SG_FOR_EACH_SCALAR(SG_INSTANTIATE)
#undef SG_INSTANTIATE
}  // namespace sg
