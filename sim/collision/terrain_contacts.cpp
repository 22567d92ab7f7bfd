#include "sim/collision/terrain_contacts.h"

#include <algorithm>

namespace sg {
namespace {

/// m: how far a neighbour may lie above a contact plane through a vertex or edge of the ground
/// for that feature still to count as the ground's extreme point there: a lean of 1/1024 rad
/// over a cell, plus rounding (16 units of a fixed-point format; float and double well above
/// theirs at kilometre coordinates). A straight ridge line's own neighbours lie *on* such a plane
/// and a box resting on it rocks by far less than a milliradian, so it must count; and a crease
/// bent by less than a margin must still count, or the wedge above it between its faces' regions
/// has no contact at all (a ball fell through a 0.2 mm ridge when edges had to be convex by
/// 1/4096 m). Against ghosts it is tight: a side face or a rocking box is leaning by far more.
template <class S>
S convexMargin(const Terrain<S>& t) {
  S rounding;
  if constexpr (ScalarTraits<S>::isFixed) {
    rounding = S::fromRaw(16);
  } else if constexpr (sizeof(S) == sizeof(float)) {
    rounding = S(1e-4f);
  } else {
    rounding = S(1e-9);
  }
  return rounding + t.cellSize() / S(1024);
}

/// m: a vertex whose six triangles agree in height steps to this is planar (no feature).
template <class S>
S planarMargin() {
  return S(1) / S(4096);
}

/// A vertex of the ground grid in world coordinates (any indices: beyond the map the edge
/// samples extend).
template <class S>
Vec3<S> vertexAt(const Terrain<S>& t, int64_t ix, int64_t iz) {
  return Vec3<S>(t.sampleX(ix), t.heightOfSample(ix, iz), t.sampleZ(iz));
}

/// The six neighbours of a vertex in the triangulation (cells split from (ix+1, iz) to (ix, iz+1)).
constexpr int kNeighbours[6][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, -1}, {-1, 1}};

/// Whether no neighbour of vertex (ix, iz) lies more than the margin above the plane through p
/// with normal n: the vertex is the ground's extreme point towards n (a peak, or a point of a
/// ridge line, or planar ground touched straight along its normal).
template <class S>
bool vertexIsExtreme(const Terrain<S>& t, int64_t ix, int64_t iz, const Vec3<S>& p, const Vec3<S>& n) {
  const S margin = convexMargin(t);
  for (const auto& o : kNeighbours)
    if ((vertexAt(t, ix + o[0], iz + o[1]) - p).dot(n) > margin) return false;
  return true;
}

/// Whether the six triangles around vertex (ix, iz) lie in one plane (to the margin): the height
/// steps to opposite neighbours agree. Such a vertex is no feature at all; its faces' contacts
/// (a box's corners, a sphere's face foot) carry the body. A box nearly flat on planar ground
/// otherwise took every sample under it as a contact along the box's own face normal, tilted
/// with the box's rocking: sideways pushes that turned a sliding box 5 cm off its line.
template <class S>
bool vertexIsPlanar(const Terrain<S>& t, int64_t ix, int64_t iz) {
  const S h = t.heightOfSample(ix, iz), margin = planarMargin<S>();
  const S stepX = t.heightOfSample(ix + 1, iz) - h, stepZ = t.heightOfSample(ix, iz + 1) - h;
  return abs(S(h - t.heightOfSample(ix - 1, iz) - stepX)) <= margin &&
         abs(S(h - t.heightOfSample(ix, iz - 1) - stepZ)) <= margin &&
         abs(S(t.heightOfSample(ix + 1, iz - 1) - h - stepX + stepZ)) <= margin &&
         abs(S(t.heightOfSample(ix - 1, iz + 1) - h + stepX - stepZ)) <= margin;
}

/// Feature keys for warm starting (contact.h): the kind in 3 bits, the cell's indices (mod 2^14)
/// above it. Unique within any body's reach.
enum TerrainFeature : uint32_t { kLowerFace, kUpperFace, kEdgeAlongX, kEdgeAlongZ, kDiagonalEdge, kVertex };
uint32_t featureKey(TerrainFeature kind, int64_t ix, int64_t iz) {
  return uint32_t(kind) | (uint32_t(uint64_t(ix)) & 0x3fffu) << 3 | (uint32_t(uint64_t(iz)) & 0x3fffu) << 17;
}

/// The unit normal of a ground triangle from its slopes dh/dx, dh/dz (as Terrain::normalAt).
template <class S>
Vec3<S> faceNormal(S dhdx, S dhdz) {
  const S len = length3(dhdx, S(1), dhdz);
  return Vec3<S>(-dhdx / len, S(1) / len, -dhdz / len);
}

/// One contact of a sphere (centre ca, radius ra) along `normal` at `dist` from the ground.
template <class S>
void addSphereContact(int32_t a, const Vec3<S>& ca, S ra, uint32_t feature, const Vec3<S>& normal, S dist,
                      std::vector<Contact<S>>& out) {
  Contact<S> c;
  c.bodyA = a;
  c.bodyB = kTerrainBody;
  c.featureB = feature;
  c.normal = normal;
  c.penetration = ra - dist;
  // Speculative: the sphere's lowest point, not the ground far below; deep (the centre under the
  // ground): no farther than r from the centre either, not the ground far above. A longer arm is
  // a larger angular term (a small ball 13 m under a hill overflowed fx16's r x n . I^-1 (r x n)).
  c.point = ca - normal * maxS(minS(dist, ra), S(-ra));
  out.push_back(c);
}

/// The plane under the centre (flat ground, or a centre below a heightmap's ground).
template <class S>
int spherePlaneUnderCentre(int32_t a, const Vec3<S>& ca, S ra, const Terrain<S>& terrain, std::vector<Contact<S>>& out,
                           S speculative) {
  const S h = terrain.heightAt(ca.x(), ca.z());
  if (ca.y() - h >= ra + ra + speculative) return 0;  // far above: not even a steep slope can touch
  Vec3<S> n;
  terrain.normalAt(ca.x(), ca.z(), &n.x(), &n.y(), &n.z());
  const S dist = (ca.y() - h) * n.y();  // to the plane through (x, h, z)
  if (dist >= ra + speculative) return 0;
  addSphereContact(a, ca, ra, 0, n, dist, out);  // the only contact then: feature 0
  return 1;
}

/// Edge a-b of the ground against centre c: the closest point strictly inside the edge (its ends
/// are the vertices' business), within `reach`, where the third corners f1, f2 of the edge's two
/// triangles lie no more than the margin above the plane through that point normal to c - p: a
/// convex crease, however gentle (the centre is then in the wedge between its faces' regions,
/// which only the edge covers). Over planar or concave ground c - p leans towards one corner,
/// which then lies above that plane: the faces hold the body there.
template <class S>
bool edgeContact(const Terrain<S>& t, const Vec3<S>& c, S reach, const Vec3<S>& a, const Vec3<S>& b, int64_t f1x,
                 int64_t f1z, int64_t f2x, int64_t f2z, Vec3<S>* normal, S* dist) {
  const Vec3<S> ab = b - a;
  const S along = (c - a).dot(ab), length2 = ab.dot(ab);
  if (!(along > S(0)) || !(along < length2)) return false;
  const Vec3<S> p = a + ab * (along / length2);
  const Vec3<S> d = c - p;
  if (abs(d.x()) >= reach || abs(d.y()) >= reach || abs(d.z()) >= reach) return false;
  *dist = length3(d.x(), d.y(), d.z());
  if (!(*dist < reach) || *dist == S(0)) return false;
  *normal = d / *dist;
  const S margin = convexMargin(t);
  return (vertexAt(t, f1x, f1z) - p).dot(*normal) < margin && (vertexAt(t, f2x, f2z) - p).dot(*normal) < margin;
}

/// Face (v, slopes) of cell (ix, iz): the centre's foot on its plane when that foot lies in the
/// triangle itself (by heightAt's rule, so a foot on a shared edge belongs to one face only).
template <class S>
bool faceContact(const Terrain<S>& t, const Vec3<S>& c, S reach, const Vec3<S>& v, S dhdx, S dhdz, int64_t ix,
                 int64_t iz, bool lower, Vec3<S>* normal, S* dist) {
  *normal = faceNormal(dhdx, dhdz);
  *dist = (c - v).dot(*normal);
  // Behind the face's plane with the centre above the ground (a centre below it takes the plane
  // under it instead): the far face of a steep ridge, whose foot lies inside it although the
  // ball is on the other side. Its row, a deep overlap, threw a ball flying away from a ridge 1.6 m
  // off to (-12.6, 50.4) m/s, and pulled a ball resting 1.7 cm from a steep blade into it and up
  // to 6.5 m (an independent review, 2026-11-28). The crest's edge and vertex rows hold there.
  if (!(*dist < reach) || *dist < S(0)) return false;
  const Vec3<S> foot = c - *normal * *dist;
  int64_t fx = 0, fz = 0;
  bool fLower = false;
  t.triangleAt(foot.x(), foot.z(), &fx, &fz, &fLower);
  return fx == ix && fz == iz && fLower == lower;
}

/// Whether a face's plane is the ground where a path (from c, a sphere of radius ra, `gap` from
/// the plane along `normal`) first comes within the sweep's margin of it. A planar slope is many
/// triangles, and a ball flying at it obliquely meets a neighbour of the triangle under its foot:
/// that face's row is real (without it the ball went up to the slop into the slope before the
/// post-solve sweep caught it). Over a ridge the plane runs on in the air above the falling
/// ground: a ghost.
template <class S>
bool planeIsGroundAhead(const Terrain<S>& terrain, const Vec3<S>& c, S ra, const Vec3<S>& normal, S gap,
                        const PairSweep<S>& sweep) {
  const S closing = -dot3(sweep.displacement, normal);  // m this tick towards the plane
  if (!(closing > S(0))) return false;
  // The fraction of the tick to that point, at most 1 (divided only below 1: a slow approach's
  // quotient leaves fx16's range).
  const S ahead = gap - ra - sweep.margin;
  const S t = ahead < closing ? S(ahead / closing) : S(1);
  const Vec3<S> foot = c + sweep.displacement * t - normal * S(gap - closing * t);
  return abs(S(terrain.heightAt(foot.x(), foot.z()) - foot.y())) <= sweep.margin;
}

/// A box corner's speculative row against the triangle under it is a ghost when the corner's path
/// this tick never comes within the margin of that triangle and the plane is not the ground where
/// the path nears it (as a sphere's face rows: collideSphereTerrain).
template <class S>
bool cornerIsGhost(const Terrain<S>& terrain, const Vec3<S>& p, const Vec3<S>& normal, S gap,
                   const PairSweep<S>& sweep) {
  if (!(gap > sweep.margin)) return false;
  int64_t ix = 0, iz = 0;
  bool lower = false;
  terrain.triangleAt(p.x(), p.z(), &ix, &iz, &lower);
  const Vec3<S> v10 = vertexAt(terrain, ix + 1, iz), v01 = vertexAt(terrain, ix, iz + 1);
  const Vec3<S> v0 = lower ? vertexAt(terrain, ix, iz) : vertexAt(terrain, ix + 1, iz + 1);
  const S nearest = leastDistanceAlong(
      p, sweep.displacement, [&](const Vec3<S>& q) { return pointTriangleDistance(q, v0, v10, v01, normal); });
  return nearest > sweep.margin && !planeIsGroundAhead(terrain, p, S(0), normal, gap, sweep);
}

/// Most cells a sphere's reach may span along an axis before it takes the plane under its centre
/// instead (a fast or huge sphere over fine cells: the cost is the square of this).
constexpr int64_t kMaxReachCells = 64;

/// Most cells a box's bounding sphere may span along an axis for its vertex scan (a 5 m box over
/// 5 cm cells is 200): beyond it the box meets the ground with its corners only.
constexpr int64_t kMaxBoxCells = 256;

/// The face of a box (0 to 5: +x, -x, +y, -y, +z, -z in its own frame) through which the ground
/// pushes a feature out with the least depth, among the faces whose inward normal n (world) the
/// feature can push along (`pushable(n)`); -1 when none can. depthBelow(axis, side) is the
/// feature's depth below that face (m).
template <class S, class DepthBelow, class Pushable>
int shallowestFace(const Pose<S>& pose, const DepthBelow& depthBelow, const Pushable& pushable, S* depth,
                   Vec3<S>* normal) {
  int best = -1;
  for (int face = 0; face < 6; ++face) {
    const int axis = face / 2;
    const S side = face % 2 == 0 ? S(1) : S(-1);
    const S d = depthBelow(axis, side);
    if (best >= 0 && !(d < *depth)) continue;
    Vec3<S> outward = Vec3<S>::Zero();
    outward[axis] = side;
    const Vec3<S> n = -(pose.rotation * outward);  // the ground pushes the box away from that face
    if (!pushable(n)) continue;
    best = face;
    *depth = d;
    *normal = n;
  }
  return best;
}

/// The part [t0, t1] of segment la + t (lb - la), t in [0, 1], strictly inside the box of half
/// extents ha (box coordinates); false when none is.
template <class S>
bool clipSegmentToBox(const Vec3<S>& la, const Vec3<S>& lb, const Vec3<S>& ha, S* t0, S* t1) {
  *t0 = S(0);
  *t1 = S(1);
  for (int k = 0; k < 3; ++k) {
    const S d = lb[k] - la[k];
    if (d == S(0)) {
      if (!(abs(la[k]) < ha[k])) return false;
      continue;
    }
    S enter = (-ha[k] - la[k]) / d, leave = (ha[k] - la[k]) / d;
    if (d < S(0)) std::swap(enter, leave);
    *t0 = maxS(*t0, enter);
    *t1 = minS(*t1, leave);
    if (!(*t0 < *t1)) return false;
  }
  return true;
}

/// Ground edge (ai, aj)-(bi, bj), whose two triangles' third corners are f1 and f2, against a box
/// (step 3 of collideBoxTerrain): where the edge is a convex crease and passes through the box with
/// neither end inside, the part inside is pushed out through the face that takes the least depth
/// among those the crease can push (the face's inward normal, made normal to the edge, lies in the
/// crease's wedge: both third corners lie no more than the margin above the plane through the edge
/// normal to it). One contact at each end of that part, each at its own depth. A planar crease
/// (the two triangles in one plane) is no feature, as vertexIsPlanar's vertices are not: boxes
/// slide over planar heightmaps on their corners alone; nor is a valley's.
template <class S>
int creaseThroughBox(int32_t body, const Vec3<S>& ha, const Pose<S>& pose, S reach, const Vec3<S>& shift,
                     const Terrain<S>& t, int64_t ai, int64_t aj, int64_t bi, int64_t bj, int64_t f1i, int64_t f1j,
                     int64_t f2i, int64_t f2j, uint32_t featureB, std::vector<Contact<S>>& out) {
  const Vec3<S> a = vertexAt(t, ai, aj), b = vertexAt(t, bi, bj);
  // Both ends beyond the box's bounding sphere on one side of an axis (`reach`: its radius and a
  // millimetre for rounding): the edge misses the box, and most edges of the scan do, before the
  // two rotations below (the hills drops took 1.8 s with them for every edge, 1.1 s without edges).
  for (int k = 0; k < 3; ++k) {
    const S da = a[k] - pose.position[k], db = b[k] - pose.position[k];
    if ((da >= reach && db >= reach) || (da <= -reach && db <= -reach)) return 0;
  }
  const Vec3<S> la = pose.toLocal(a), lb = pose.toLocal(b);
  for (int k = 0; k < 3; ++k)  // both ends beyond one face: the common case, no division
    if ((la[k] >= ha[k] && lb[k] >= ha[k]) || (la[k] <= -ha[k] && lb[k] <= -ha[k])) return 0;
  const auto inside = [&](const Vec3<S>& l) {
    return abs(l.x()) < ha.x() && abs(l.y()) < ha.y() && abs(l.z()) < ha.z();
  };
  if (inside(la) || inside(lb)) return 0;  // step 2's vertex contacts hold it
  const Vec3<S> f1 = vertexAt(t, f1i, f1j), f2 = vertexAt(t, f2i, f2j);
  // The third corners are symmetric about the edge's midpoint: the crease is convex (a ridge,
  // which has a wedge of normals) when they lie lower on average than the edge, planar when level
  // with it, and concave (a valley: no normal at all, the ground is solid below) when higher.
  if (!(f1.y() + f2.y() < a.y() + b.y() - planarMargin<S>())) return 0;
  S t0, t1;
  if (!clipSegmentToBox(la, lb, ha, &t0, &t1)) return 0;
  const Vec3<S> l0 = la + (lb - la) * t0, l1 = la + (lb - la) * t1;
  const Vec3<S> edge = b - a;
  const S edgeLength2 = edge.dot(edge);
  const S margin = convexMargin(t);
  S bestDepth{};
  Vec3<S> bestNormal = Vec3<S>::UnitY();
  const int bestFace = shallowestFace(
      pose, [&](int axis, S side) { return maxS(S(ha[axis] - side * l0[axis]), S(ha[axis] - side * l1[axis])); },
      [&](const Vec3<S>& n) {
        const Vec3<S> across = n - edge * S(edge.dot(n) / edgeLength2);  // n made normal to the edge
        return !((f1 - a).dot(across) > margin) && !((f2 - a).dot(across) > margin);
      },
      &bestDepth, &bestNormal);
  if (bestFace < 0) return 0;
  const int axis = bestFace / 2;
  const S side = bestFace % 2 == 0 ? S(1) : S(-1);
  int added = 0;
  for (int end = 0; end < 2; ++end) {
    const Vec3<S>& l = end == 0 ? l0 : l1;
    Contact<S> c;
    c.bodyA = body;
    c.bodyB = kTerrainBody;
    c.featureA = 14 + uint32_t(2 * bestFace + end);
    c.featureB = featureB;
    c.normal = bestNormal;
    c.penetration = ha[axis] - side * l[axis];
    c.point = pose.toWorld(l) + shift;
    out.push_back(c);
    ++added;
  }
  return added;
}

}  // namespace

template <class S>
int collideSphereTerrain(int32_t a, const Vec3<S>& ca, S ra, const Terrain<S>& terrain, std::vector<Contact<S>>& out,
                         S speculative, const PairSweep<S>* sweep) {
  if (terrain.flat() || ca.y() < terrain.heightAt(ca.x(), ca.z()))
    return spherePlaneUnderCentre(a, ca, ra, terrain, out, speculative);
  const S reach = ra + speculative;
  // Beyond the map and its two-cell margin the ground does not change along that axis: the
  // centre moves in to where its reach just meets the margin, which changes no distance and keeps
  // the cell range short and the indices in range (contact points are moved back).
  Vec3<S> c = ca;
  c.x() = std::clamp(c.x(), S(terrain.lowX() - reach), S(terrain.highX() + reach));
  c.z() = std::clamp(c.z(), S(terrain.lowZ() - reach), S(terrain.highZ() + reach));
  const int64_t i0 = terrain.cellX(c.x() - reach), i1 = terrain.cellX(c.x() + reach);
  const int64_t j0 = terrain.cellZ(c.z() - reach), j1 = terrain.cellZ(c.z() + reach);
  if (i1 - i0 > kMaxReachCells || j1 - j0 > kMaxReachCells)
    return spherePlaneUnderCentre(a, ca, ra, terrain, out, speculative);
  S top = terrain.heightOfSample(i0, j0);
  for (int64_t j = j0; j <= j1 + 1; ++j)
    for (int64_t i = i0; i <= i1 + 1; ++i) top = maxS(top, terrain.heightOfSample(i, j));
  if (c.y() - top >= reach) return 0;  // above every vertex, so above every face, by the reach

  const S inv = terrain.invCellSize();
  const size_t first = out.size();
  Vec3<S> n;
  S dist;
  // A ghost: a contact beyond the margin whose feature the sphere's path this tick never comes
  // within the margin of (`distanceAt` gives a point's distance to the feature).
  const auto ghost = [&](S gap, const auto& distanceAt) {
    return sweep && gap - ra > sweep->margin &&
           leastDistanceAlong(c, sweep->displacement, distanceAt) - ra > sweep->margin;
  };
  for (int64_t j = j0; j <= j1 + 1; ++j)
    for (int64_t i = i0; i <= i1 + 1; ++i) {
      const Vec3<S> v00 = vertexAt(terrain, i, j), v10 = vertexAt(terrain, i + 1, j);
      const Vec3<S> v01 = vertexAt(terrain, i, j + 1);
      if (i <= i1 && j <= j1) {  // the cell's two faces and its diagonal
        const Vec3<S> v11 = vertexAt(terrain, i + 1, j + 1);
        if (faceContact(terrain, c, reach, v00, S((v10.y() - v00.y()) * inv), S((v01.y() - v00.y()) * inv), i, j, true,
                        &n, &dist) &&
            !(ghost(dist, [&](const Vec3<S>& q) { return pointTriangleDistance(q, v00, v10, v01, n); }) &&
              !planeIsGroundAhead(terrain, c, ra, n, dist, *sweep)))
          addSphereContact(a, ca, ra, featureKey(kLowerFace, i, j), n, dist, out);
        if (faceContact(terrain, c, reach, v11, S((v11.y() - v01.y()) * inv), S((v11.y() - v10.y()) * inv), i, j, false,
                        &n, &dist) &&
            !(ghost(dist, [&](const Vec3<S>& q) { return pointTriangleDistance(q, v11, v10, v01, n); }) &&
              !planeIsGroundAhead(terrain, c, ra, n, dist, *sweep)))
          addSphereContact(a, ca, ra, featureKey(kUpperFace, i, j), n, dist, out);
        if (edgeContact(terrain, c, reach, v10, v01, i, j, i + 1, j + 1, &n, &dist) &&
            !ghost(dist, [&](const Vec3<S>& q) { return segmentPointDistance(v10, Vec3<S>(v01 - v10), q); }))
          addSphereContact(a, ca, ra, featureKey(kDiagonalEdge, i, j), n, dist, out);
      }
      // The edges from this vertex along +x and +z, with the third corners of their triangles.
      if (edgeContact(terrain, c, reach, v00, v10, i, j + 1, i + 1, j - 1, &n, &dist) &&
          !ghost(dist, [&](const Vec3<S>& q) { return segmentPointDistance(v00, Vec3<S>(v10 - v00), q); }))
        addSphereContact(a, ca, ra, featureKey(kEdgeAlongX, i, j), n, dist, out);
      if (edgeContact(terrain, c, reach, v00, v01, i + 1, j, i - 1, j + 1, &n, &dist) &&
          !ghost(dist, [&](const Vec3<S>& q) { return segmentPointDistance(v00, Vec3<S>(v01 - v00), q); }))
        addSphereContact(a, ca, ra, featureKey(kEdgeAlongZ, i, j), n, dist, out);
      const Vec3<S> d = c - v00;
      if (abs(d.x()) >= reach || abs(d.y()) >= reach || abs(d.z()) >= reach) continue;
      dist = length3(d.x(), d.y(), d.z());
      if (!(dist < reach) || dist == S(0)) continue;
      n = d / dist;
      if (!vertexIsPlanar(terrain, i, j) && vertexIsExtreme(terrain, i, j, v00, n) &&
          !ghost(dist,
                 [&](const Vec3<S>& q) { return length3(S(q.x() - v00.x()), S(q.y() - v00.y()), S(q.z() - v00.z())); }))
        addSphereContact(a, ca, ra, featureKey(kVertex, i, j), n, dist, out);
    }
  return int(out.size() - first);
}

template <class S>
int collideBoxTerrain(int32_t a, const Vec3<S>& ha, const Pose<S>& pa, const Terrain<S>& terrain,
                      std::vector<Contact<S>>& out, S speculative, const PairSweep<S>* sweep) {
  int added = 0;
  // 1. Corners against the triangle under each (exact distance to its plane).
  for (uint32_t corner = 0; corner < 8; ++corner) {
    const Vec3<S> local((corner & 1) ? ha.x() : -ha.x(), (corner & 2) ? ha.y() : -ha.y(),
                        (corner & 4) ? ha.z() : -ha.z());
    const Vec3<S> p = pa.toWorld(local);
    const S h = terrain.heightAt(p.x(), p.z());
    if (p.y() - h >= speculative) continue;  // the vertical gap bounds the gap along the normal
    Vec3<S> n;
    terrain.normalAt(p.x(), p.z(), &n.x(), &n.y(), &n.z());
    if (sweep && !terrain.flat() && cornerIsGhost(terrain, p, n, S((p.y() - h) * n.y()), *sweep)) continue;
    Contact<S> c;
    c.bodyA = a;
    c.bodyB = kTerrainBody;
    c.featureA = corner;
    c.normal = n;
    c.penetration = (h - p.y()) * n.y();
    c.point = p;
    out.push_back(c);
    ++added;
  }
  if (terrain.flat()) return added;
  // 2. Heightmap vertices inside the box, each pushed out through the shallowest face towards
  // which it is the ground's extreme point. On planar ground that is only the face lying on the
  // ground (no side face: a side face pointing up a slope was the ghost that stopped boxes
  // sliding over fine heightmaps); none at all when the box is not flat on it.
  // Beyond the map and its two-cell margin the ground does not change along that axis: the box
  // moves in to where its bounding sphere just meets the margin (as the sphere's centre does),
  // so ridges that extend beyond the edge still hold it and the scan stays short and in range;
  // the contact points move back.
  const S radius = ha.norm();
  Pose<S> pose = pa;
  pose.position.x() = std::clamp(pa.position.x(), S(terrain.lowX() - radius), S(terrain.highX() + radius));
  pose.position.z() = std::clamp(pa.position.z(), S(terrain.lowZ() - radius), S(terrain.highZ() + radius));
  const Vec3<S> shift = pa.position - pose.position;
  const int64_t i0 = terrain.cellX(S(pose.position.x() - radius)),
                i1 = terrain.cellX(S(pose.position.x() + radius)) + 1;
  const int64_t j0 = terrain.cellZ(S(pose.position.z() - radius)),
                j1 = terrain.cellZ(S(pose.position.z() + radius)) + 1;
  if (i1 - i0 > kMaxBoxCells || j1 - j0 > kMaxBoxCells) return added;  // a huge box over fine cells: corners only
  for (int64_t j = j0; j <= j1; ++j)
    for (int64_t i = i0; i <= i1; ++i) {
      const Vec3<S> v = vertexAt(terrain, i, j);
      const Vec3<S> local = pose.toLocal(v);
      if (abs(local.x()) >= ha.x() || abs(local.y()) >= ha.y() || abs(local.z()) >= ha.z()) continue;
      if (vertexIsPlanar(terrain, i, j)) continue;
      S bestDepth{};
      Vec3<S> bestNormal = Vec3<S>::UnitY();
      const int bestFace = shallowestFace(
          pose, [&](int axis, S side) { return S(ha[axis] - side * local[axis]); },
          [&](const Vec3<S>& n) { return vertexIsExtreme(terrain, i, j, v, n); }, &bestDepth, &bestNormal);
      if (bestFace < 0) continue;
      Contact<S> c;
      c.bodyA = a;
      c.bodyB = kTerrainBody;
      c.featureA = 8 + uint32_t(bestFace);
      c.featureB = featureKey(kVertex, i, j);
      c.normal = bestNormal;
      c.penetration = bestDepth;
      c.point = v + shift;
      out.push_back(c);
      ++added;
    }
  // 3. Crease edges that pass through the box with neither end inside it: a ridge under a box
  // narrower than a cell, or crossing it between two samples. Neither the corners (they hang over
  // the slopes) nor the vertices (none is inside) meet it, and a 0.2 m cube on a 1 m ridge sank
  // until its corners reached the slopes, the crest 10 cm inside it.
  const S reach = radius + S(1) / S(1024);
  for (int64_t j = j0; j <= j1; ++j)
    for (int64_t i = i0; i <= i1; ++i) {
      added += creaseThroughBox(a, ha, pose, reach, shift, terrain, i, j, i + 1, j, i, j + 1, i + 1, j - 1,
                                featureKey(kEdgeAlongX, i, j), out);
      added += creaseThroughBox(a, ha, pose, reach, shift, terrain, i, j, i, j + 1, i + 1, j, i - 1, j + 1,
                                featureKey(kEdgeAlongZ, i, j), out);
      added += creaseThroughBox(a, ha, pose, reach, shift, terrain, i + 1, j, i, j + 1, i, j, i + 1, j + 1,
                                featureKey(kDiagonalEdge, i, j), out);
    }
  return added;
}

#define SG_INSTANTIATE(S)                                                                                              \
  template int collideSphereTerrain(int32_t, const Vec3<S>&, S, const Terrain<S>&, std::vector<Contact<S>>&, S,        \
                                    const PairSweep<S>*);                                                              \
  template int collideBoxTerrain(int32_t, const Vec3<S>&, const Pose<S>&, const Terrain<S>&, std::vector<Contact<S>>&, \
                                 S, const PairSweep<S>*);
SG_FOR_EACH_SCALAR(SG_INSTANTIATE)
#undef SG_INSTANTIATE
}  // namespace sg
