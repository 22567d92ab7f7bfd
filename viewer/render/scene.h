// What the renderer draws, as plain float data extracted from a world (no GL here): one tuft per
// simulated patch, one per visible edge-ring cell, every body part with its pose, and the ground
// grid. The renderer never sees World<S>; this file is where the scalar type is erased.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "viewer/render/camera.h"

namespace sg {
class SimWorld;
struct Scenario;
struct Observation;
}  // namespace sg

namespace sg::viewer {

/// One tuft (thesis §2): two vertical quads crossed at 90 degrees about the root, the first turned
/// by `angle` about y; their top edges sit `topY - y` above their bottom edges, shifted by (tipX,
/// tipZ). The renderer bends each bottom corner onto the terrain (docs/rendering.md). 36 bytes,
/// uploaded as is.
struct TuftInstance {
  float x, y, z;      ///< root on the ground (m)
  float halfWidth;    ///< m (scaleXZ)
  float topY;         ///< m, world height of the top edge
  float tipX, tipZ;   ///< m, top-edge shift from the root
  float angle;        ///< radians (rotation / 65536 turns)
  uint8_t variant;    ///< atlas column: 0..variants-1, variants = the white marking tuft
  uint8_t level;      ///< atlas row: brightness 0..3 (tilt level; mown tufts are brightest)
  uint8_t heat = 0;   ///< divergence overlay: 0 = none .. 255 = full scale (applyDivergenceHeat)
  uint8_t trail = 0;  ///< pressed by a body: 0 = untouched .. 255 = just pressed (drawn flatter, darker)
};

/// One body part: a unit sphere or a unit cube (-1..1) under `model` (translation, rotation,
/// scale by the radius or half extents), or a user mesh (Shape::Mesh: `mesh` is the OBJ path as
/// the scenario names it, drawn in body-local metres under `model`, which then holds the body's
/// pose without scale; `proxies` are the collision primitives drawn when the mesh fails to load).
struct BodyPartDraw {
  enum class Shape : uint8_t { Sphere, Box, Mesh } shape = Shape::Sphere;
  enum class Pattern : uint8_t { Plain, Football } pattern = Pattern::Plain;
  Mat4 model = identity4();
  float colour[3] = {0.8f, 0.8f, 0.8f};     ///< linear RGB albedo
  std::string mesh;                         ///< Shape::Mesh: OBJ path (relative: the asset directory)
  uint32_t firstProxy = 0, proxyCount = 0;  ///< Shape::Mesh: the body's primitive parts in
                                            ///< Scene::meshProxies (the fallback when the mesh fails)
};

/// Debug overlay geometry (extractDebug): world-space lines and points, linear RGB colours.
struct DebugScene {
  struct Line {
    float a[3], b[3];
    float colour[3];
  };
  struct Point {
    float p[3];
    float size;  ///< pixels
    float colour[3];
  };
  std::vector<Line> lines;
  std::vector<Point> points;
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

/// How long a body's trail stays visible (s), and how far apart two extractions may be for a
/// body's path between them to be swept (ticks, m: beyond, only the current footprint presses).
inline constexpr double kTrailSeconds = 8.0;
inline constexpr int64_t kTrailSweepTicks = 120;
inline constexpr float kTrailSweepMetres = 6.0f;

/// Render-side memory of where bodies pressed the grass (extractScene keeps it between frames):
/// per lattice patch of the field, the tick at which its trail has faded. A pure function of the
/// sequence of extracted states (no clock), so a frame sequence always draws the same trails.
struct TrailMemory {
  uint64_t key = 0;                ///< the scenario it belongs to (another one starts afresh)
  int64_t tick = -1;               ///< tick of the last extraction (-1: none)
  int64_t fieldI = 0, fieldJ = 0;  ///< patches of the field (fadesAt is fieldI * fieldJ, row-major)
  int64_t fadeTicks = 1;           ///< a trail fades from 1 to 0 over this many ticks
  std::vector<int32_t> fadesAt;    ///< tick at which patch (i, j)'s trail is gone (0: never pressed)
  /// The body parts' footprints at the last extraction, to sweep each part's path to the next.
  struct Footprint {
    float x, z;          ///< centre (m)
    float axisX[2];      ///< unit horizontal axis of the first half extent
    float halfA, halfB;  ///< half extents along axisX and its perpendicular (m; a disc: both its radius)
    float bottom;        ///< lowest point (m)
    bool disc;           ///< a sphere's section (else a box's rectangle)
  };
  std::vector<Footprint> footprints;
};

/// The edge ring's tufts for one ring and window position (extractScene rebuilds them only when
/// the window moves or a cut appears).
struct RingCache {
  uint64_t key = 0;
  std::vector<TuftInstance> tufts;
  std::vector<int64_t> patch;  ///< per tuft: its lattice patch j * fieldPatchesX + i
};

struct Scene {
  int64_t tick = 0;
  int atlasVariants = 4;
  uint64_t atlasSeed = 1;
  std::vector<TuftInstance> tufts;  ///< simulated tufts first, then the edge ring
  size_t simulatedTufts = 0;
  std::vector<BodyPartDraw> bodyParts;
  std::vector<BodyPartDraw> meshProxies;  ///< primitives of mesh bodies (drawn if a mesh fails)
  GroundGrid ground;
  DebugScene debug;  ///< overlay (extractDebug; drawn per RenderOptions::debug)
  /// The simulated tufts' layout: the LOD window's first patch (i, j) and size, and the field's
  /// patch columns. Two scenes with equal layouts hold the same patches in the same slots.
  int64_t windowOriginI = 0, windowOriginJ = 0, windowWidth = 0, windowHeight = 0;
  int64_t fieldPatchesX = 0, fieldPatchesZ = 0;
  /// Where the simulated grass is (the level-of-detail window, else the field), m.
  float focusMinX = 0, focusMaxX = 0, focusMinZ = 0, focusMaxZ = 0;
  float groundHeightAtFocus = 0;  ///< terrain height at the focus centre
  float tuftHeight = 1;           ///< scaleY
  TrailMemory trails;             ///< where bodies pressed the grass (kept between extractions)
  RingCache ring;                 ///< the edge ring's tufts (kept between extractions)
  /// The GPU physics path (docs/gpu-physics.md): an OpenGL buffer of the device, in the
  /// renderer's context, holding each simulated tuft's top y, tip offset x and z and brightness
  /// level (SimWorld::devicePatchDrawBuffer); 0: the tufts hold their own. With a buffer, the
  /// simulated tufts' topY, tipX, tipZ and level are placeholders the renderer replaces (no copy
  /// back), and its culling allows each tip `deviceTipReach` metres from the root.
  uint32_t deviceTops = 0;
  float deviceTipReach = 0;
  /// Display interpolation on the device path (interpolateScene): the previous tick's buffer
  /// (the device alternates two, ParticleDevice::patchDrawBuffer) and how far toward deviceTops
  /// the tops, tips are drawn (0: the previous tick's, 1: deviceTops'); 0 buffer: none.
  uint32_t deviceTopsPrevious = 0;
  float deviceTopsAlpha = 1;
};

/// Fills `scene` from the world's current state. The ground grid is rebuilt only when `scene`
/// holds none for this terrain and field yet (terrain is static). `scenario` must be the world's
/// (body names and colours, tuft sizes, mower height).
///
/// The edge ring is drawn as the thesis built it: rows `edgeSpacing` grass spacings apart, around
/// the simulated window, each row a line of the grass lattice's own tufts one grass spacing
/// apart (a ring cell of EdgeRing gives the row through its centre patch; docs/rendering.md).
///
/// Trails: every body part that reaches below the grass top presses the patches under its
/// footprint, swept along its path since the previous extraction into the same `scene` (at most
/// kTrailSweepTicks and kTrailSweepMetres apart); a pressed patch's TuftInstance::trail fades
/// from 255 to 0 over kTrailSeconds. With the blade model's trampling, a trampled particle's
/// level shows too. An extraction at an earlier tick or of another scenario starts afresh.
///
/// A world whose device holds the current patch state (SimWorld::devicePatchDrawBuffer) is
/// extracted without copying anything back: Scene::deviceTops names the device's buffer (the
/// renderer must share the device's context), the trample levels included.
void extractScene(const SimWorld& world, const Scenario& scenario, Scene* scene);

/// Which debug overlay layers to build / draw.
struct DebugFlags {
  bool particles = false, constraints = false, primitives = false, cells = false, contacts = false;
  bool any() const { return particles || constraints || primitives || cells || contacts; }
};

/// Fills scene->debug from the world's current state (replacing what it held): particles (a
/// point per particle of the simulated window), constraints (root -> particle lines), body
/// primitives (wireframe spheres and boxes at their poses, mower parts included), broad-phase
/// cells (outline of every occupied particle-grid cell) and contacts (a point and a short normal
/// line each), as `flags` ask.
void extractDebug(const SimWorld& world, const Scenario& scenario, const DebugFlags& flags, Scene* scene);

/// Display-only interpolation between the last two ticks, alpha in [0, 1] (0: previous, 1:
/// current). Tuft tops lerp where both scenes have the same tuft layout, else `out` takes
/// current's tufts; body parts lerp translation and slerp rotation when the part counts match.
/// The ground and everything else come from `current`. Never feeds back into the simulation.
void interpolateScene(const Scene& previous, const Scene& current, float alpha, Scene* out);

/// Sets the simulated tufts' `heat` from |tipA - tipB| / fullScaleMetres (clamped to 1, scaled to
/// 255) of the two full-field observations; patches outside the LOD window have no tuft. Edge-ring
/// tufts get 0.
void applyDivergenceHeat(const Observation& a, const Observation& b, float fullScaleMetres, Scene* scene);

/// Terrain height (m) at (x, z) of the world, for camera placement.
float groundHeight(const SimWorld& world, float x, float z);

/// The default view of a scene, for a frame of width/height `aspect`. With bodies: the nearest
/// view from the -z side, 20 degrees above, that keeps every corner of the bodies' bounds (grown
/// to at least 3 m across) inside the middle 80 % of the frame, the eye at least 1.7 m above the
/// ground. Without: 1.7 m above the ground just outside the -z edge of the simulated grass,
/// looking at its centre.
Camera defaultCamera(const Scene& scene, const SimWorld& world, float aspect = 16.0f / 9.0f);

}  // namespace sg::viewer
