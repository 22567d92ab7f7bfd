#include "viewer/render/scene.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <climits>
#include <cmath>
#include <initializer_list>
#include <set>
#include <string>

#include "sim/collision/body_particles.h"
#include "sim/field/markings.h"
#include "sim/math/scalar_ops.h"
#include "sim/scenario/derived.h"
#include "sim/world/world.h"

namespace sg::viewer {
namespace {

constexpr float kTurn = 6.283185307179586f / 65536.0f;

template <class S>
double toD(S v) {
  return ScalarTraits<S>::toDouble(v);
}

template <class S>
S fromD(double v) {
  if constexpr (ScalarTraits<S>::isFixed)
    return S::fromDouble(v);
  else
    return S(v);
}

template <class S>
const World<S>* typed(const SimWorld& world) {
  return dynamic_cast<const World<S>*>(&world);
}

bool nameHas(const std::string& name, const char* word) {
  std::string lower(name);
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return lower.find(word) != std::string::npos;
}

void setColour(BodyPartDraw& d, float r, float g, float b) {
  d.colour[0] = r;
  d.colour[1] = g;
  d.colour[2] = b;
}

/// Albedo by what the body is: a football is white with dark patches, a mower red with dark
/// wheels, a box wooden; anything else takes a colour from a small palette by index.
void paint(BodyPartDraw& d, const std::string& name, bool mower, size_t bodyIndex) {
  if (mower) {
    if (d.shape == BodyPartDraw::Shape::Box)
      setColour(d, 0.70f, 0.08f, 0.06f);
    else
      setColour(d, 0.08f, 0.08f, 0.08f);
    return;
  }
  if (nameHas(name, "football") || nameHas(name, "ball")) {
    setColour(d, 0.92f, 0.92f, 0.90f);
    if (d.shape == BodyPartDraw::Shape::Sphere) d.pattern = BodyPartDraw::Pattern::Football;
    return;
  }
  if (nameHas(name, "bunny")) return setColour(d, 0.72f, 0.66f, 0.58f);
  if (nameHas(name, "rock") || nameHas(name, "stone")) return setColour(d, 0.46f, 0.44f, 0.41f);
  if (nameHas(name, "crate")) return setColour(d, 0.60f, 0.42f, 0.22f);
  if (d.shape == BodyPartDraw::Shape::Box && nameHas(name, "box")) return setColour(d, 0.60f, 0.42f, 0.22f);
  static const float palette[][3] = {{0.25f, 0.40f, 0.75f},
                                     {0.80f, 0.60f, 0.15f},
                                     {0.55f, 0.25f, 0.60f},
                                     {0.20f, 0.60f, 0.60f},
                                     {0.75f, 0.35f, 0.30f}};
  const auto& c = palette[bodyIndex % (sizeof palette / sizeof palette[0])];
  setColour(d, c[0], c[1], c[2]);
}

/// Grid lines from lo to hi at most `step` apart (at least 2 lines).
std::vector<float> gridLines(double lo, double hi, double step, int maxCells) {
  int cells = std::max(1, int(std::ceil((hi - lo) / step)));
  cells = std::min(cells, maxCells);
  std::vector<float> v(size_t(cells) + 1);
  for (int i = 0; i <= cells; ++i) v[size_t(i)] = float(lo + (hi - lo) * double(i) / double(cells));
  return v;
}

/// FNV-1a over what the ground grid depends on: the terrain and the field's extent.
uint64_t groundKey(const Scenario& s) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* data, size_t n) {
    const auto* b = static_cast<const uint8_t*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  };
  auto mixD = [&mix](double d) { mix(&d, sizeof d); };
  const Scenario::Terrain& t = s.terrain;
  const uint8_t flat = t.flat ? 1 : 0;
  mix(&flat, 1);
  for (const Rational* r : {&t.flatHeight, &t.cellSize, &t.maxHeight, &t.centerX, &t.centerZ, &s.field.spacing,
                            &s.field.centerX, &s.field.centerZ})
    mixD(r->toDouble());
  const int64_t dims[4] = {t.heightmap.width, t.heightmap.height, s.field.patchesX, s.field.patchesZ};
  mix(dims, sizeof dims);
  mix(t.heightmap.samples.data(), t.heightmap.samples.size());
  return h;
}

std::atomic<uint64_t> nextGroundRevision{1};

template <class S>
void extractGround(const World<S>& w, const Scenario& scenario, GroundGrid* g) {
  // Inner grid: the field and a margin of half its size (at least 20 m), at the heightmap's
  // resolution (1 m on flat ground), at most 512 cells a side; then a skirt 3 km out.
  const double spacing = toD(w.lattice().spacing);
  const double x0 = toD(w.lattice().originX), z0 = toD(w.lattice().originZ);
  const double x1 = x0 + spacing * double(w.lattice().patchesX - 1);
  const double z1 = z0 + spacing * double(w.lattice().patchesZ - 1);
  const double margin = std::max(20.0, 0.5 * std::max(x1 - x0, z1 - z0));
  const double step = scenario.terrain.flat ? 1.0 : std::max(0.05, scenario.terrain.cellSize.toDouble());
  constexpr double kSkirt = 3000.0;
  double gx0 = x0 - margin, gx1 = x1 + margin, gz0 = z0 - margin, gz1 = z1 + margin;
  if (!scenario.terrain.flat) {
    // On the heightmap's own samples, so the mesh's triangles (split from (i + 1, j) to
    // (i, j + 1), see uploadGround) are the simulation's ground triangles exactly, where the
    // 512-cell cap and the 5 cm floor leave the resolution whole.
    const double sx = toD(w.terrain().sampleX(0)), sz = toD(w.terrain().sampleZ(0));
    gx0 = sx + step * std::floor((gx0 - sx) / step);
    gx1 = sx + step * std::ceil((gx1 - sx) / step);
    gz0 = sz + step * std::floor((gz0 - sz) / step);
    gz1 = sz + step * std::ceil((gz1 - sz) / step);
  }
  g->xs = gridLines(gx0, gx1, step, 512);
  g->zs = gridLines(gz0, gz1, step, 512);
  g->xs.insert(g->xs.begin(), float(x0 - kSkirt));
  g->xs.push_back(float(x1 + kSkirt));
  g->zs.insert(g->zs.begin(), float(z0 - kSkirt));
  g->zs.push_back(float(z1 + kSkirt));
  g->heights.resize(g->xs.size() * g->zs.size());
  // The skirt takes the height at the inner border (the terrain extends its edge samples anyway).
  const size_t nx = g->xs.size(), nz = g->zs.size();
  for (size_t j = 0; j < nz; ++j) {
    const double z = g->zs[std::clamp<size_t>(j, 1, nz - 2)];
    for (size_t i = 0; i < nx; ++i) {
      const double x = g->xs[std::clamp<size_t>(i, 1, nx - 2)];
      g->heights[j * nx + i] = float(toD(w.terrain().heightAt(fromD<S>(x), fromD<S>(z))));
    }
  }
  g->revision = nextGroundRevision.fetch_add(1);
}

/// Floor division (b > 0) for lattice coordinates that may be negative.
int64_t floorDiv(int64_t a, int64_t b) {
  const int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

/// FNV-1a over a list of integers (cache and memory keys).
uint64_t mixKey(uint64_t h, std::initializer_list<int64_t> values) {
  for (int64_t v : values)
    for (int b = 0; b < 8; ++b) h = (h ^ uint64_t((v >> (8 * b)) & 0xff)) * 1099511628211ull;
  return h;
}

/// The world's football-field markings, built from the scenario exactly as World<S> builds its own
/// (sim/world/world.cpp): the renderer needs them for the edge ring's lattice tufts.
template <class S>
FieldMarkings<S> markingsOf(const Scenario& s) {
  // The scenario's exact numbers, converted as World<S> converts them (a validated scenario's
  // values fit S), so a lattice point on a line's edge falls on the same side as in the world.
  const auto exact = [](const Rational& r) {
    return ScalarTraits<S>::fromRational(r).value_or(fromD<S>(r.toDouble()));
  };
  FieldMarkings<S> m;
  if (!s.markings.enabled) return m;
  m.enabled = true;
  m.centerX = exact(s.markings.centerX);
  m.centerZ = exact(s.markings.centerZ);
  m.halfLength = exact(s.markings.length) / S(2);
  m.halfWidth = exact(s.markings.width) / S(2);
  m.halfLine = exact(s.markings.lineWidth) / S(2);
  m.circleRadius = exact(s.markings.centerCircleRadius);
  return m;
}

/// The edge ring as the thesis built it (DIGEST §3): rows m = edgeSpacing grass spacings apart
/// around the simulated window, the tufts of a row one grass spacing apart. The simulation's
/// EdgeRing holds one coarse cell per m x m patches (which cells are drawn, and where the hole
/// is); each visible cell becomes the m grass-lattice tufts of the ring row through its centre
/// patch: along x in the bands beyond the window's -z and +z sides, along z beside its -x and +x
/// sides, and in a corner cell (as far out in x as in z) an L from its inner edges to its centre,
/// so every row closes into a square loop. They are the grass lattice's own tufts (position,
/// rotation, variant, marking, cut): a row that the window reaches shows the same tufts simulated.
/// Rebuilt only when the ring or the window moves or a cut appears.
template <class S>
void extractRing(const World<S>& w, const Scenario& scenario, float halfWidth, float scaleY, Scene* scene) {
  const EdgeRing<S>& ring = w.edgeRing();
  RingCache& cache = scene->ring;
  if (ring.rows <= 0) {
    cache.tufts.clear();
    cache.patch.clear();
    cache.key = 0;
    return;
  }
  const LatticeWindow &cells = ring.cells, &hole = ring.hole;
  const uint64_t key = mixKey(scenario.seed ^ 0x72696e67ull,
                              {cells.originI, cells.originJ, cells.sizeI, cells.sizeJ, hole.originI, hole.originJ,
                               hole.sizeI, hole.sizeJ, hole.fieldI, hole.fieldJ, int64_t(w.cuts().size()),
                               ring.spacingMultiple, int64_t(scenario.field.atlasVariants)});
  if (key == cache.key && !cache.tufts.empty()) return;
  cache.key = key;
  cache.tufts.clear();
  cache.patch.clear();
  const int64_t m = std::max<int64_t>(1, ring.spacingMultiple);
  // The hole in coarse cells: a in [a0, a1], b in [b0, b1] have their centre patch in the window.
  const auto firstCell = [m](int64_t patch) { return floorDiv(patch - m / 2 + m - 1, m); };
  const int64_t a0 = firstCell(hole.originI), a1 = firstCell(hole.endI()) - 1;
  const int64_t b0 = firstCell(hole.originJ), b1 = firstCell(hole.endJ()) - 1;
  const GrassLattice<S>& lattice = w.lattice();
  const FieldMarkings<S> markings = markingsOf<S>(scenario);
  const double cutTop = std::min<double>(std::max(scenario.bodies.mowerCutHeight.toDouble(), scaleY / 10.0), scaleY);
  auto emit = [&](int64_t i, int64_t j) {
    if (i < 0 || j < 0 || i >= hole.fieldI || j >= hole.fieldJ || hole.contains(i, j)) return;
    S x, z;
    lattice.rootXZ(i, j, &x, &z);
    TuftInstance t{};
    t.x = float(toD(x));
    t.z = float(toD(z));
    t.y = float(toD(w.terrain().heightAt(x, z)));
    const bool cut = w.cuts().count({i, j}) > 0;
    t.halfWidth = halfWidth;
    t.topY = t.y + (cut ? float(cutTop) : scaleY);
    t.angle = float(lattice.rotation(i, j)) * kTurn;
    t.variant = lattice.variant(i, j);
    if (markings.onLine(lattice.originX + mulInt(lattice.spacing, i), lattice.originZ + mulInt(lattice.spacing, j)))
      t.variant = uint8_t(lattice.atlasVariants);
    t.level = cut ? 3 : 0;
    cache.tufts.push_back(t);
    cache.patch.push_back(j * hole.fieldI + i);
  };
  for (int64_t b = cells.originJ; b < cells.endJ(); ++b)
    for (int64_t a = cells.originI; a < cells.endI(); ++a) {
      if (!ring.visible(a, b)) continue;
      const int64_t dx = a < a0 ? a0 - a : (a > a1 ? a - a1 : 0);
      const int64_t dz = b < b0 ? b0 - b : (b > b1 ? b - b1 : 0);
      const int64_t ic = ring.centrePatchI(a), jc = ring.centrePatchJ(b);
      if (dz > dx) {  // beyond the -z or +z side: a row along x
        for (int64_t i = a * m; i < a * m + m; ++i) emit(i, jc);
      } else if (dx > dz) {  // beside the -x or +x side: a row along z
        for (int64_t j = b * m; j < b * m + m; ++j) emit(ic, j);
      } else {  // a corner: from the x row's inner edge to the centre, then on to the z row's
        const bool right = a > a1, far = b > b1;
        for (int64_t i = right ? a * m : ic; i <= (right ? ic : a * m + m - 1); ++i) emit(i, jc);
        for (int64_t j = far ? b * m : jc + 1; j <= (far ? jc - 1 : b * m + m - 1); ++j) emit(ic, j);
      }
    }
}

/// The current footprints of the bodies' primitives (a mesh body: its collision proxies), in a
/// stable order: the scene's parts, a mesh's proxies in its place.
std::vector<TrailMemory::Footprint> footprintsOf(const Scene& scene, float margin) {
  std::vector<TrailMemory::Footprint> out;
  auto add = [&](const BodyPartDraw& p) {
    const Mat4& m = p.model;
    TrailMemory::Footprint f{};
    f.x = m[12];
    f.z = m[14];
    if (p.shape == BodyPartDraw::Shape::Sphere) {
      // A sphere's model is a rotation times its radius: any column's length is the radius.
      const float r = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
      f.bottom = m[13] - r;
      f.disc = true;
      f.halfA = f.halfB = r + margin;
      f.axisX[0] = 1, f.axisX[1] = 0;
    } else {
      f.bottom = m[13] - (std::fabs(m[1]) + std::fabs(m[5]) + std::fabs(m[9]));  // the box's lowest corner
      // The box's two most horizontal axes (columns scaled by the half extents) span its footprint.
      int up = 0;
      float best = -1;
      for (int c = 0; c < 3; ++c) {
        const float* v = &m[size_t(c) * 4];
        const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        const float vertical = len > 0 ? std::fabs(v[1]) / len : 0;
        if (vertical > best) best = vertical, up = c;
      }
      const float* u = &m[size_t((up + 1) % 3) * 4];
      const float* v = &m[size_t((up + 2) % 3) * 4];
      const float lu = std::sqrt(u[0] * u[0] + u[2] * u[2]), lv = std::sqrt(v[0] * v[0] + v[2] * v[2]);
      f.disc = false;
      f.axisX[0] = lu > 0 ? u[0] / lu : 1;
      f.axisX[1] = lu > 0 ? u[2] / lu : 0;
      f.halfA = lu + margin;
      f.halfB = lv + margin;
    }
    out.push_back(f);
  };
  for (const BodyPartDraw& p : scene.bodyParts) {
    if (p.shape != BodyPartDraw::Shape::Mesh) {
      add(p);
      continue;
    }
    for (uint32_t i = p.firstProxy; i < p.firstProxy + p.proxyCount && i < scene.meshProxies.size(); ++i)
      add(scene.meshProxies[i]);
  }
  return out;
}

/// Presses every patch under footprint `f` at tick `tick`: its trail lasts until tick +
/// fadeTicks. Only where the body reaches below the grass top (the terrain under its centre +
/// the tuft height); a sphere presses the disc of its section at the grass top.
template <class S>
void stamp(const World<S>& w, const TrailMemory::Footprint& f, float margin, float scaleY, int64_t tick,
           TrailMemory* mem) {
  const float ground = float(toD(w.terrain().heightAt(fromD<S>(f.x), fromD<S>(f.z))));
  const float top = ground + scaleY;
  if (f.bottom >= top) return;
  float halfA = f.halfA, halfB = f.halfB;
  if (f.disc) {  // the section at the grass top (the whole radius when the centre is below it)
    const float r = f.halfA - margin, centreY = f.bottom + r, above = std::max(0.0f, centreY - top);
    halfA = halfB = std::sqrt(std::max(0.0f, r * r - above * above)) + margin;
  }
  const GrassLattice<S>& lattice = w.lattice();
  const double spacing = toD(lattice.spacing), jitter = toD(lattice.jitterAmplitude);
  const double reach = std::sqrt(double(halfA) * halfA + double(halfB) * halfB) + jitter;
  const double ox = toD(lattice.originX), oz = toD(lattice.originZ);
  const int64_t i0 = std::max<int64_t>(0, int64_t(std::floor((f.x - reach - ox) / spacing)));
  const int64_t i1 = std::min<int64_t>(mem->fieldI - 1, int64_t(std::ceil((f.x + reach - ox) / spacing)));
  const int64_t j0 = std::max<int64_t>(0, int64_t(std::floor((f.z - reach - oz) / spacing)));
  const int64_t j1 = std::min<int64_t>(mem->fieldJ - 1, int64_t(std::ceil((f.z + reach - oz) / spacing)));
  const int32_t until = int32_t(std::min<int64_t>(tick + mem->fadeTicks, INT32_MAX));
  for (int64_t j = j0; j <= j1; ++j)
    for (int64_t i = i0; i <= i1; ++i) {
      S sx, sz;
      lattice.rootXZ(i, j, &sx, &sz);
      const float dx = float(toD(sx)) - f.x, dz = float(toD(sz)) - f.z;
      const float along = dx * f.axisX[0] + dz * f.axisX[1], across = -dx * f.axisX[1] + dz * f.axisX[0];
      const bool inside =
          f.disc ? dx * dx + dz * dz <= halfA * halfA : std::fabs(along) <= halfA && std::fabs(across) <= halfB;
      if (!inside) continue;
      int32_t& at = mem->fadesAt[size_t(j * mem->fieldI + i)];
      at = std::max(at, until);
    }
}

/// Updates the trail memory with this extraction (see extractScene) and returns nothing; the
/// caller reads TrailMemory::fadesAt.
template <class S>
void updateTrails(const World<S>& w, const Scenario& scenario, float scaleY, Scene* scene) {
  TrailMemory& mem = scene->trails;
  const int64_t tick = w.tick();
  uint64_t key = mixKey(groundKey(scenario) ^ scenario.seed,
                        {w.lattice().patchesX, w.lattice().patchesZ, int64_t(scenario.bodies.list.size())});
  for (const char c : scenario.name) key = mixKey(key, {int64_t(c)});
  if (key != mem.key || tick < mem.tick || mem.fieldI != w.lattice().patchesX || mem.fieldJ != w.lattice().patchesZ) {
    mem.key = key;
    mem.tick = -1;
    mem.fieldI = w.lattice().patchesX;
    mem.fieldJ = w.lattice().patchesZ;
    mem.fadesAt.clear();
    mem.footprints.clear();
  }
  mem.fadeTicks = std::max<int64_t>(1, std::llround(kTrailSeconds / scenario.timeStep.toDouble()));
  // A tuft is pressed when its root lies within this much of the body's footprint: the rods lean
  // away from the body, so the bent grass reaches a little beyond it (m).
  const float margin = 0.6f * float(toD(w.lattice().spacing));
  std::vector<TrailMemory::Footprint> now = footprintsOf(*scene, margin);
  if (!now.empty() && mem.fadesAt.empty()) mem.fadesAt.assign(size_t(mem.fieldI * mem.fieldJ), 0);
  const int64_t gap = tick - mem.tick;
  const bool sweep = mem.tick >= 0 && gap >= 1 && gap <= kTrailSweepTicks && mem.footprints.size() == now.size();
  const float step = 0.5f * float(toD(w.lattice().spacing));
  for (size_t p = 0; p < now.size(); ++p) {
    const TrailMemory::Footprint& f = now[p];
    const float dist = sweep ? std::hypot(f.x - mem.footprints[p].x, f.z - mem.footprints[p].z) : 0.0f;
    if (!sweep || dist > kTrailSweepMetres || mem.footprints[p].disc != f.disc) {
      stamp(w, f, margin, scaleY, tick, &mem);
      continue;
    }
    // The path since the last extraction, a sample every half grass spacing, each pressed at its
    // own (interpolated) tick, so the trail fades from its old end.
    const TrailMemory::Footprint& before = mem.footprints[p];
    const int64_t samples = std::max<int64_t>(1, int64_t(std::ceil(dist / step)));
    for (int64_t s = 1; s <= samples; ++s) {
      const float t = float(s) / float(samples);
      TrailMemory::Footprint g = f;
      g.x = before.x + (f.x - before.x) * t;
      g.z = before.z + (f.z - before.z) * t;
      g.bottom = before.bottom + (f.bottom - before.bottom) * t;
      stamp(w, g, margin, scaleY, mem.tick + s * gap / samples, &mem);
    }
  }
  mem.footprints = std::move(now);
  mem.tick = tick;
}

/// A patch's trail (0..255) at `tick`: how much of kTrailSeconds is left since a body pressed it.
uint8_t trailAt(const TrailMemory& mem, int64_t patch, int64_t tick) {
  if (mem.fadesAt.empty() || patch < 0 || size_t(patch) >= mem.fadesAt.size()) return 0;
  const int64_t left = int64_t(mem.fadesAt[size_t(patch)]) - tick;
  if (left <= 0) return 0;
  return uint8_t(std::min<int64_t>(255, (left * 255 + mem.fadeTicks - 1) / mem.fadeTicks));
}

template <class S>
void extractTyped(const World<S>& w, const Scenario& scenario, Scene* scene) {
  scene->tick = w.tick();
  scene->atlasVariants = scenario.field.atlasVariants;
  scene->atlasSeed = scenario.seed;
  const float halfWidth = float(scenario.field.scaleXZ.toDouble());
  const float scaleY = float(scenario.field.scaleY.toDouble());
  scene->tuftHeight = scaleY;

  // Simulated tufts: every storage slot of the patch window holds one patch. On the GPU path
  // the device holds the tops (the renderer draws them from its buffer); the roots, rotations
  // and variants are the host's, and nothing is copied back.
  scene->deviceTops = w.devicePatchDrawBuffer();
  scene->deviceTipReach = scene->deviceTops ? float(toD(w.particleConstants().rodLength)) : 0.0f;
  const bool onDevice = scene->deviceTops != 0;
  const PatchArrays<S>& p = onDevice ? w.hostPatches() : w.patches();
  const LatticeWindow& win = w.patchWindow();
  const size_t n = size_t(win.size());
  scene->tufts.resize(n);
  for (size_t k = 0; k < n; ++k) {
    TuftInstance& t = scene->tufts[k];
    t.x = float(toD(p.rootX[k]));
    t.y = float(toD(p.rootY[k]));
    t.z = float(toD(p.rootZ[k]));
    t.halfWidth = halfWidth;
    if (onDevice) {  // placeholders: a tuft standing straight
      t.topY = t.y + scaleY;
      t.tipX = t.tipZ = 0;
      t.level = 0;
    } else {
      t.topY = float(toD(p.topY[k]));
      t.tipX = float(toD(p.tipOffsetX[k]));
      t.tipZ = float(toD(p.tipOffsetZ[k]));
      t.level = p.cut[k] ? uint8_t(3) : p.tiltLevel[k];  // thesis §5: mown tufts stay brighter
    }
    t.angle = float(p.rotation[k]) * kTurn;
    t.variant = p.variant[k];
    t.heat = 0;
    t.trail = 0;
  }
  scene->simulatedTufts = n;
  scene->windowOriginI = win.originI;
  scene->windowOriginJ = win.originJ;
  scene->windowWidth = win.sizeI;
  scene->windowHeight = win.sizeJ;
  scene->fieldPatchesX = win.fieldI;
  scene->fieldPatchesZ = win.fieldJ;

  // Edge ring (level of detail): static tufts, standing straight.
  extractRing(w, scenario, halfWidth, scaleY, scene);
  scene->tufts.insert(scene->tufts.end(), scene->ring.tufts.begin(), scene->ring.tufts.end());

  // Bodies: one draw per part; a body with a mesh is one mesh draw, its parts kept as proxies.
  scene->bodyParts.clear();
  scene->meshProxies.clear();
  const auto& bodies = w.bodies();
  for (size_t b = 0; b < bodies.size(); ++b) {
    const RigidBody<S>& body = bodies[b];
    // A spawned body looks like the scenario body it copies (SimWorld::bodyTemplate).
    const int32_t spec = w.bodyTemplate(int64_t(b));
    const bool known = spec >= 0 && size_t(spec) < scenario.bodies.list.size();
    const std::string name = known ? scenario.bodies.list[size_t(spec)].name : std::string();
    const std::string mesh = known ? scenario.bodies.list[size_t(spec)].mesh : std::string();
    if (!mesh.empty()) {
      BodyPartDraw d;
      d.shape = BodyPartDraw::Shape::Mesh;
      d.mesh = mesh;
      const Mat3<S>& rotation = body.rotation;
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) d.model[size_t(c * 4 + r)] = float(toD(rotation(r, c)));
      // The mesh is authored around the scenario's origin for the body, not its centre of mass.
      const Vec3<S> origin = body.position - rotation * body.centreOfMassLocal;
      for (int r = 0; r < 3; ++r) d.model[size_t(12 + r)] = float(toD(origin[r]));
      paint(d, name, body.mower, b);
      d.firstProxy = uint32_t(scene->meshProxies.size());
      d.proxyCount = uint32_t(body.parts.size());
      scene->bodyParts.push_back(d);
    }
    std::vector<BodyPartDraw>& target = mesh.empty() ? scene->bodyParts : scene->meshProxies;
    for (size_t i = 0; i < body.parts.size(); ++i) {
      const BodyPart<S>& part = body.parts[i];
      const Pose<S> pose = body.partPose(i);
      BodyPartDraw d;
      d.shape = part.type == ShapeType::Sphere ? BodyPartDraw::Shape::Sphere : BodyPartDraw::Shape::Box;
      float scale[3];
      if (part.type == ShapeType::Sphere) {
        scale[0] = scale[1] = scale[2] = float(toD(part.radius));
      } else {
        for (int a = 0; a < 3; ++a) scale[a] = float(toD(part.halfExtents[a]));
      }
      // model = T * R * S (column-major).
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) d.model[size_t(c * 4 + r)] = float(toD(pose.rotation(r, c))) * scale[c];
      for (int r = 0; r < 3; ++r) d.model[size_t(12 + r)] = float(toD(pose.position[r]));
      paint(d, name, body.mower, b);
      target.push_back(d);
    }
  }

  // Trails: where bodies pressed the grass (render-side memory), and the blade model's trampling.
  updateTrails(w, scenario, scaleY, scene);
  const TrailMemory& mem = scene->trails;
  // (On the device the trample levels are the device's patch stage's, in its draw buffer.)
  const ParticleArrays<S>& pa = onDevice ? w.hostParticles() : w.particles();
  const ParticleGrid& grid = w.particleGrid();
  const bool trampling = !onDevice && !pa.trample.empty();
  if (!mem.fadesAt.empty() || trampling) {
    for (size_t k = 0; k < n; ++k) {
      const int64_t i = win.latticeColumn(int64_t(k) % win.sizeI), j = win.latticeRow(int64_t(k) / win.sizeI);
      uint8_t t = trailAt(mem, j * win.fieldI + i, scene->tick);
      if (trampling) {  // the particle this patch takes its motion from (its lower-left one)
        const int64_t I = i / grid.k, J = j / grid.k;
        if (grid.window.contains(I, J)) {
          const double level = std::clamp(toD(pa.trample[grid.window.storageIndex(I, J)]), 0.0, 1.0);
          t = std::max(t, uint8_t(std::lround(255.0 * level)));
        }
      }
      scene->tufts[k].trail = t;
    }
    for (size_t r = 0; r < scene->ring.patch.size(); ++r)
      scene->tufts[n + r].trail = trailAt(mem, scene->ring.patch[r], scene->tick);
  }

  // Focus: the simulated window (the whole field with the level of detail off).
  const double spacing = toD(w.lattice().spacing);
  const double ox = toD(w.lattice().originX), oz = toD(w.lattice().originZ);
  scene->focusMinX = float(ox + spacing * double(win.originI));
  scene->focusMaxX = float(ox + spacing * double(win.endI() - 1));
  scene->focusMinZ = float(oz + spacing * double(win.originJ));
  scene->focusMaxZ = float(oz + spacing * double(win.endJ() - 1));
  const double cx = 0.5 * (scene->focusMinX + scene->focusMaxX), cz = 0.5 * (scene->focusMinZ + scene->focusMaxZ);
  scene->groundHeightAtFocus = float(toD(w.terrain().heightAt(fromD<S>(cx), fromD<S>(cz))));

  const uint64_t key = groundKey(scenario);
  if (scene->ground.heights.empty() || scene->ground.key != key) {
    extractGround(w, scenario, &scene->ground);
    scene->ground.key = key;
  }
}

// ---- debug overlay ---------------------------------------------------------------------------

using Line = DebugScene::Line;
using Point = DebugScene::Point;

void addLine(DebugScene* d, const float a[3], const float b[3], const float colour[3]) {
  Line l;
  for (int k = 0; k < 3; ++k) l.a[k] = a[k], l.b[k] = b[k], l.colour[k] = colour[k];
  d->lines.push_back(l);
}

void addPoint(DebugScene* d, const float p[3], float size, const float colour[3]) {
  Point q;
  for (int k = 0; k < 3; ++k) q.p[k] = p[k], q.colour[k] = colour[k];
  q.size = size;
  d->points.push_back(q);
}

/// Wireframe of a primitive at a pose: a box's 12 edges, or a sphere's three great circles.
template <class S>
void addPrimitive(DebugScene* d, const BodyPart<S>& part, const Pose<S>& pose, const float colour[3]) {
  float c[3], axes[3][3];  // centre; world axes scaled by the half extents or radius
  for (int r = 0; r < 3; ++r) c[r] = float(toD(pose.position[r]));
  for (int a = 0; a < 3; ++a) {
    const float scale = float(toD(part.type == ShapeType::Sphere ? part.radius : part.halfExtents[a]));
    for (int r = 0; r < 3; ++r) axes[a][r] = float(toD(pose.rotation(r, a))) * scale;
  }
  auto at = [&](float u, int ua, float v, int va, float w, int wa, float* out) {
    for (int r = 0; r < 3; ++r) out[r] = c[r] + u * axes[ua][r] + v * axes[va][r] + w * axes[wa][r];
  };
  if (part.type == ShapeType::Sphere) {
    constexpr int kSegments = 24;
    for (int plane = 0; plane < 3; ++plane) {
      const int ua = plane, va = (plane + 1) % 3, wa = (plane + 2) % 3;
      for (int s = 0; s < kSegments; ++s) {
        const float t0 = 6.2831853f * float(s) / kSegments, t1 = 6.2831853f * float(s + 1) / kSegments;
        float a[3], b[3];
        at(std::cos(t0), ua, std::sin(t0), va, 0, wa, a);
        at(std::cos(t1), ua, std::sin(t1), va, 0, wa, b);
        addLine(d, a, b, colour);
      }
    }
    return;
  }
  for (int axis = 0; axis < 3; ++axis) {  // 4 edges along each axis
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int k = 0; k < 4; ++k) {
      const float su = (k & 1) ? 1.0f : -1.0f, sv = (k & 2) ? 1.0f : -1.0f;
      float a[3], b[3];
      at(-1, axis, su, u, sv, v, a);
      at(1, axis, su, u, sv, v, b);
      addLine(d, a, b, colour);
    }
  }
}

template <class S>
void extractDebugTyped(const World<S>& w, const Scenario& scenario, const DebugFlags& flags, Scene* scene) {
  DebugScene* d = &scene->debug;
  d->lines.clear();
  d->points.clear();
  const ParticleArrays<S>& pa = w.particles();
  const size_t n = size_t(w.particleGrid().size());
  static const float kParticle[3] = {1.0f, 0.85f, 0.10f}, kRod[3] = {0.95f, 0.95f, 0.95f};
  static const float kPrimitive[3] = {0.10f, 1.0f, 1.0f}, kCell[3] = {1.0f, 0.30f, 1.0f};
  static const float kContact[3] = {1.0f, 0.10f, 0.10f};
  for (size_t i = 0; i < n && (flags.particles || flags.constraints); ++i) {
    const float p[3] = {float(toD(pa.px[i])), float(toD(pa.py[i])), float(toD(pa.pz[i]))};
    if (flags.particles) addPoint(d, p, 2.0f, kParticle);
    if (flags.constraints) {
      const float root[3] = {float(toD(pa.anchorX[i])), float(toD(pa.anchorY[i])), float(toD(pa.anchorZ[i]))};
      addLine(d, root, p, kRod);
    }
  }
  if (flags.primitives)
    for (const RigidBody<S>& body : w.bodies())
      for (size_t i = 0; i < body.parts.size(); ++i) addPrimitive(d, body.parts[i], body.partPose(i), kPrimitive);
  if (flags.cells) {
    // The body-particle broad phase's candidate cells (sim/collision/body_particles.h): the same
    // ranges the collision stage computes, from the same settings World<S> derives.
    const ScenarioConstants c = deriveConstants(scenario);
    BodyParticleSettings<S> settings;
    settings.broadphase = ParticleBroadphase::Grid;  // brute has no cells; show what grid would test
    S largest(0);
    for (const RigidBody<S>& b : w.bodies()) largest = maxS(largest, b.boundingRadius);
    settings.margin = fromD<S>(scenario.particles.constraintLength.toDouble()) + w.lattice().jitterAmplitude + largest;
    settings.anchorOriginX = w.lattice().originX;
    settings.anchorOriginZ = w.lattice().originZ;
    settings.invParticleSpacing = fromD<S>(c.invParticleSpacing.toDouble());
    std::set<std::pair<int64_t, int64_t>> cells;  // ordered: a deterministic line order
    for (const ParticleRange& r : particleRanges(w.bodies(), w.particleGrid(), settings))
      for (int64_t b = r.b0; b <= r.b1; ++b)
        for (int64_t a = r.a0; a <= r.a1; ++a) cells.insert({b, a});
    // Cell (a, b) is the square of one particle spacing around particle (a, b)'s un-jittered
    // anchor, drawn 2 cm above the terrain at its centre.
    const double ks = 1.0 / c.invParticleSpacing.toDouble();
    const double ox = toD(w.lattice().originX), oz = toD(w.lattice().originZ);
    for (const auto& [b, a] : cells) {
      const double x0 = ox + (double(a) - 0.5) * ks, x1 = x0 + ks, z0 = oz + (double(b) - 0.5) * ks, z1 = z0 + ks;
      const float y = float(toD(w.terrain().heightAt(fromD<S>(0.5 * (x0 + x1)), fromD<S>(0.5 * (z0 + z1))))) + 0.02f;
      const float corners[4][3] = {
          {float(x0), y, float(z0)}, {float(x1), y, float(z0)}, {float(x1), y, float(z1)}, {float(x0), y, float(z1)}};
      for (int k = 0; k < 4; ++k) addLine(d, corners[k], corners[(k + 1) % 4], kCell);
    }
  }
  if (flags.contacts)
    for (const Contact<S>& ct : w.contacts()) {
      const float p[3] = {float(toD(ct.point.x())), float(toD(ct.point.y())), float(toD(ct.point.z()))};
      const float q[3] = {p[0] + 0.25f * float(toD(ct.normal.x())), p[1] + 0.25f * float(toD(ct.normal.y())),
                          p[2] + 0.25f * float(toD(ct.normal.z()))};
      addPoint(d, p, 7.0f, kContact);
      addLine(d, p, q, kContact);
    }
}

// ---- interpolation ---------------------------------------------------------------------------

/// Rotation quaternion (w, x, y, z) of a model matrix's upper 3x3 after dividing out the column
/// scales (Shepperd's method).
void toQuaternion(const Mat4& m, const float scale[3], float q[4]) {
  auto R = [&](int r, int c) { return m[size_t(c * 4 + r)] / scale[c]; };
  const float trace = R(0, 0) + R(1, 1) + R(2, 2);
  if (trace > 0) {
    const float s = 2 * std::sqrt(trace + 1);
    q[0] = 0.25f * s, q[1] = (R(2, 1) - R(1, 2)) / s, q[2] = (R(0, 2) - R(2, 0)) / s, q[3] = (R(1, 0) - R(0, 1)) / s;
  } else if (R(0, 0) > R(1, 1) && R(0, 0) > R(2, 2)) {
    const float s = 2 * std::sqrt(1 + R(0, 0) - R(1, 1) - R(2, 2));
    q[0] = (R(2, 1) - R(1, 2)) / s, q[1] = 0.25f * s, q[2] = (R(0, 1) + R(1, 0)) / s, q[3] = (R(0, 2) + R(2, 0)) / s;
  } else if (R(1, 1) > R(2, 2)) {
    const float s = 2 * std::sqrt(1 + R(1, 1) - R(0, 0) - R(2, 2));
    q[0] = (R(0, 2) - R(2, 0)) / s, q[1] = (R(0, 1) + R(1, 0)) / s, q[2] = 0.25f * s, q[3] = (R(1, 2) + R(2, 1)) / s;
  } else {
    const float s = 2 * std::sqrt(1 + R(2, 2) - R(0, 0) - R(1, 1));
    q[0] = (R(1, 0) - R(0, 1)) / s, q[1] = (R(0, 2) + R(2, 0)) / s, q[2] = (R(1, 2) + R(2, 1)) / s, q[3] = 0.25f * s;
  }
}

/// Interpolated part pose: translation lerped, rotation slerped (shortest arc), current's scale.
Mat4 lerpModel(const Mat4& a, const Mat4& b, float t) {
  float sa[3], sb[3];
  for (int c = 0; c < 3; ++c) {
    sa[c] = std::sqrt(a[size_t(c * 4)] * a[size_t(c * 4)] + a[size_t(c * 4 + 1)] * a[size_t(c * 4 + 1)] +
                      a[size_t(c * 4 + 2)] * a[size_t(c * 4 + 2)]);
    sb[c] = std::sqrt(b[size_t(c * 4)] * b[size_t(c * 4)] + b[size_t(c * 4 + 1)] * b[size_t(c * 4 + 1)] +
                      b[size_t(c * 4 + 2)] * b[size_t(c * 4 + 2)]);
    if (sa[c] < 1e-12f || sb[c] < 1e-12f) return b;  // degenerate: no rotation to recover
  }
  float qa[4], qb[4], q[4];
  toQuaternion(a, sa, qa);
  toQuaternion(b, sb, qb);
  float dot = qa[0] * qb[0] + qa[1] * qb[1] + qa[2] * qb[2] + qa[3] * qb[3];
  if (dot < 0) {
    for (float& v : qb) v = -v;
    dot = -dot;
  }
  float wa = 1 - t, wb = t;
  if (dot < 0.9995f) {  // slerp; nearly parallel: the lerp below is as good and stable
    const float theta = std::acos(std::min(dot, 1.0f)), s = std::sin(theta);
    wa = std::sin((1 - t) * theta) / s;
    wb = std::sin(t * theta) / s;
  }
  float len = 0;
  for (int k = 0; k < 4; ++k) q[k] = wa * qa[k] + wb * qb[k], len += q[k] * q[k];
  len = std::sqrt(len);
  for (float& v : q) v /= len;
  const float w = q[0], x = q[1], y = q[2], z = q[3];
  const float R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                         {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                         {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  Mat4 m = b;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) m[size_t(c * 4 + r)] = R[r][c] * sb[c];
  for (int r = 0; r < 3; ++r) m[size_t(12 + r)] = a[size_t(12 + r)] + (b[size_t(12 + r)] - a[size_t(12 + r)]) * t;
  return m;
}

void lerpParts(const std::vector<BodyPartDraw>& previous, std::vector<BodyPartDraw>* parts, float t) {
  if (previous.size() != parts->size()) return;
  for (size_t i = 0; i < parts->size(); ++i)
    if (previous[i].shape == (*parts)[i].shape) (*parts)[i].model = lerpModel(previous[i].model, (*parts)[i].model, t);
}

}  // namespace

void extractScene(const SimWorld& world, const Scenario& scenario, Scene* scene) {
  dispatchScalar(world.scalar(), [&]<class S>() {
    if (const World<S>* w = typed<S>(world)) extractTyped(*w, scenario, scene);
  });
}

void extractDebug(const SimWorld& world, const Scenario& scenario, const DebugFlags& flags, Scene* scene) {
  scene->debug.lines.clear();
  scene->debug.points.clear();
  if (!flags.any()) return;
  dispatchScalar(world.scalar(), [&]<class S>() {
    if (const World<S>* w = typed<S>(world)) extractDebugTyped(*w, scenario, flags, scene);
  });
}

void interpolateScene(const Scene& previous, const Scene& current, float alpha, Scene* out) {
  *out = current;
  const float t = std::clamp(alpha, 0.0f, 1.0f);
  if (t >= 1.0f) return;  // exactly current
  if (t <= 0.0f) {        // exactly previous' tufts and poses, current's everything else
    if (previous.tufts.size() == current.tufts.size() && previous.simulatedTufts == current.simulatedTufts &&
        previous.windowOriginI == current.windowOriginI && previous.windowOriginJ == current.windowOriginJ &&
        previous.windowWidth == current.windowWidth && previous.windowHeight == current.windowHeight) {
      out->tufts = previous.tufts;
      if (previous.deviceTops != 0 && current.deviceTops != 0) out->deviceTops = previous.deviceTops;
    }
    if (previous.bodyParts.size() == current.bodyParts.size()) out->bodyParts = previous.bodyParts;
    if (previous.meshProxies.size() == current.meshProxies.size()) out->meshProxies = previous.meshProxies;
    return;
  }
  // The same layout: the same window (origin and size) holds the same patches in the same slots.
  const bool sameLayout =
      previous.simulatedTufts == current.simulatedTufts && previous.tufts.size() >= previous.simulatedTufts &&
      previous.windowOriginI == current.windowOriginI && previous.windowOriginJ == current.windowOriginJ &&
      previous.windowWidth == current.windowWidth && previous.windowHeight == current.windowHeight;
  if (sameLayout)
    for (size_t k = 0; k < current.simulatedTufts; ++k) {
      const TuftInstance& a = previous.tufts[k];
      TuftInstance& o = out->tufts[k];
      o.topY = a.topY + (o.topY - a.topY) * t;
      o.tipX = a.tipX + (o.tipX - a.tipX) * t;
      o.tipZ = a.tipZ + (o.tipZ - a.tipZ) * t;
    }
  // On the device path the tops are in the device's two draw buffers: the renderer blends them
  // the same way (its tuft vertex shader).
  if (sameLayout && current.deviceTops != 0 && previous.deviceTops != 0 && previous.deviceTops != current.deviceTops) {
    out->deviceTopsPrevious = previous.deviceTops;
    out->deviceTopsAlpha = t;
  }
  lerpParts(previous.bodyParts, &out->bodyParts, t);
  lerpParts(previous.meshProxies, &out->meshProxies, t);
}

void applyDivergenceHeat(const Observation& a, const Observation& b, float fullScaleMetres, Scene* scene) {
  for (TuftInstance& t : scene->tufts) t.heat = 0;
  const size_t patches = size_t(std::max<int64_t>(0, a.patchesX * a.patchesZ));
  if (a.patchesX != b.patchesX || a.patchesZ != b.patchesZ || a.tipX.size() < patches || b.tipX.size() < patches ||
      a.tipY.size() < patches || b.tipY.size() < patches || a.tipZ.size() < patches || b.tipZ.size() < patches ||
      a.patchesX != scene->fieldPatchesX || a.patchesZ != scene->fieldPatchesZ || !(fullScaleMetres > 0))
    return;
  // Storage slot k of the (toroidal) window holds lattice patch (latticeColumn(c), latticeRow(r)).
  LatticeWindow win;
  win.originI = scene->windowOriginI;
  win.originJ = scene->windowOriginJ;
  win.sizeI = scene->windowWidth;
  win.sizeJ = scene->windowHeight;
  win.fieldI = scene->fieldPatchesX;
  win.fieldJ = scene->fieldPatchesZ;
  const size_t n = std::min(scene->simulatedTufts, scene->tufts.size());
  if (win.sizeI <= 0 || size_t(win.size()) != n) return;
  for (size_t k = 0; k < n; ++k) {
    const int64_t i = win.latticeColumn(int64_t(k) % win.sizeI), j = win.latticeRow(int64_t(k) / win.sizeI);
    if (!win.insideField(i, j)) continue;
    const size_t p = size_t(j * a.patchesX + i);
    const double dx = a.tipX[p] - b.tipX[p], dy = a.tipY[p] - b.tipY[p], dz = a.tipZ[p] - b.tipZ[p];
    const double x = std::sqrt(dx * dx + dy * dy + dz * dz) / double(fullScaleMetres);
    scene->tufts[k].heat = uint8_t(std::lround(255.0 * std::clamp(x, 0.0, 1.0)));
  }
}

float groundHeight(const SimWorld& world, float x, float z) {
  return dispatchScalar(world.scalar(), [&]<class S>() -> float {
    const World<S>* w = typed<S>(world);
    return w ? float(toD(w->terrain().heightAt(fromD<S>(x), fromD<S>(z)))) : 0.0f;
  });
}

Camera defaultCamera(const Scene& scene, const SimWorld& world, float aspect) {
  if (!scene.bodyParts.empty()) {
    // The bodies' bounds: each part's centre plus its largest scale (a radius or half extent; a
    // mesh's model holds no scale, so its size is not known here: 0.5 m).
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (const BodyPartDraw& p : scene.bodyParts) {
      float extent = 0.5f;
      if (p.shape != BodyPartDraw::Shape::Mesh)
        for (size_t c = 0; c < 3; ++c) {
          const float* col = &p.model[c * 4];
          extent = std::max(extent, std::sqrt(col[0] * col[0] + col[1] * col[1] + col[2] * col[2]));
        }
      for (size_t a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], p.model[12 + a] - extent);
        hi[a] = std::max(hi[a], p.model[12 + a] + extent);
      }
    }
    for (size_t a = 0; a < 3; ++a) {  // at least 3 m across: a lone ball is seen with grass around it
      const float grow = std::max(0.0f, 1.5f - 0.5f * (hi[a] - lo[a]));
      lo[a] -= grow;
      hi[a] += grow;
    }
    const float tx = 0.5f * (lo[0] + hi[0]), ty = 0.5f * (lo[1] + hi[1]), tz = 0.5f * (lo[2] + hi[2]);
    const float elevation = 20 * Camera::kRadians;
    auto at = [&](float distance) {
      const float ex = tx, ez = tz - distance * std::cos(elevation);
      const float ey = std::max(ty + distance * std::sin(elevation), groundHeight(world, ex, ez) + 1.7f);
      return Camera::lookingAt(ex, ey, ez, tx, ty, tz);
    };
    auto fits = [&](const Camera& c) {
      const Mat4 m = multiply(c.projection(aspect), c.view());
      for (int corner = 0; corner < 8; ++corner) {
        const float p[3] = {corner & 1 ? hi[0] : lo[0], corner & 2 ? hi[1] : lo[1], corner & 4 ? hi[2] : lo[2]};
        float clip[4];
        for (size_t r = 0; r < 4; ++r) clip[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
        if (clip[3] <= c.nearPlane || std::fabs(clip[0]) > 0.8f * clip[3] || std::fabs(clip[1]) > 0.8f * clip[3])
          return false;
      }
      return true;
    };
    // The nearest distance that fits, in 5 % steps (bounds of any size: at most ~330 steps to 10 km).
    float distance = 1;
    while (distance < 1e4f && !fits(at(distance))) distance *= 1.05f;
    return at(distance);
  }
  const float cx = 0.5f * (scene.focusMinX + scene.focusMaxX), cz = 0.5f * (scene.focusMinZ + scene.focusMaxZ);
  const float ez = scene.focusMinZ - 1.0f;
  const float eyeY = groundHeight(world, cx, ez) + 1.7f;
  return Camera::lookingAt(cx, eyeY, ez, cx, scene.groundHeightAtFocus, cz);
}

}  // namespace sg::viewer
