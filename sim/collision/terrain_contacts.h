// Bodies against the terrain: flat ground, or the triangles of a heightmap (sim/terrain).
//
// A heightmap's ground is a triangle mesh, so the contacts are those of a mesh, with the rule
// that keeps a mesh free of ghost normals (Jolt's active edges and Bullet's internal-edge
// utility solve the same problem): an edge or a vertex of the ground makes a contact only when
// it is the ground's extreme point in that contact's direction. A vertex of planar ground, or a
// concave crease, never pushes along a tilted normal; its faces give the contact instead. The
// conventions are contact.h's (normal from the terrain to the body, speculative up to
// `speculative` m with a negative penetration).
#pragma once

#include <vector>

#include "sim/collision/contact.h"
#include "sim/collision/swept_spheres.h"
#include "sim/terrain/terrain.h"

namespace sg {

/// Sphere A against the terrain. On a heightmap: the closest point of every face, edge and vertex
/// within the sphere's reach; faces whose nearest point lies inside them, edges and vertices only
/// where they are convex (ridges and peaks). A centre below the ground takes the plane under it.
/// With a `sweep` (the sphere's path this tick), a contact farther than the sweep's margin is kept
/// only if that path comes within the margin of its feature (the face, edge or vertex itself, not
/// the feature's plane: swept_spheres.h).
template <class S>
int collideSphereTerrain(int32_t a, const Vec3<S>& ca, S ra, const Terrain<S>& terrain, std::vector<Contact<S>>& out,
                         S speculative = S(0), const PairSweep<S>* sweep = nullptr);

/// Box A against the terrain. The eight corners against the triangle under each (thesis: the
/// corners against the height under them), and the heightmap vertices inside the box that are
/// the ground's extreme point towards one of its faces (a ridge or peak pressing into that face;
/// the thesis let a box sink through such a ridge between its corners). Corners up to
/// `speculative` above the ground are speculative contacts; vertices only overlap.
/// Not covered: a ridge edge crossing a box face with none of its vertices inside the box (a box
/// smaller than a cell lying across a ridge sinks onto it until a corner meets the ground).
/// With a `sweep` (the box's path this tick), a corner's row farther than the margin is kept only
/// if the corner's path comes within the margin of the triangle under it, or the triangle's plane
/// is the ground where the path nears it (a ghost otherwise: swept_spheres.h).
template <class S>
int collideBoxTerrain(int32_t a, const Vec3<S>& ha, const Pose<S>& pa, const Terrain<S>& terrain,
                      std::vector<Contact<S>>& out, S speculative = S(0), const PairSweep<S>* sweep = nullptr);

}  // namespace sg
