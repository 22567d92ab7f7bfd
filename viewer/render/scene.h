// What the renderer draws, as plain float data extracted from a world (no GL here): one tuft per
// simulated patch, one per visible edge-ring cell, every body part with its pose, and the ground
// grid. The renderer never sees World<S>; this file is where the scalar type is erased.
#pragma once

#include <cstdint>
#include <vector>

#include "viewer/render/camera.h"

namespace sg {
class SimWorld;
struct Scenario;
}  // namespace sg

namespace sg::viewer {

/// One tuft quad (thesis §2): a vertical quad whose bottom edge is centred on the root, turned by
/// `angle` about y; the top edge sits at `topY`, shifted by (tipX, tipZ). 36 bytes, uploaded as is.
struct TuftInstance {
  float x, y, z;        ///< root on the ground (m)
  float halfWidth;      ///< m (scaleXZ; larger for edge-ring tufts)
  float topY;           ///< m, world height of the top edge
  float tipX, tipZ;     ///< m, top-edge shift from the root
  float angle;          ///< radians (rotation / 65536 turns)
  uint8_t variant;      ///< atlas column: 0..variants-1, variants = the white marking tuft
  uint8_t level;        ///< atlas row: brightness 0..3 (tilt level; mown tufts are brightest)
  uint8_t pad[2] = {0, 0};
};

/// One body part: a unit sphere or a unit cube (-1..1) under `model` (translation, rotation,
/// scale by the radius or half extents).
struct BodyPartDraw {
  enum class Shape : uint8_t { Sphere, Box } shape = Shape::Sphere;
  enum class Pattern : uint8_t { Plain, Football } pattern = Pattern::Plain;
  Mat4 model = identity4();
  float colour[3] = {0.8f, 0.8f, 0.8f};  ///< linear RGB albedo
};

/// The ground: heights on a rectilinear grid (xs x zs), row-major (z rows, x fastest). The inner
/// part follows the terrain at its own resolution; the outermost lines reach far out (a skirt to
/// the horizon, hidden in fog).
struct GroundGrid {
  std::vector<float> xs, zs;
  std::vector<float> heights;  ///< zs.size() * xs.size()
  uint64_t revision = 0;       ///< unique per built grid (the renderer re-uploads when it changes)
  uint64_t key = 0;            ///< hash of the terrain and field it was built for
};

struct Scene {
  int64_t tick = 0;
  int atlasVariants = 4;
  uint64_t atlasSeed = 1;
  std::vector<TuftInstance> tufts;  ///< simulated tufts first, then the edge ring
  size_t simulatedTufts = 0;
  std::vector<BodyPartDraw> bodyParts;
  GroundGrid ground;
  /// Where the simulated grass is (the level-of-detail window, else the field), m.
  float focusMinX = 0, focusMaxX = 0, focusMinZ = 0, focusMaxZ = 0;
  float groundHeightAtFocus = 0;  ///< terrain height at the focus centre
  float tuftHeight = 1;           ///< scaleY
};

/// Fills `scene` from the world's current state. The ground grid is rebuilt only when `scene`
/// holds none for this terrain and field yet (terrain is static). `scenario` must be the world's
/// (body names and colours, tuft sizes, mower height). Edge-ring tufts are drawn sqrt(edgeSpacing)
/// times wider than the grass: they stand edgeSpacing spacings apart, and a wider quad keeps the
/// ring about as dense.
void extractScene(const SimWorld& world, const Scenario& scenario, Scene* scene);

/// Terrain height (m) at (x, z) of the world, for camera placement.
float groundHeight(const SimWorld& world, float x, float z);

/// The default view of a scene: 1.7 m above the ground just outside the -z edge of the simulated
/// grass, looking at its centre.
Camera defaultCamera(const Scene& scene, const SimWorld& world);

}  // namespace sg::viewer
