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
GrassPushers<S> prepareGrassPushers(const std::vector<RigidBody<S>>& bodies, const ParticleGrid& grid,
                                    const BodyParticleSettings<S>& settings) {
  GrassPushers<S> out;
  const std::vector<ParticleRange> ranges = particleRanges(bodies, grid, settings);
  size_t rangeIndex = 0;
  for (size_t bodyIndex = 0; bodyIndex < bodies.size(); ++bodyIndex) {
    const RigidBody<S>& body = bodies[bodyIndex];
    const S share = settings.particleInvMass / (settings.particleInvMass + body.invMass);
    for (size_t part = 0; part < body.parts.size(); ++part, ++rangeIndex)
      out.parts.push_back(
          GrassPusher<S>{body.partPose(part), &body.parts[part], share, ranges[rangeIndex], int32_t(bodyIndex)});
  }
  // Counting sort of (row, part) pairs by row: parts stay in (body, part) order within a row.
  const LatticeWindow& w = grid.window;
  out.originJ = w.originJ;
  const int64_t rows = w.sizeJ;
  out.rowStart.assign(size_t(rows + 1), 0);
  for (const GrassPusher<S>& p : out.parts)
    for (int64_t b = std::max(p.range.b0, w.originJ); b <= std::min(p.range.b1, w.endJ() - 1); ++b)
      ++out.rowStart[size_t(b - w.originJ + 1)];
  for (int64_t r = 0; r < rows; ++r) out.rowStart[size_t(r + 1)] += out.rowStart[size_t(r)];
  out.byRow.resize(size_t(out.rowStart[size_t(rows)]));
  std::vector<int64_t> next(out.rowStart.begin(), out.rowStart.end() - 1);
  for (size_t k = 0; k < out.parts.size(); ++k) {
    const ParticleRange& r = out.parts[k].range;
    for (int64_t b = std::max(r.b0, w.originJ); b <= std::min(r.b1, w.endJ() - 1); ++b)
      out.byRow[size_t(next[size_t(b - w.originJ)]++)] = int32_t(k);
  }
  return out;
}

namespace {

/// Pushes one particle out of a sphere or box part; returns whether it was inside.
template <class S>
bool pushOut(ParticleArrays<S>& pa, size_t i, const GrassPusher<S>& pusher, BoxParticleNormal boxNormal) {
  const Vec3<S> p(pa.px[i], pa.py[i], pa.pz[i]);
  const BodyPart<S>& shape = *pusher.shape;
  const Pose<S>& pose = pusher.pose;
  if (shape.type == ShapeType::Sphere) {
    const Vec3<S> d = p - pose.position;
    if (abs(d.x()) >= shape.radius || abs(d.y()) >= shape.radius || abs(d.z()) >= shape.radius) return false;
    const S dist = length3(d.x(), d.y(), d.z());
    if (dist >= shape.radius) return false;
    const Vec3<S> n = dist == S(0) ? Vec3<S>(Vec3<S>::UnitY()) : Vec3<S>(d / dist);
    const Vec3<S> moved = p + n * ((shape.radius - dist) * pusher.share);
    pa.px[i] = moved.x();
    pa.py[i] = moved.y();
    pa.pz[i] = moved.z();
    return true;
  }
  const Vec3<S> local = pose.toLocal(p);
  const Vec3<S>& h = shape.halfExtents;
  if (abs(local.x()) >= h.x() || abs(local.y()) >= h.y() || abs(local.z()) >= h.z()) return false;
  S gap, side;
  const int axis = nearestFaceAxis(local, h, &gap, &side);
  if (boxNormal == BoxParticleNormal::Up) {
    pa.py[i] -= gap * pusher.share;
  } else {
    Vec3<S> face = Vec3<S>::Zero();
    face[axis] = side;
    const Vec3<S> moved = p + (pose.rotation * face) * (gap * pusher.share);
    pa.px[i] = moved.x();
    pa.py[i] = moved.y();
    pa.pz[i] = moved.z();
  }
  return true;
}

}  // namespace

template <class S>
int64_t pushParticlesOutOfBodies(ParticleArrays<S>& pa, const ParticleGrid& grid, const GrassPushers<S>& pushers,
                                 const BodyParticleSettings<S>& s, int64_t rowBegin, int64_t rowEnd,
                                 int64_t* pushedPerBody) {
  using T = ScalarTraits<S>;
  // Storage rows [rowBegin, rowEnd): each holds one lattice row of the window. Per particle the
  // parts apply in (body, part) order, as the bucket keeps them: the same bits as any order of
  // rows, any thread count and either broad phase.
  for (int64_t row = rowBegin; row < rowEnd; ++row) {
    const int64_t b = grid.window.latticeRow(row) - pushers.originJ;
    for (int64_t k = pushers.rowStart[size_t(b)]; k < pushers.rowStart[size_t(b + 1)]; ++k) {
      const GrassPusher<S>& pusher = pushers.parts[size_t(pushers.byRow[size_t(k)])];
      const ParticleRange& r = pusher.range;
      const bool sphere = pusher.shape->type == ShapeType::Sphere;
      const S cx = pusher.pose.position.x(), cy = pusher.pose.position.y(), cz = pusher.pose.position.z();
      const S radius = pusher.shape->radius;
      int64_t column = grid.window.storageColumn(r.a0);
      for (int64_t a = r.a0; a <= r.a1; ++a, column = column + 1 == grid.countX ? 0 : column + 1) {
        const size_t i = size_t(row * grid.countX + column);
        // Most candidates of a sphere miss it on one axis (a tuft's tip above a ball in the
        // grass): rejected here, before pushOut's call and its loads of the pose.
        if (sphere &&
            (abs(S(pa.py[i] - cy)) >= radius || abs(S(pa.px[i] - cx)) >= radius || abs(S(pa.pz[i] - cz)) >= radius))
          continue;
        if (!pushOut(pa, i, pusher, s.boxNormal)) continue;
        if (pushedPerBody) ++pushedPerBody[pusher.body];
        if (T::faultPending() || !(T::isFinite(pa.px[i]) && T::isFinite(pa.py[i]) && T::isFinite(pa.pz[i])))
          return int64_t(i);
      }
    }
  }
  return -1;
}

#define SG_INSTANTIATE(S)                                                                                    \
  template std::vector<ParticleRange> particleRanges(const std::vector<RigidBody<S>>&, const ParticleGrid&,  \
                                                     const BodyParticleSettings<S>&);                        \
  template GrassPushers<S> prepareGrassPushers(const std::vector<RigidBody<S>>&, const ParticleGrid&,        \
                                               const BodyParticleSettings<S>&);                              \
  template int64_t pushParticlesOutOfBodies(ParticleArrays<S>&, const ParticleGrid&, const GrassPushers<S>&, \
                                            const BodyParticleSettings<S>&, int64_t, int64_t, int64_t*);
SG_FOR_EACH_SCALAR(SG_INSTANTIATE)
#undef SG_INSTANTIATE
}  // namespace sg
