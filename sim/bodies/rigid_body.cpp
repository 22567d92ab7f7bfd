#include "sim/bodies/rigid_body.h"

#include <algorithm>
#include <stdexcept>

namespace sg {
namespace {
template <class S>
S toS(const Rational& r) {
  const auto v = ScalarTraits<S>::fromRational(r);
  if (!v) throw std::out_of_range("body value " + r.toString() + " does not fit the scalar");
  return *v;
}
template <class S>
Vec3<S> toS3(const Rational3& r) {
  return Vec3<S>(toS<S>(r[0]), toS<S>(r[1]), toS<S>(r[2]));
}

/// Checked exact arithmetic for the mass properties; an overflow names the body.
struct Exact {
  const std::string& file;
  const std::string& path;
  Rational operator()(std::optional<Rational> r) const {
    if (!r) throw ScenarioError(file, path, "mass properties that fit 128-bit fractions (use fewer digits)");
    return *r;
  }
  Rational mul(const Rational& a, const Rational& b) const { return (*this)(sg::mul(a, b)); }
  Rational add(const Rational& a, const Rational& b) const { return (*this)(sg::add(a, b)); }
  Rational sub(const Rational& a, const Rational& b) const { return (*this)(sg::sub(a, b)); }
  Rational div(const Rational& a, const Rational& b) const { return (*this)(sg::div(a, b)); }
};

/// Volume of a part (m^3), pi as 355/113: only ever used as a ratio between parts.
Rational volumeOf(const ShapeSpec& p, const Exact& x) {
  if (p.type == ShapeType::Sphere) {
    const Rational r3 = x.mul(x.mul(p.radius, p.radius), p.radius);
    return x.mul(r3, Rational{1420, 339} /* 4/3 pi with pi = 355/113 */);
  }
  return x.mul(x.mul(x.mul(p.halfExtents[0], p.halfExtents[1]), p.halfExtents[2]), Rational{8, 1});
}
}  // namespace

template <class S>
Quat<S> normalizedQuat(const Quat<S>& q) {
  const S n2 = q.w() * q.w() + q.x() * q.x() + q.y() * q.y() + q.z() * q.z();
  if (n2 == S(0)) return Quat<S>::Identity();
  using std::sqrt;
  const S n = sqrt(n2);
  return Quat<S>(q.w() / n, q.x() / n, q.y() / n, q.z() / n);
}

template <class S>
RigidBody<S> makeBody(const BodySpec& spec, const Rational& dt, const std::string& file, const std::string& path) {
  const Exact x{file, path};
  RigidBody<S> b;
  Rational totalVolume{0, 1};
  for (const ShapeSpec& p : spec.parts) totalVolume = x.add(totalVolume, volumeOf(p, x));
  // The centre of mass from the parts (mass split by volume), whatever origin the author placed
  // the offsets around: the body turns about it and the inertia is taken about it.
  Rational com[3] = {{0, 1}, {0, 1}, {0, 1}};
  for (const ShapeSpec& p : spec.parts)
    for (size_t a = 0; a < 3; ++a) com[a] = x.add(com[a], x.mul(x.div(volumeOf(p, x), totalVolume), p.offset[a]));
  Rational inertia[3] = {{0, 1}, {0, 1}, {0, 1}};
  using std::sqrt;
  for (const ShapeSpec& spec0 : spec.parts) {
    ShapeSpec p = spec0;
    for (size_t a = 0; a < 3; ++a) p.offset[a] = x.sub(p.offset[a], com[a]);  // from the centre of mass
    const Rational m = x.mul(spec.mass, x.div(volumeOf(p, x), totalVolume));
    Rational own[3];
    if (p.type == ShapeType::Sphere) {
      own[0] = own[1] = own[2] = x.mul(x.mul(m, x.mul(p.radius, p.radius)), Rational{2, 5});
    } else {
      const Rational h2[3] = {x.mul(p.halfExtents[0], p.halfExtents[0]), x.mul(p.halfExtents[1], p.halfExtents[1]),
                              x.mul(p.halfExtents[2], p.halfExtents[2])};
      // m/12 (dy^2 + dz^2) with d = 2h, i.e. m/3 (hy^2 + hz^2)
      for (int a = 0; a < 3; ++a) own[a] = x.mul(x.div(m, Rational{3, 1}), x.add(h2[(a + 1) % 3], h2[(a + 2) % 3]));
    }
    // Parallel axis: I_a += m (o_b^2 + o_c^2) for the two other axes b, c.
    for (int a = 0; a < 3; ++a) {
      const Rational& ob = p.offset[size_t((a + 1) % 3)];
      const Rational& oc = p.offset[size_t((a + 2) % 3)];
      inertia[a] = x.add(inertia[a], x.add(own[a], x.mul(m, x.add(x.mul(ob, ob), x.mul(oc, oc)))));
    }
    BodyPart<S> part;
    part.type = p.type;
    part.radius = toS<S>(p.radius);
    part.halfExtents = toS3<S>(p.halfExtents);
    part.offset = toS3<S>(p.offset);
    part.boundingRadius = p.type == ShapeType::Sphere ? part.radius : part.halfExtents.norm();
    b.boundingRadius = std::max(b.boundingRadius, part.offset.norm() + part.boundingRadius);
    b.parts.push_back(part);
  }
  b.invMass = toS<S>(x.div(Rational{1, 1}, spec.mass));
  for (int a = 0; a < 3; ++a) {
    b.invInertiaLocal[a] = toS<S>(x.div(Rational{1, 1}, inertia[a]));
    b.inertiaLocal[a] = toS<S>(inertia[a]);
  }
  b.linearDampingPerTick = toS<S>(deterministicPow(spec.linearDamping, dt));
  b.angularDampingPerTick = toS<S>(deterministicPow(spec.angularDamping, dt));
  b.restitution = toS<S>(spec.restitution);
  b.friction = toS<S>(spec.friction);
  b.mower = spec.mower;
  b.canSleep = spec.canSleep;
  b.orientation = normalizedQuat(Quat<S>(toS<S>(spec.orientation[0]), toS<S>(spec.orientation[1]),
                                         toS<S>(spec.orientation[2]), toS<S>(spec.orientation[3])));
  b.centreOfMassLocal = Vec3<S>(toS<S>(com[0]), toS<S>(com[1]), toS<S>(com[2]));
  b.position = toS3<S>(spec.position) + b.orientation.toRotationMatrix() * b.centreOfMassLocal;
  b.velocity = toS3<S>(spec.velocity);
  b.angularVelocity = toS3<S>(spec.angularVelocity);
  b.updateDerived();
  return b;
}

#define SG_INSTANTIATE(S)                                                                                      \
  template RigidBody<S> makeBody<S>(const BodySpec&, const Rational&, const std::string&, const std::string&); \
  template Quat<S> normalizedQuat<S>(const Quat<S>&);
SG_FOR_EACH_SCALAR(SG_INSTANTIATE)
#undef SG_INSTANTIATE
}  // namespace sg
