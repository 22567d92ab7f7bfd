#include "sim/collision/body_particles.h"

#include <algorithm>
#include <type_traits>
#include <vector>

#include "sim/collision/grass_candidates.h"
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

namespace {

/// Half-side (m) of the cube around a part's centre outside which no particle is pushed. A sphere:
/// its radius. A box: its bounding radius with a slack (an eighth of it and 4 mm) for the rounding
/// of the rotation in the exact test (relative errors of a few 1e-5 in Fx16), so the pre-test
/// never refuses a particle the box test would push.
template <class S>
S candidateReach(const BodyPart<S>& shape) {
  if (shape.type == ShapeType::Sphere) return shape.radius;
  return shape.boundingRadius + shape.boundingRadius / S(8) + S(1) / S(256);
}

}  // namespace

template <class S>
GrassPushers<S> prepareGrassPushers(const std::vector<RigidBody<S>>& bodies, const ParticleGrid& grid,
                                    const BodyParticleSettings<S>& settings) {
  GrassPushers<S> out;
  const std::vector<ParticleRange> ranges = particleRanges(bodies, grid, settings);
  out.parts.reserve(ranges.size());
  size_t rangeIndex = 0;
  for (size_t bodyIndex = 0; bodyIndex < bodies.size(); ++bodyIndex) {
    const RigidBody<S>& body = bodies[bodyIndex];
    const S share = settings.particleInvMass / (settings.particleInvMass + body.invMass);
    for (size_t part = 0; part < body.parts.size(); ++part, ++rangeIndex) {
      const BodyPart<S>& shape = body.parts[part];
      out.parts.push_back(GrassPusher<S>{body.partPose(part), &shape, share, ranges[rangeIndex],
                                         grid.window.storageColumn(ranges[rangeIndex].a0), candidateReach(shape),
                                         int32_t(bodyIndex)});
    }
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

/// Pushes one particle out of a sphere or box part; returns whether it was inside. Called only for
/// particles within the part's candidateReach (withinReach).
/// Held tips (model blade; thesis and pbd with tipContact hold), nearest-face normal: the box face nearest the particle
/// among those its blade can reach out through (exit point within `reach` of its root); the nearest face when none can.
/// A blade under a box dropped on it cannot reach the top face just above its tip: it goes out through a side or is
/// pressed flat through the bottom, instead of being pushed up and pulled back in by its rod every tick.
template <class S>
int reachableFaceAxis(const ParticleArrays<S>& pa, size_t i, const Vec3<S>& local, const Vec3<S>& h,
                      const Pose<S>& pose, S share, S reach, S* gap, S* side) {
  const int nearest = nearestFaceAxis(local, h, gap, side);
  const Vec3<S> root(pa.anchorX[i], pa.anchorY[i], pa.anchorZ[i]);
  bool found = false;
  int axis = nearest;
  for (int k = 0; k < 3; ++k)
    for (const S sign : {S(-1), S(1)}) {
      const S g = h[k] - sign * local[k];  // > 0: the particle is inside
      if (found && g >= *gap) continue;
      Vec3<S> face = Vec3<S>::Zero();
      face[k] = sign;
      const Vec3<S> exit = pose.position + pose.rotation * (local + face * (g * share)) - root;
      if (exit.x() * exit.x() + exit.y() * exit.y() + exit.z() * exit.z() > reach * reach) continue;
      found = true;
      axis = k;
      *gap = g;
      *side = sign;
    }
  if (!found) nearestFaceAxis(local, h, gap, side);
  return axis;
}

/// `reach`: tips held as contacts (holdTips), the rod length (0: the nearest face whatever it is).
template <class S>
bool pushOut(ParticleArrays<S>& pa, size_t i, const GrassPusher<S>& pusher, BoxParticleNormal boxNormal, S reach) {
  const Vec3<S> p(pa.px[i], pa.py[i], pa.pz[i]);
  const BodyPart<S>& shape = *pusher.shape;
  const Pose<S>& pose = pusher.pose;
  if (shape.type == ShapeType::Sphere) {
    const Vec3<S> d = p - pose.position;
    // Most candidates inside the reach cube rest on the ball's surface, just outside it: decided
    // without the square root, exactly as length3 >= radius would (so dist < radius below).
    if (length3AtLeast(d.x(), d.y(), d.z(), shape.radius)) return false;
    const S dist = length3(d.x(), d.y(), d.z());
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
  const int axis = reach > S(0) && boxNormal == BoxParticleNormal::NearestFace
                       ? reachableFaceAxis(pa, i, local, h, pose, pusher.share, reach, &gap, &side)
                       : nearestFaceAxis(local, h, &gap, &side);
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

/// Held tips: a push straight down (an `up` box normal, a ball centred over the tip) moves the
/// tip toward its root; the rod's projection would put it back where it was, inside the body, and
/// store the undoing as an upward velocity. The blade bends instead: the tip keeps the height the
/// push gave it and goes to the rod's length sideways, in the direction it leans (standing
/// straight: away from the body's centre; under it: +x).
template <class S>
void bendUnderVerticalPush(ParticleArrays<S>& pa, size_t i, const Vec3<S>& bodyCentre, S rod) {
  using std::sqrt;
  const S ax = pa.anchorX[i], ay = pa.anchorY[i], az = pa.anchorZ[i];
  const S height = std::clamp(pa.py[i] - ay, S(0), rod);
  S leanX = pa.px[i] - ax, leanZ = pa.pz[i] - az;
  S lean = length3(leanX, S(0), leanZ);
  if (lean == S(0)) {
    leanX = ax - bodyCentre.x();
    leanZ = az - bodyCentre.z();
    lean = length3(leanX, S(0), leanZ);
  }
  if (lean == S(0)) {
    leanX = S(1);
    leanZ = S(0);
    lean = S(1);
  }
  const S reach = sqrt(rod * rod - height * height) / lean;
  pa.px[i] = ax + leanX * reach;
  pa.py[i] = ay + height;
  pa.pz[i] = az + leanZ * reach;
}

/// Held tips: a pushed tip goes straight back to its rod's length (above its root) here, not in
/// the next tick's projection, which would turn the whole push into velocity (PBD's v += correction
/// / dt): a box pushing a tip 0.3 m out through a face sent it off at 18 m/s.
template <class S>
void backToTheRod(ParticleArrays<S>& pa, size_t i, S rod) {
  const S ax = pa.anchorX[i], ay = pa.anchorY[i], az = pa.anchorZ[i];
  const S ex = pa.px[i] - ax, ey = pa.py[i] > ay ? pa.py[i] - ay : S(0), ez = pa.pz[i] - az;
  const S len = length3(ex, ey, ez);
  if (len == S(0)) return;  // at the root: the projection stands it up
  const S scale = rod / len;
  pa.px[i] = ax + ex * scale;
  pa.py[i] = ay + ey * scale;
  pa.pz[i] = az + ez * scale;
}

/// Held tips (holdTips), after a push moved particle i from `before`: a vertical push bends the blade
/// (bendUnderVerticalPush), any other goes back to the rod (backToTheRod), the velocity into the body goes (the body
/// stops the tip, as a contact would: the spring would otherwise build an inward velocity tick after tick), and the tip
/// is trampled.
template <class S>
void holdTip(ParticleArrays<S>& pa, size_t i, const Vec3<S>& before, const Vec3<S>& bodyCentre, S rod) {
  if (!pa.trample.empty()) pa.trample[i] = S(1);
  if (pa.px[i] == before.x() && pa.pz[i] == before.z())
    bendUnderVerticalPush(pa, i, bodyCentre, rod);
  else
    backToTheRod(pa, i, rod);
  const Vec3<S> push = Vec3<S>(pa.px[i], pa.py[i], pa.pz[i]) - before;
  const S length = length3(push.x(), push.y(), push.z());
  if (length == S(0)) {  // pinned (pressed flat, the ground below): held still
    pa.vx[i] = pa.vy[i] = pa.vz[i] = S(0);
    return;
  }
  const Vec3<S> n = push / length;
  const S into = pa.vx[i] * n.x() + pa.vy[i] * n.y() + pa.vz[i] * n.z();
  if (into >= S(0)) return;
  pa.vx[i] -= n.x() * into;
  pa.vy[i] -= n.y() * into;
  pa.vz[i] -= n.z() * into;
}

}  // namespace

namespace {

/// The columns firstColumn .. firstColumn + count - 1 of a toroidal row, as runs within one
/// 64-column word each, in order (the window wraps at most once): calls run(c0, c1) for
/// storage columns [c0, c1) (all in word c0 / 64), and stops at the first index it returns (>= 0).
template <class Run>
int64_t forEachWordRun(int64_t countX, int64_t firstColumn, int64_t count, Run&& run) {
  int64_t column = firstColumn;
  while (count > 0) {
    const int64_t end = std::min(countX, column + count);
    count -= end - column;
    for (int64_t c0 = column; c0 < end;) {
      const int64_t c1 = std::min(end, (c0 / 64 + 1) * 64);
      const int64_t stop = run(c0, c1);
      if (stop >= 0) return stop;
      c0 = c1;
    }
    column = 0;
  }
  return -1;
}

/// Whether four or more bits are set (no popcount instruction in the baseline x86-64 build).
inline bool atLeastFourBits(uint64_t bits) {
  for (int k = 0; k < 3; ++k) bits &= bits - 1;
  return bits != 0;
}

/// Whether a coordinate moved by `limit` or more from where it started (or so far that the
/// difference leaves the format: no fault is raised here, the caller treats it as moved).
template <class S>
bool movedAtLeast(S now, S start, S limit) {
  if constexpr (ScalarTraits<S>::isFixed) {
    decltype(now.raw()) d;
    if (__builtin_sub_overflow(now.raw(), start.raw(), &d)) return true;
    using U = std::make_unsigned_t<decltype(d)>;
    const U magnitude = d < 0 ? U(0) - U(d) : U(d);  // no negation of the most negative value
    return limit.raw() <= 0 || magnitude >= U(limit.raw());
  } else {
    return !(abs(now - start) < limit);
  }
}

}  // namespace

template <class S>
int64_t pushParticlesOutOfBodies(ParticleArrays<S>& pa, const ParticleGrid& grid, const GrassPushers<S>& pushers,
                                 const BodyParticleSettings<S>& s, int64_t rowBegin, int64_t rowEnd,
                                 int64_t* pushedPerBody, ParticleKernel kernel) {
  using T = ScalarTraits<S>;
  // Scratch reused across calls: the rows' height marks (grass_candidates.h, fixed-point only),
  // which particles of the row moved and where they stood before their first push, and which of
  // them left the ranges.
  thread_local std::vector<uint64_t> marks, escaped, moved;
  thread_local std::vector<S> startX, startZ;
  const bool useMarks = T::isFixed && s.heightMarks;
  const bool vector = T::isFixed && kernel == ParticleKernel::Avx2;
  const bool ranged = s.broadphase == ParticleBroadphase::Grid;
  const size_t words = size_t((grid.countX + 63) / 64);
  if (useMarks) marks.resize(words);
  if (ranged) {
    escaped.resize(words);
    moved.resize(words);
    startX.resize(size_t(grid.countX));
    startZ.resize(size_t(grid.countX));
  }
  // One particle pushed out of a part it is within reach of; false where the stage must stop.
  const auto pushInside = [&](size_t i, const GrassPusher<S>& pusher) {
    const Vec3<S> before(pa.px[i], pa.py[i], pa.pz[i]);
    if (!pushOut(pa, i, pusher, s.boxNormal, s.holdTips ? s.rodLength : S(0))) return true;
    if (pushedPerBody) ++pushedPerBody[pusher.body];
    if (s.holdTips) holdTip(pa, i, before, pusher.pose.position, s.rodLength);
    // The velocities too: holdTip takes the normal part off a tip's velocity, which can raise one
    // component (the device's push checks all six, as here).
    return !T::faultPending() && T::inStateRange(pa.px[i]) && T::inStateRange(pa.py[i]) && T::inStateRange(pa.pz[i]) &&
           T::inStateRange(pa.vx[i]) && T::inStateRange(pa.vy[i]) && T::inStateRange(pa.vz[i]);
  };
  // Storage rows [rowBegin, rowEnd): each holds one lattice row of the window. Per particle the
  // parts apply in (body, part) order, as the bucket keeps them: the same bits as any order of
  // rows, any thread count and either broad phase. A row's marks stay valid while its parts push:
  // an unmarked particle is outside every part's reach, so none moves it.
  for (int64_t row = rowBegin; row < rowEnd; ++row) {
    const int64_t b = grid.window.latticeRow(row) - pushers.originJ;
    const int64_t firstPart = pushers.rowStart[size_t(b)], endPart = pushers.rowStart[size_t(b + 1)];
    if (firstPart == endPart) continue;
    const size_t rowBase = size_t(row * grid.countX);
    if constexpr (T::isFixed) {
      if (useMarks) {
        HeightBand<S> band;
        for (int64_t k = firstPart; k < endPart; ++k) {
          const GrassPusher<S>& pusher = pushers.parts[size_t(pushers.byRow[size_t(k)])];
          band.add(pusher.pose.position.y(), pusher.candidateReach);
        }
        markHeightBand(&pa.py[rowBase], grid.countX, band, kernel, marks.data());
        // No particle in the band: none is within any part's reach (tall grass over lying bodies).
        if (std::all_of(marks.begin(), marks.end(), [](uint64_t w) { return w == 0; })) continue;
      }
    }
    bool anyEscaped = false;
    if (ranged) std::fill(moved.begin(), moved.end(), uint64_t(0));
    for (int64_t k = firstPart; k < endPart; ++k) {
      const int32_t part = pushers.byRow[size_t(k)];
      const GrassPusher<S>& pusher = pushers.parts[size_t(part)];
      const S cx = pusher.pose.position.x(), cy = pusher.pose.position.y(), cz = pusher.pose.position.z();
      const S reach = pusher.candidateReach;
      // The rare path, out of the hot loop: a particle inside the part.
      const auto pushAndFollow = [&](size_t i) {
        const size_t column = i - rowBase;
        const uint64_t bit = uint64_t(1) << (column % 64);
        const S x = pa.px[i], z = pa.pz[i];
        if (!pushInside(i, pusher)) return false;
        if (!ranged || (pa.px[i] == x && pa.pz[i] == z)) return true;
        if (!(moved[column / 64] & bit)) {  // its first push this tick: where it started
          moved[column / 64] |= bit;
          startX[column] = x;
          startZ[column] = z;
        }
        // The ranges allow for a particle within a rod of its anchor moved by less than the
        // largest radius this tick. A chain of pushes (bodies piled in a line) can carry it
        // further: then it meets every later part in order here, as brute force would, and the
        // row's later parts pass it by.
        if (!movedAtLeast(pa.px[i], startX[column], s.pushAllowance) &&
            !movedAtLeast(pa.pz[i], startZ[column], s.pushAllowance))
          return true;
        if (!anyEscaped) std::fill(escaped.begin(), escaped.end(), uint64_t(0));
        anyEscaped = true;
        escaped[column / 64] |= bit;
        for (size_t later = size_t(part) + 1; later < pushers.parts.size(); ++later) {
          const GrassPusher<S>& next = pushers.parts[later];
          const Vec3<S>& c = next.pose.position;
          if (withinReach(pa.px[i], pa.py[i], pa.pz[i], c.x(), c.y(), c.z(), next.candidateReach) &&
              !pushInside(i, next))
            return false;
        }
        return true;
      };
      const int64_t fault = forEachWordRun(
          grid.countX, pusher.firstColumn, pusher.range.a1 - pusher.range.a0 + 1,
          [&](int64_t c0, int64_t c1) -> int64_t {
            const int64_t word = c0 / 64;
            uint64_t bits = useMarks ? marks[size_t(word)] : ~uint64_t(0);
            bits &= (~uint64_t(0) << (c0 - word * 64)) & (~uint64_t(0) >> (word * 64 + 64 - c1));
            if (anyEscaped) bits &= ~escaped[size_t(word)];  // already through every later part
            if (bits == 0) return -1;
            // Four or more to test: the vector pre-test of the run (the same answers, fixed-point).
            bool tested = false;
            if constexpr (T::isFixed) {
              uint64_t inside = 0;
              const size_t first = rowBase + size_t(c0);
              if (vector && atLeastFourBits(bits) &&
                  withinReachMask(&pa.px[first], &pa.py[first], &pa.pz[first], int(c1 - c0), pusher.pose.position,
                                  reach, &inside)) {
                bits &= inside << (c0 - word * 64);
                tested = true;
              }
            }
            for (; bits != 0; bits &= bits - 1) {
              const size_t i = rowBase + size_t(word * 64 + __builtin_ctzll(bits));
              if ((tested || withinReach(pa.px[i], pa.py[i], pa.pz[i], cx, cy, cz, reach)) && !pushAndFollow(i))
                return int64_t(i);
            }
            return -1;
          });
      if (fault >= 0) return fault;
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
                                            const BodyParticleSettings<S>&, int64_t, int64_t, int64_t*,      \
                                            ParticleKernel);
SG_FOR_EACH_SCALAR(SG_INSTANTIATE)
#undef SG_INSTANTIATE
}  // namespace sg
