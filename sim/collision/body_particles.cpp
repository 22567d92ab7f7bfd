#include "sim/collision/body_particles.h"

#include <algorithm>

#include "sim/math/scalar_ops.h"

namespace sg {

template <class S>
std::vector<ParticleRange> particleRanges(const std::vector<RigidBody<S>>& bodies, const ParticleGrid& grid,
                                          const BodyParticleSettings<S>& s) {
  std::vector<ParticleRange> out;
  for (const RigidBody<S>& body : bodies)
    for (size_t p = 0; p < body.parts.size(); ++p) {
      ParticleRange r;
      // Lattice particle coordinates, clipped to the held window.
      const LatticeWindow& w = grid.window;
      if (s.broadphase == ParticleBroadphase::Brute) {
        r = {w.originI, w.endI() - 1, w.originJ, w.endJ() - 1};
      } else {
        const Vec3<S> c = body.partPose(p).position;
        const S reach = body.parts[p].boundingRadius + s.margin;
        // floorOfProduct: the index may exceed the scalar's range (fx16 far corners) though the
        // coordinate difference does not (coordinates are within a quarter of the range).
        const S inv = s.invParticleSpacing;
        r.a0 = std::max<int64_t>(w.originI, floorOfProduct(S(c.x() - reach - s.anchorOriginX), inv));
        r.a1 = std::min<int64_t>(w.endI() - 1, floorOfProduct(S(c.x() + reach - s.anchorOriginX), inv) + 1);
        r.b0 = std::max<int64_t>(w.originJ, floorOfProduct(S(c.z() - reach - s.anchorOriginZ), inv));
        r.b1 = std::min<int64_t>(w.endJ() - 1, floorOfProduct(S(c.z() + reach - s.anchorOriginZ), inv) + 1);
      }
      out.push_back(r);
    }
  return out;
}

template <class S>
int64_t pushParticlesOutOfBodies(ParticleArrays<S>& pa, const ParticleGrid& grid,
                                 const std::vector<RigidBody<S>>& bodies, const std::vector<ParticleRange>& ranges,
                                 const BodyParticleSettings<S>& s, int64_t rowBegin, int64_t rowEnd,
                                 int64_t* pushedPerBody) {
  using T = ScalarTraits<S>;
  size_t rangeIndex = 0;
  for (size_t bodyIndex = 0; bodyIndex < bodies.size(); ++bodyIndex) {
    const RigidBody<S>& body = bodies[bodyIndex];
    const S share = s.particleInvMass / (s.particleInvMass + body.invMass);
    for (size_t part = 0; part < body.parts.size(); ++part, ++rangeIndex) {
      const ParticleRange& r = ranges[rangeIndex];
      const BodyPart<S>& shape = body.parts[part];
      const Pose<S> pose = body.partPose(part);
      // Storage rows [rowBegin, rowEnd): each holds one lattice row of the window.
      for (int64_t row = rowBegin; row < rowEnd; ++row) {
        const int64_t b = grid.window.latticeRow(row);
        if (b < r.b0 || b > r.b1) continue;
        int64_t column = grid.window.storageColumn(r.a0);
        for (int64_t a = r.a0; a <= r.a1; ++a, column = column + 1 == grid.countX ? 0 : column + 1) {
          const size_t i = size_t(row * grid.countX + column);
          const Vec3<S> p(pa.px[i], pa.py[i], pa.pz[i]);
          if (shape.type == ShapeType::Sphere) {
            const Vec3<S> d = p - pose.position;
            if (abs(d.x()) >= shape.radius || abs(d.y()) >= shape.radius || abs(d.z()) >= shape.radius) continue;
            const S dist = length3(d.x(), d.y(), d.z());
            if (dist >= shape.radius) continue;
            const Vec3<S> n = dist == S(0) ? Vec3<S>(Vec3<S>::UnitY()) : Vec3<S>(d / dist);
            const Vec3<S> moved = p + n * ((shape.radius - dist) * share);
            if (pushedPerBody) ++pushedPerBody[bodyIndex];
            pa.px[i] = moved.x();
            pa.py[i] = moved.y();
            pa.pz[i] = moved.z();
          } else {
            const Vec3<S> local = pose.toLocal(p);
            const Vec3<S>& h = shape.halfExtents;
            if (abs(local.x()) >= h.x() || abs(local.y()) >= h.y() || abs(local.z()) >= h.z()) continue;
            S gap, side;
            const int axis = nearestFaceAxis(local, h, &gap, &side);
            if (pushedPerBody) ++pushedPerBody[bodyIndex];
            if (s.boxNormal == BoxParticleNormal::Up) {
              pa.py[i] -= gap * share;
            } else {
              Vec3<S> face = Vec3<S>::Zero();
              face[axis] = side;
              const Vec3<S> moved = p + (pose.rotation * face) * (gap * share);
              pa.px[i] = moved.x();
              pa.py[i] = moved.y();
              pa.pz[i] = moved.z();
            }
          }
          if (T::faultPending() || !(T::isFinite(pa.px[i]) && T::isFinite(pa.py[i]) && T::isFinite(pa.pz[i])))
            return int64_t(i);
        }
      }
    }
  }
  return -1;
}

#define SG_INSTANTIATE(S)                                                                                              \
  template std::vector<ParticleRange> particleRanges(const std::vector<RigidBody<S>>&, const ParticleGrid&,            \
                                                     const BodyParticleSettings<S>&);                                  \
  template int64_t pushParticlesOutOfBodies(ParticleArrays<S>&, const ParticleGrid&, const std::vector<RigidBody<S>>&, \
                                            const std::vector<ParticleRange>&, const BodyParticleSettings<S>&,         \
                                            int64_t, int64_t, int64_t*);
SG_FOR_EACH_SCALAR(SG_INSTANTIATE)
#undef SG_INSTANTIATE
}  // namespace sg
