#include "viewer/render/scene.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <string>

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
  if (d.shape == BodyPartDraw::Shape::Box && nameHas(name, "box")) return setColour(d, 0.60f, 0.42f, 0.22f);
  static const float palette[][3] = {{0.25f, 0.40f, 0.75f}, {0.80f, 0.60f, 0.15f}, {0.55f, 0.25f, 0.60f},
                                     {0.20f, 0.60f, 0.60f}, {0.75f, 0.35f, 0.30f}};
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
  g->xs = gridLines(x0 - margin, x1 + margin, step, 512);
  g->zs = gridLines(z0 - margin, z1 + margin, step, 512);
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

template <class S>
void extractTyped(const World<S>& w, const Scenario& scenario, Scene* scene) {
  scene->tick = w.tick();
  scene->atlasVariants = scenario.field.atlasVariants;
  scene->atlasSeed = scenario.seed;
  const float halfWidth = float(scenario.field.scaleXZ.toDouble());
  const float scaleY = float(scenario.field.scaleY.toDouble());
  scene->tuftHeight = scaleY;

  // Simulated tufts: every storage slot of the patch window holds one patch.
  const PatchArrays<S>& p = w.patches();
  const LatticeWindow& win = w.patchWindow();
  const size_t n = size_t(win.size());
  scene->tufts.resize(n);
  for (size_t k = 0; k < n; ++k) {
    TuftInstance& t = scene->tufts[k];
    t.x = float(toD(p.rootX[k]));
    t.y = float(toD(p.rootY[k]));
    t.z = float(toD(p.rootZ[k]));
    t.halfWidth = halfWidth;
    t.topY = float(toD(p.topY[k]));
    t.tipX = float(toD(p.tipOffsetX[k]));
    t.tipZ = float(toD(p.tipOffsetZ[k]));
    t.angle = float(p.rotation[k]) * kTurn;
    t.variant = p.variant[k];
    t.level = p.cut[k] ? uint8_t(3) : p.tiltLevel[k];  // thesis §5: mown tufts stay brighter
  }
  scene->simulatedTufts = n;

  // Edge ring (level of detail): static tufts, standing straight.
  const EdgeRing<S>& ring = w.edgeRing();
  const std::vector<size_t> cells = ring.visibleCells();
  const float ringHalfWidth = halfWidth * std::sqrt(float(std::max<int64_t>(1, ring.spacingMultiple)));
  const double cutTop = std::max(scenario.bodies.mowerCutHeight.toDouble(), scaleY / 10.0);
  for (const size_t q : cells) {
    TuftInstance t{};
    t.x = float(toD(ring.x[q]));
    t.y = float(toD(ring.y[q]));
    t.z = float(toD(ring.z[q]));
    t.halfWidth = ringHalfWidth;
    t.topY = t.y + (ring.cut[q] ? float(std::min<double>(cutTop, scaleY)) : scaleY);
    t.tipX = t.tipZ = 0;
    t.angle = float(ring.rotation[q]) * kTurn;
    t.variant = ring.variant[q];
    t.level = ring.cut[q] ? 3 : 0;
    scene->tufts.push_back(t);
  }

  // Bodies: one draw per part.
  scene->bodyParts.clear();
  const auto& bodies = w.bodies();
  for (size_t b = 0; b < bodies.size(); ++b) {
    const RigidBody<S>& body = bodies[b];
    const std::string name = b < scenario.bodies.list.size() ? scenario.bodies.list[b].name : std::string();
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
      scene->bodyParts.push_back(d);
    }
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

}  // namespace

void extractScene(const SimWorld& world, const Scenario& scenario, Scene* scene) {
  dispatchScalar(world.scalar(), [&]<class S>() {
    if (const World<S>* w = typed<S>(world)) extractTyped(*w, scenario, scene);
  });
}

float groundHeight(const SimWorld& world, float x, float z) {
  return dispatchScalar(world.scalar(), [&]<class S>() -> float {
    const World<S>* w = typed<S>(world);
    return w ? float(toD(w->terrain().heightAt(fromD<S>(x), fromD<S>(z)))) : 0.0f;
  });
}

Camera defaultCamera(const Scene& scene, const SimWorld& world) {
  const float cx = 0.5f * (scene.focusMinX + scene.focusMaxX), cz = 0.5f * (scene.focusMinZ + scene.focusMaxZ);
  const float ez = scene.focusMinZ - 1.0f;
  const float eyeY = groundHeight(world, cx, ez) + 1.7f;
  return Camera::lookingAt(cx, eyeY, ez, cx, scene.groundHeightAtFocus, cz);
}

}  // namespace sg::viewer
