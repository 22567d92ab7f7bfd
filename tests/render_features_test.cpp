// Renderer features (docs/rendering.md): SSAO, the rock blend, OBJ meshes, the debug overlay, the
// divergence heat map and display interpolation; `simgrass render`'s flags for them. Rendered
// offscreen with OSMesa like tests/render_test.cpp; every check compares two renders that differ
// in one option, or compares against independently computed geometry (projections, ray casts,
// analytic midpoints), never against hard-coded pixel values.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include "sim/world/world.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"
#include "viewer/offscreen/osmesa_context.h"
#include "viewer/render/obj_mesh.h"
#include "viewer/render/renderer.h"
#include "viewer/render/scene.h"

namespace sg {
namespace {
namespace fs = std::filesystem;
using viewer::Camera;
using viewer::Image;
using viewer::Scene;

constexpr int kWidth = 320, kHeight = 240;

/// One offscreen renderer for the suite (4x MSAA like the goldens); its context is made current
/// on every render, so it lives beside render_test.cpp's.
viewer::OffscreenRenderer& offscreen() {
  static std::unique_ptr<viewer::OffscreenRenderer> r = [] {
    std::string error;
    auto made = viewer::OffscreenRenderer::create(kWidth, kHeight, 4, &error);
    if (!made) ADD_FAILURE() << error;
    return made;
  }();
  if (!r) throw std::runtime_error("no offscreen renderer");
  return *r;
}

/// Renders with `options` (the renderer's options are restored afterwards).
Image renderWith(const Scene& scene, const Camera& camera, const viewer::RenderOptions& options) {
  viewer::OffscreenRenderer& r = offscreen();
  const viewer::RenderOptions saved = r.options();
  r.options() = options;
  Image img = r.render(scene, camera);
  r.options() = saved;
  return img;
}

/// Fraction of pixels with some channel off by more than `tolerance`.
double differingFraction(const Image& a, const Image& b, int tolerance = 2) {
  size_t n = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      for (int c = 0; c < 3; ++c)
        if (std::abs(int(a.at(x, y)[c]) - int(b.at(x, y)[c])) > tolerance) {
          ++n;
          break;
        }
  return double(n) / (double(a.width) * double(a.height));
}

double luminance(const Image& img, int x, int y) {
  const uint8_t* p = img.at(x, y);
  return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

/// Mean luminance over a (2r+1)^2 window.
double meanLuminance(const Image& img, int cx, int cy, int r) {
  double sum = 0;
  int n = 0;
  for (int y = std::max(0, cy - r); y <= std::min(img.height - 1, cy + r); ++y)
    for (int x = std::max(0, cx - r); x <= std::min(img.width - 1, cx + r); ++x) sum += luminance(img, x, y), ++n;
  return n ? sum / n : 0;
}

/// Pixel (top row 0) of a world point, from the camera's own matrices.
bool project(const Camera& c, float x, float y, float z, int* px, int* py) {
  const viewer::Mat4 m = viewer::multiply(c.projection(float(kWidth) / float(kHeight)), c.view());
  const float cx = m[0] * x + m[4] * y + m[8] * z + m[12], cy = m[1] * x + m[5] * y + m[9] * z + m[13];
  const float cw = m[3] * x + m[7] * y + m[11] * z + m[15];
  if (cw <= 0) return false;
  *px = int(std::floor((cx / cw * 0.5f + 0.5f) * kWidth));
  *py = int(std::floor((0.5f - cy / cw * 0.5f) * kHeight));
  return *px >= 0 && *px < kWidth && *py >= 0 && *py < kHeight;
}

struct Loaded {
  Scenario scenario;
  std::unique_ptr<SimWorld> world;
};

Loaded load(const char* file, int64_t ticks = 0) {
  Loaded l;
  l.scenario = loadScenarioFile(test::sourcePath(std::string("scenarios/") + file));
  l.world = makeWorld(l.scenario);
  while (l.world->tick() < ticks) {
    const StepResult r = l.world->step(scriptedInput(l.scenario, l.world->tick()));
    if (!r.ok) throw std::runtime_error(r.error.message());
  }
  return l;
}

/// Flat ground only (the thesis meadow's), no tufts, no bodies.
Scene flatGround() {
  const Loaded l = load("thesis-meadow.json");
  Scene s;
  viewer::extractScene(*l.world, l.scenario, &s);
  s.tufts.clear();
  s.simulatedTufts = 0;
  s.bodyParts.clear();
  return s;
}

viewer::BodyPartDraw boxPart(float cx, float cy, float cz, float half) {
  viewer::BodyPartDraw b;
  b.shape = viewer::BodyPartDraw::Shape::Box;
  b.model = viewer::identity4();
  b.model[0] = b.model[5] = b.model[10] = half;
  b.model[12] = cx, b.model[13] = cy, b.model[14] = cz;
  b.colour[0] = 0.6f, b.colour[1] = 0.42f, b.colour[2] = 0.22f;
  return b;
}

// ---- OBJ meshes --------------------------------------------------------------------------------

std::string objPath(const char* name) { return test::sourcePath(std::string("tests/data/obj/") + name); }

TEST(RenderObj, CubeHasEightVerticesTwelveTrianglesAndUnitOutwardNormals) {
  viewer::ObjMesh mesh;
  std::string error;
  ASSERT_TRUE(viewer::loadObjMesh(objPath("cube.obj"), &mesh, &error)) << error;
  EXPECT_EQ(mesh.objVertices, size_t(8));
  EXPECT_EQ(mesh.triangles(), size_t(12)) << "6 quads, fan-triangulated";
  ASSERT_EQ(mesh.positions.size(), mesh.normals.size());
  for (size_t i = 0; i < mesh.normals.size(); i += 3) {
    const float* n = &mesh.normals[i];
    const float* p = &mesh.positions[i];
    EXPECT_NEAR(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0f, 1e-5f);
    // A corner's smooth normal averages its three faces' outward normals: it points into the
    // corner's octant, away from the centre.
    for (int a = 0; a < 3; ++a) EXPECT_GT(n[a] * p[a], 0.0f) << "vertex " << i / 3 << " axis " << a;
  }
  for (uint32_t idx : mesh.indices) EXPECT_LT(idx, mesh.positions.size() / 3);
}

TEST(RenderObj, PolygonsTexturedCornersAndNegativeIndices) {
  viewer::ObjMesh mesh;
  std::string error;
  ASSERT_TRUE(viewer::loadObjMesh(objPath("mixed-forms.obj"), &mesh, &error)) << error;
  EXPECT_EQ(mesh.triangles(), size_t(4)) << "a pentagon (3) and a triangle";
  for (size_t i = 0; i < mesh.normals.size(); i += 3) EXPECT_EQ(mesh.normals[i + 2], 1.0f) << "the file's vn";
  // The triangle -5 -4 -3 is vertices 1 2 3 (of 5): the last three indices name their positions.
  const size_t t = mesh.indices.size() - 3;
  const float expected[3][2] = {{0, 0}, {1, 0}, {1.5f, 1}};
  for (int k = 0; k < 3; ++k) {
    const float* p = &mesh.positions[size_t(mesh.indices[t + size_t(k)]) * 3];
    EXPECT_EQ(p[0], expected[k][0]);
    EXPECT_EQ(p[1], expected[k][1]);
  }
}

TEST(RenderObj, BadFilesGiveOneLineWithTheirLineNumber) {
  const struct {
    const char* file;
    int line;
  } cases[] = {{"bad-number.obj", 3},  {"short-vertex.obj", 3}, {"index-range.obj", 5},   {"zero-index.obj", 4},
               {"short-face.obj", 3},  {"normal-range.obj", 6}, {"no-faces.obj", 4},      {"negative-range.obj", 4},
               {"bad-texture.obj", 4}, {"not-finite.obj", 5},   {"does-not-exist.obj", 0}};
  for (const auto& c : cases) {
    viewer::ObjMesh mesh;
    std::string error;
    EXPECT_FALSE(viewer::loadObjMesh(objPath(c.file), &mesh, &error)) << c.file;
    const std::string prefix = objPath(c.file) + ":" + std::to_string(c.line) + ": expected ";
    EXPECT_EQ(error.rfind(prefix, 0), size_t(0)) << c.file << ": " << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << c.file;
  }
}

/// parseObjMesh's error for `text` ("" when it was accepted).
std::string objError(const std::string& text) {
  viewer::ObjMesh mesh;
  std::string error;
  return viewer::parseObjMesh(text, "m.obj", &mesh, &error) ? std::string() : error;
}

TEST(RenderObj, NumbersOutOfRangeOrNotFiniteAreRefused) {
  // from_chars reports overflow; NaN and infinity parse but are refused; so is a coordinate past
  // 1e6 m (its normal sums would overflow float).
  for (const char* bad : {"1e39", "-1e39", "nan", "inf", "-inf", "1e7", "-1000001", "0x10", "1.5.2", "+1"}) {
    const std::string e = objError(std::string("v 0 0 0\nv 1 0 0\nv 0 ") + bad + " 0\nf 1 2 3\n");
    EXPECT_EQ(e.rfind("m.obj:3: expected a finite number within +-1e6, got '", 0), size_t(0)) << bad << ": " << e;
  }
  EXPECT_EQ(objError("v 0 0 0\nv 1e6 0 0\nv 0 -1e6 0\nf 1 2 3\n"), "") << "the bound itself is allowed";
  EXPECT_EQ(
      objError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n").rfind("m.obj:4: expected a vertex index", 0),
      size_t(0))
      << "an index past int64 is an error, not a wrapped number";
}

TEST(RenderObj, EchoedWordsAreShortAndEscaped) {
  const std::string e = objError("v 0 0 " + std::string(100000, '7') + "x\n");
  EXPECT_LT(e.size(), size_t(200)) << e;
  EXPECT_NE(e.find("7777..."), std::string::npos) << e;
  const std::string c = objError(std::string("v 0 0 1\x01\x1b[2J\n"));
  EXPECT_NE(c.find("'1\\x01\\x1b[2J'"), std::string::npos) << c;
  EXPECT_EQ(c.find('\x1b'), std::string::npos) << "no raw control characters";
}

TEST(RenderObj, TriangleCountIsBoundedBeforeTheCornersAreRead) {
  // One face of 4 000 003 corners would be 4 000 001 triangles (192 MiB of corners): refused at
  // its line. 4 000 002 corners (the bound) are read.
  std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
  for (int i = 0; i < 4'000'003; ++i) text += " 1";
  const std::string e = objError(text + "\n");
  EXPECT_EQ(e, "m.obj:4: expected at most 4000000 triangles in the mesh");
  text.resize(text.size() - 2);
  viewer::ObjMesh mesh;
  std::string error;
  ASSERT_TRUE(viewer::parseObjMesh(text, "m.obj", &mesh, &error)) << error;
  EXPECT_EQ(mesh.triangles(), size_t(4'000'000));
  // The bound is over the whole mesh, not per face.
  EXPECT_EQ(objError(text + "\nf 1 2 3\n"), "m.obj:5: expected at most 4000000 triangles in the mesh");
}

TEST(RenderObj, OnePositionWithManyNormalsGivesOneVertexPerPair) {
  // 1//1, 1//2 and 1//1 again: two output vertices for position 1 (a map keyed by the pair).
  viewer::ObjMesh mesh;
  std::string error;
  ASSERT_TRUE(
      viewer::parseObjMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 1 0\n"
                           "f 1//1 2//1 3//1\nf 1//2 2//1 3//1\nf 1//1 3//1 2//1\n",
                           "m.obj", &mesh, &error))
      << error;
  EXPECT_EQ(mesh.positions.size() / 3, size_t(4));
  EXPECT_EQ(mesh.indices[0], mesh.indices[6]);
  EXPECT_NE(mesh.indices[0], mesh.indices[3]);
}

TEST(RenderObj, LoadReadsOnlyBoundedRegularFiles) {
  // A directory (and, by readInputFile, a FIFO or device): refused at line 0 before any read.
  viewer::ObjMesh mesh;
  std::string error;
  EXPECT_FALSE(viewer::loadObjMesh(objPath(""), &mesh, &error));
  EXPECT_NE(error.find(":0: expected a regular file, got a directory"), std::string::npos) << error;
  EXPECT_FALSE(viewer::loadObjMesh("/dev/zero", &mesh, &error));
  EXPECT_NE(error.find(":0: expected a regular file"), std::string::npos) << error;
}

TEST(RenderObj, RandomBytesNeverCrash) {
  uint64_t state = 12345;
  auto next = [&] { return state = state * 6364136223846793005ull + 1442695040888963407ull; };
  const std::string alphabet = "vnft/ -0123456789.e\n#\r";
  for (int round = 0; round < 300; ++round) {
    std::string text;
    const size_t n = size_t(next() >> 54);
    for (size_t i = 0; i < n; ++i) text += alphabet[size_t(next() >> 33) % alphabet.size()];
    viewer::ObjMesh mesh;
    std::string error;
    if (viewer::parseObjMesh(text, "fuzz.obj", &mesh, &error)) {
      for (uint32_t idx : mesh.indices) ASSERT_LT(idx, mesh.positions.size() / 3);
    } else {
      ASSERT_EQ(error.rfind("fuzz.obj:", 0), size_t(0)) << error;
      ASSERT_EQ(error.find('\n'), std::string::npos);
    }
  }
}

// ---- meshes in the renderer -----------------------------------------------------------------

/// The scene with every mesh body replaced by its primitives.
Scene withProxies(const Scene& s) {
  Scene out = s;
  out.bodyParts.clear();
  for (const viewer::BodyPartDraw& b : s.bodyParts) {
    if (b.shape != viewer::BodyPartDraw::Shape::Mesh) {
      out.bodyParts.push_back(b);
      continue;
    }
    for (uint32_t i = 0; i < b.proxyCount; ++i) out.bodyParts.push_back(s.meshProxies[b.firstProxy + i]);
  }
  out.meshProxies.clear();
  return out;
}

TEST(RenderMesh, MeshBodiesChangeTheImageAndAMissingMeshFallsBackToPrimitives) {
  const Loaded l = load("mesh-bodies.json");
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  size_t meshes = 0;
  for (const auto& b : scene.bodyParts) meshes += b.shape == viewer::BodyPartDraw::Shape::Mesh ? 1 : 0;
  ASSERT_EQ(meshes, size_t(2)) << "the rock and the crate";
  ASSERT_EQ(scene.meshProxies.size(), size_t(2)) << "their collision sphere and box";
  // Look at the rock (bunny position) and crate from near, grass cleared so they show whole.
  scene.tufts.clear();
  scene.simulatedTufts = 0;
  const Camera camera = Camera::lookingAt(-1, 4, -10, -1, 0.3f, 2);
  viewer::OffscreenRenderer& r = offscreen();
  r.renderer().setAssetDirectory(test::sourcePath("scenarios"));
  const viewer::RenderOptions options;
  const Image meshImage = renderWith(scene, camera, options);
  EXPECT_EQ(r.renderer().lastAssetError(), "");
  const Image proxyImage = renderWith(withProxies(scene), camera, options);
  EXPECT_GT(differingFraction(meshImage, proxyImage, 8), 0.002)
      << "the rock and the crate look unlike a sphere and a box";

  Scene missing = scene;
  for (auto& b : missing.bodyParts)
    if (b.shape == viewer::BodyPartDraw::Shape::Mesh) b.mesh = "meshes/no-such-mesh.obj";
  const Image fallback = renderWith(missing, camera, options);
  EXPECT_NE(r.renderer().lastAssetError().find("no-such-mesh.obj:0: expected"), std::string::npos)
      << r.renderer().lastAssetError();
  EXPECT_EQ(r.renderer().lastAssetError().find('\n'), std::string::npos);
  EXPECT_EQ(differingFraction(fallback, proxyImage, 0), 0.0) << "a failed mesh draws exactly its primitives";
  r.renderer().setAssetDirectory("");
}

// ---- SSAO --------------------------------------------------------------------------------------

TEST(RenderSsao, DarkensTheCreaseUnderABoxMoreThanOpenGroundAndLeavesTheSky) {
  Scene scene = flatGround();
  scene.bodyParts.push_back(boxPart(0, 0.5f, 0, 0.5f));
  const Camera camera = Camera::lookingAt(0.3f, 1.6f, -3.5f, 0, 0.2f, 0);
  viewer::RenderOptions off, on;
  on.ssao = true;
  const Image a = renderWith(scene, camera, off), b = renderWith(scene, camera, on);
  int cx, cy, ox, oy;
  // The crease: ground 4 cm in front of the box's -z face; open ground: 1.6 m to the side, out of
  // the SSAO radius (0.5 m) of the box and of its shadow disc.
  ASSERT_TRUE(project(camera, 0, 0, -0.54f, &cx, &cy));
  ASSERT_TRUE(project(camera, -1.9f, 0, -0.8f, &ox, &oy));
  const double creaseRatio = meanLuminance(b, cx, cy + 2, 1) / meanLuminance(a, cx, cy + 2, 1);
  const double openRatio = meanLuminance(b, ox, oy, 2) / meanLuminance(a, ox, oy, 2);
  std::printf("SSAO: crease keeps %.3f of its brightness, open ground %.3f\n", creaseRatio, openRatio);
  EXPECT_LT(creaseRatio, openRatio - 0.04) << "the crease must darken clearly more than open ground";
  EXPECT_GT(openRatio, 0.93) << "open flat ground is hardly occluded";
  for (int x = 0; x < kWidth; ++x)
    for (int c = 0; c < 3; ++c) ASSERT_EQ(a.at(x, 0)[c], b.at(x, 0)[c]) << "the sky row, x " << x;
  const Image ao = offscreen().renderer().readAmbientOcclusion();
  EXPECT_EQ(ao.width, kWidth / 2);
  EXPECT_EQ(ao.height, kHeight / 2);
  renderWith(scene, camera, off);
  EXPECT_TRUE(offscreen().renderer().readAmbientOcclusion().rgba.empty()) << "no AO buffer with SSAO off";
}

// A tuft quad laid almost flat 10 cm above the ground (a "roof" of blades), seen from above. The
// ground visible through its transparent texels lies under the blades: SSAO must darken it (the
// prepass drew the blades only). Had the prepass drawn the whole quad, those pixels would be the
// open top of the roof, with nothing above to occlude them.
TEST(RenderSsao, TuftGapsShowOccludedGroundNotAQuad) {
  Scene ground = flatGround();
  Scene roof = ground;
  viewer::TuftInstance t{};
  t.x = 0, t.y = 0.10f, t.z = 0;
  t.halfWidth = 1.0f;
  t.topY = 0.11f;
  t.tipX = 0, t.tipZ = 2.0f;
  t.angle = 0;
  roof.tufts.push_back(t);
  const Camera camera = Camera::lookingAt(0, 3.2f, -0.6f, 0, 0, 1.0f);
  viewer::RenderOptions off, on;
  on.ssao = true;
  const Image roofOff = renderWith(roof, camera, off), groundOff = renderWith(ground, camera, off);
  renderWith(roof, camera, on);
  const Image aoRoof = offscreen().renderer().readAmbientOcclusion();
  renderWith(ground, camera, on);
  const Image aoGround = offscreen().renderer().readAmbientOcclusion();
  ASSERT_FALSE(aoRoof.rgba.empty());
  // Inside the roof's footprint (x in -0.8..0.8, z in 0.3..1.7, away from its edges): pixels where
  // the roof changes nothing show ground through a gap; the others show blades.
  int x0, y0, x1, y1;
  ASSERT_TRUE(project(camera, -0.8f, 0.1f, 1.7f, &x0, &y0));
  ASSERT_TRUE(project(camera, 0.8f, 0.1f, 0.3f, &x1, &y1));
  double gapAo = 0, groundAo = 0;
  int gaps = 0, blades = 0;
  for (int y = std::min(y0, y1); y <= std::max(y0, y1); ++y)
    for (int x = std::min(x0, x1); x <= std::max(x0, x1); ++x) {
      bool same = true;
      for (int c = 0; c < 3; ++c) same = same && roofOff.at(x, y)[c] == groundOff.at(x, y)[c];
      if (!same) {
        ++blades;
        continue;
      }
      ++gaps;
      gapAo += aoRoof.at(x / 2, y / 2)[0] / 255.0;
      groundAo += aoGround.at(x / 2, y / 2)[0] / 255.0;
    }
  ASSERT_GT(gaps, 200) << "the tuft texture has gaps between its blades";
  ASSERT_GT(blades, 200);
  gapAo /= gaps;
  groundAo /= gaps;
  std::printf("SSAO: ground seen through tuft gaps %.3f, the same ground without the tuft %.3f (%d gap pixels)\n",
              gapAo, groundAo, gaps);
  EXPECT_GT(groundAo, 0.97) << "open flat ground";
  EXPECT_LT(gapAo, groundAo - 0.05) << "the blades above occlude the ground seen between them";
}

// ---- rock blend --------------------------------------------------------------------------------

/// Terrain height from the scene's ground grid (bilinear), as the renderer triangulates it
/// (nearly: the grid's triangles split each cell; the difference is far below the tolerances).
float gridHeight(const viewer::GroundGrid& g, float x, float z) {
  const auto cell = [](const std::vector<float>& v, float p) {
    const size_t i = size_t(std::upper_bound(v.begin(), v.end(), p) - v.begin());
    return std::clamp<size_t>(i, 1, v.size() - 1) - 1;
  };
  const size_t i = cell(g.xs, x), j = cell(g.zs, z), nx = g.xs.size();
  const float u = std::clamp((x - g.xs[i]) / (g.xs[i + 1] - g.xs[i]), 0.0f, 1.0f);
  const float v = std::clamp((z - g.zs[j]) / (g.zs[j + 1] - g.zs[j]), 0.0f, 1.0f);
  const float h00 = g.heights[j * nx + i], h10 = g.heights[j * nx + i + 1];
  const float h01 = g.heights[(j + 1) * nx + i], h11 = g.heights[(j + 1) * nx + i + 1];
  return (h00 * (1 - u) + h10 * u) * (1 - v) + (h01 * (1 - u) + h11 * u) * v;
}

TEST(RenderRock, SteepGroundMovesTowardTheRockColourAndFlatGroundKeepsItsOwn) {
  const Loaded l = load("hilly-meadow.json");
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  scene.tufts.clear();  // the bare hills beyond and under the grass
  scene.simulatedTufts = 0;
  const Camera camera = Camera::lookingAt(-6, 12, -14, 12, 2, 0);
  viewer::RenderOptions on, off;
  off.rockBlend = false;
  const Image withRock = renderWith(scene, camera, on), without = renderWith(scene, camera, off);
  // The textures' mean colours, independent of the renderer.
  const viewer::TuftAtlas atlas = viewer::makeTuftAtlas(scene.atlasVariants, scene.atlasSeed);
  const Image rockTex = viewer::makeRockTexture(scene.atlasSeed),
              groundTex = viewer::makeGroundTexture(atlas, scene.atlasSeed);
  double towardRock[3];
  for (int c = 0; c < 3; ++c) {
    double r = 0, g = 0;
    for (size_t i = size_t(c); i < rockTex.rgba.size(); i += 4) r += rockTex.rgba[i];
    for (size_t i = size_t(c); i < groundTex.rgba.size(); i += 4) g += groundTex.rgba[i];
    towardRock[c] = (r - g) / double(rockTex.rgba.size() / 4);
  }
  // Ray-cast every 3rd pixel onto the terrain; the slope there from central differences.
  // Rays from the camera's basis (forward, right, up) and its field of view.
  const auto f = camera.forward();
  const float rl = std::sqrt(f[0] * f[0] + f[2] * f[2]);
  const float right[3] = {-f[2] / rl, 0, f[0] / rl};
  const float up[3] = {right[1] * f[2] - right[2] * f[1], right[2] * f[0] - right[0] * f[2],
                       right[0] * f[1] - right[1] * f[0]};
  const float tanY = std::tan(0.5f * camera.fovYDegrees * Camera::kRadians), aspect = float(kWidth) / kHeight;
  int flat = 0, flatChanged = 0, steep = 0;
  double shiftDot = 0, shiftMagnitude = 0;
  for (int py = 1; py < kHeight; py += 3)
    for (int px = 1; px < kWidth; px += 3) {
      const float sx = ((px + 0.5f) / kWidth * 2 - 1) * tanY * aspect, sy = (1 - (py + 0.5f) / kHeight * 2) * tanY;
      float d[3];
      for (int k = 0; k < 3; ++k) d[k] = f[size_t(k)] + sx * right[k] + sy * up[k];
      const float dl = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      float hit = -1;
      for (float s = 0.5f; s < 90; s += 0.02f) {
        const float x = camera.x + d[0] / dl * s, y = camera.y + d[1] / dl * s, z = camera.z + d[2] / dl * s;
        if (y <= gridHeight(scene.ground, x, z)) {
          hit = s;
          break;
        }
      }
      if (hit < 0) continue;
      const float x = camera.x + d[0] / dl * hit, z = camera.z + d[2] / dl * hit;
      const float e = 0.5f;  // the heightmap's cell
      const float gx = (gridHeight(scene.ground, x + e, z) - gridHeight(scene.ground, x - e, z)) / (2 * e);
      const float gz = (gridHeight(scene.ground, x, z + e) - gridHeight(scene.ground, x, z - e)) / (2 * e);
      const float slope = std::atan(std::sqrt(gx * gx + gz * gz)) / Camera::kRadians;
      if (slope < 5) {
        ++flat;
        bool changed = false;
        for (int c = 0; c < 3; ++c) changed = changed || std::abs(withRock.at(px, py)[c] - without.at(px, py)[c]) > 2;
        flatChanged += changed ? 1 : 0;
      } else if (slope > 13) {
        ++steep;
        double dot = 0, mag = 0;
        for (int c = 0; c < 3; ++c) {
          const double shift = double(withRock.at(px, py)[c]) - double(without.at(px, py)[c]);
          dot += shift * towardRock[c];
          mag += shift * shift;
        }
        shiftDot += dot;
        shiftMagnitude += std::sqrt(mag);
      }
    }
  std::printf("rock: %d flat samples (%d changed), %d steep samples, mean shift %.1f\n", flat, flatChanged, steep,
              steep ? shiftMagnitude / steep : 0.0);
  ASSERT_GT(flat, 200);
  ASSERT_GT(steep, 30) << "hilly-meadow has slopes over 13 degrees in view";
  EXPECT_LE(flatChanged, flat / 100) << "ground under 5 degrees keeps the grass texture";
  EXPECT_GT(shiftMagnitude / steep, 8.0) << "steep ground changes colour";
  EXPECT_GT(shiftDot, 0.0) << "... toward the rock texture's mean";
}

TEST(RenderRock, FlatGroundIsIdenticalWithAndWithoutRock) {
  const Loaded l = load("thesis-meadow.json");
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  const Camera camera = viewer::defaultCamera(scene, *l.world);
  viewer::RenderOptions on, off;
  off.rockBlend = false;
  EXPECT_EQ(differingFraction(renderWith(scene, camera, on), renderWith(scene, camera, off), 0), 0.0);
}

// ---- debug overlay -------------------------------------------------------------------------------

TEST(RenderDebug, CountsFollowTheWorld) {
  const Loaded l = load("thesis-bodies.json", 30);
  const auto* w = dynamic_cast<const World<Fx32>*>(l.world.get());
  ASSERT_NE(w, nullptr) << "thesis-bodies is fx32";
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  const size_t particles = size_t(w->particleGrid().size());
  viewer::DebugFlags f;
  f.particles = true;
  viewer::extractDebug(*l.world, l.scenario, f, &scene);
  EXPECT_EQ(scene.debug.points.size(), particles);
  EXPECT_TRUE(scene.debug.lines.empty());
  f = {};
  f.constraints = true;
  viewer::extractDebug(*l.world, l.scenario, f, &scene);
  EXPECT_EQ(scene.debug.lines.size(), particles) << "one rod per particle";
  EXPECT_TRUE(scene.debug.points.empty());
  f = {};
  f.primitives = true;
  viewer::extractDebug(*l.world, l.scenario, f, &scene);
  size_t expected = 0;  // a box: 12 edges; a sphere: 3 circles of 24 segments
  for (const auto& b : w->bodies())
    for (const auto& p : b.parts) expected += p.type == ShapeType::Sphere ? 72 : 12;
  EXPECT_EQ(scene.debug.lines.size(), expected);
  f = {};
  f.contacts = true;
  viewer::extractDebug(*l.world, l.scenario, f, &scene);
  EXPECT_EQ(scene.debug.points.size(), w->contacts().size());
  EXPECT_EQ(scene.debug.lines.size(), w->contacts().size()) << "a normal line each";
  EXPECT_GT(w->contacts().size(), size_t(0)) << "the bodies rest on the ground";
  f = {};
  f.cells = true;
  viewer::extractDebug(*l.world, l.scenario, f, &scene);
  ASSERT_GT(scene.debug.lines.size(), size_t(0));
  EXPECT_EQ(scene.debug.lines.size() % 4, size_t(0)) << "square outlines";
  // Every body's centre lies inside some outlined cell.
  for (const auto& b : w->bodies()) {
    const float bx = float(b.position.x().toDouble()), bz = float(b.position.z().toDouble());
    bool inside = false;
    for (size_t i = 0; i < scene.debug.lines.size(); i += 4) {
      const auto& l0 = scene.debug.lines[i];
      const auto& l1 = scene.debug.lines[i + 1];  // corners 0-1, then 1-2: x0..x1, z0..z1
      inside = inside || (bx >= l0.a[0] && bx <= l0.b[0] && bz >= l1.a[2] && bz <= l1.b[2]);
    }
    EXPECT_TRUE(inside) << "body at " << bx << ", " << bz;
  }
  // Nothing asked: nothing built.
  viewer::extractDebug(*l.world, l.scenario, viewer::DebugFlags{}, &scene);
  EXPECT_TRUE(scene.debug.lines.empty() && scene.debug.points.empty());
}

TEST(RenderDebug, OverlayChangesPixelsOnlyWhenEnabled) {
  const Loaded l = load("thesis-bodies.json", 30);
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  const Camera camera = Camera::lookingAt(-0.5f, 3, -9, -2, 0, 0);
  const Image plain = renderWith(scene, camera, {});
  viewer::DebugFlags f;
  f.particles = f.primitives = f.contacts = true;
  viewer::extractDebug(*l.world, l.scenario, f, &scene);
  EXPECT_EQ(differingFraction(plain, renderWith(scene, camera, {}), 0), 0.0) << "overlay off";
  viewer::RenderOptions on;
  on.debug = f;
  EXPECT_GT(differingFraction(plain, renderWith(scene, camera, on), 8), 0.01) << "overlay on";
}

// ---- divergence heat -------------------------------------------------------------------------

TEST(RenderHeat, OneDisplacedTipHeatsOnlyItsTuft) {
  const Loaded l = load("lod-crossing.json", 3);
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  ASSERT_LT(scene.simulatedTufts, size_t(scene.fieldPatchesX * scene.fieldPatchesZ)) << "a window of the field";
  Observation a, b;
  l.world->observe(a);
  b = a;
  viewer::applyDivergenceHeat(a, b, 0.5f, &scene);
  for (const auto& t : scene.tufts) ASSERT_EQ(t.heat, 0);
  // A patch near the window's far corner (not its first slot): displace its tip by 0.3 m of 0.5.
  const int64_t i = scene.windowOriginI + scene.windowWidth - 3, j = scene.windowOriginJ + scene.windowHeight - 2;
  const size_t p = size_t(j * a.patchesX + i);
  b.tipY[p] += 0.3;
  viewer::applyDivergenceHeat(a, b, 0.5f, &scene);
  size_t heated = 0, which = 0;
  for (size_t k = 0; k < scene.tufts.size(); ++k)
    if (scene.tufts[k].heat) ++heated, which = k;
  ASSERT_EQ(heated, size_t(1));
  EXPECT_EQ(scene.tufts[which].heat, uint8_t(std::lround(255 * 0.6)));
  // The heated tuft is that patch: its drawn tip is the observed tip.
  const viewer::TuftInstance& t = scene.tufts[which];
  EXPECT_NEAR(t.x + t.tipX, a.tipX[p], 1e-3);
  EXPECT_NEAR(t.topY, a.tipY[p], 1e-3);
  EXPECT_NEAR(t.z + t.tipZ, a.tipZ[p], 1e-3);
  // Past full scale: clamped.
  b.tipY[p] += 5;
  viewer::applyDivergenceHeat(a, b, 0.5f, &scene);
  EXPECT_EQ(scene.tufts[which].heat, 255);
}

TEST(RenderHeat, HeatMapTintsOnlyWhenOnAndHeated) {
  const Loaded l = load("thesis-meadow.json");
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  const Camera camera = viewer::defaultCamera(scene, *l.world);
  viewer::RenderOptions heat;
  heat.heatMap = true;
  const Image plain = renderWith(scene, camera, {});
  EXPECT_EQ(differingFraction(plain, renderWith(scene, camera, heat), 0), 0.0) << "no heat: no tint";
  for (auto& t : scene.tufts) t.heat = 200;
  EXPECT_EQ(differingFraction(plain, renderWith(scene, camera, {}), 0), 0.0) << "heat map off";
  EXPECT_GT(differingFraction(plain, renderWith(scene, camera, heat), 8), 0.3) << "heat map on";
}

// ---- interpolation -------------------------------------------------------------------------------

viewer::BodyPartDraw rotatedPart(float degreesY, float x, float scale) {
  viewer::BodyPartDraw b;
  const float a = degreesY * Camera::kRadians;
  b.model = viewer::identity4();
  b.model[0] = std::cos(a) * scale, b.model[2] = -std::sin(a) * scale;
  b.model[5] = scale;
  b.model[8] = std::sin(a) * scale, b.model[10] = std::cos(a) * scale;
  b.model[12] = x;
  return b;
}

Scene tickScene(float top, float partDegrees, float partX) {
  Scene s;
  s.windowOriginI = 4, s.windowOriginJ = 5, s.windowWidth = 2, s.windowHeight = 1;
  for (int k = 0; k < 2; ++k) {
    viewer::TuftInstance t{};
    t.x = float(k);
    t.topY = top + float(k);
    t.tipX = 0.1f * top, t.tipZ = -0.2f * top;
    s.tufts.push_back(t);
  }
  s.simulatedTufts = 2;
  s.bodyParts.push_back(rotatedPart(partDegrees, partX, 0.3f));
  return s;
}

TEST(RenderInterpolate, EndsReproduceTheTicksAndTheMiddleIsHalfway) {
  const Scene prev = tickScene(1.0f, 0, 0), cur = tickScene(2.0f, 90, 2);
  Scene out;
  viewer::interpolateScene(prev, cur, 0.0f, &out);
  for (size_t k = 0; k < 2; ++k) EXPECT_EQ(out.tufts[k].topY, prev.tufts[k].topY);
  EXPECT_EQ(out.bodyParts[0].model, prev.bodyParts[0].model);
  viewer::interpolateScene(prev, cur, 1.0f, &out);
  for (size_t k = 0; k < 2; ++k) EXPECT_EQ(out.tufts[k].topY, cur.tufts[k].topY);
  EXPECT_EQ(out.bodyParts[0].model, cur.bodyParts[0].model);
  viewer::interpolateScene(prev, cur, 0.5f, &out);
  EXPECT_NEAR(out.tufts[0].topY, 1.5f, 1e-6f);
  EXPECT_NEAR(out.tufts[1].topY, 2.5f, 1e-6f);
  EXPECT_NEAR(out.tufts[0].tipX, 0.15f, 1e-6f);
  EXPECT_NEAR(out.tufts[0].tipZ, -0.3f, 1e-6f);
  // Halfway between 0 and 90 degrees about y is 45 degrees, the scale kept, the centre halfway.
  const viewer::Mat4 expected = rotatedPart(45, 1, 0.3f).model;
  for (size_t i = 0; i < 16; ++i) EXPECT_NEAR(out.bodyParts[0].model[i], expected[i], 1e-5f) << i;
}

TEST(RenderInterpolate, DifferentLayoutsTakeTheCurrentTufts) {
  const Scene prev = tickScene(1.0f, 0, 0);
  Scene cur = tickScene(2.0f, 0, 0);
  cur.windowOriginI += 1;  // the window moved: slot k holds another patch
  Scene out;
  viewer::interpolateScene(prev, cur, 0.5f, &out);
  for (size_t k = 0; k < 2; ++k) EXPECT_EQ(out.tufts[k].topY, cur.tufts[k].topY);
  Scene more = tickScene(2.0f, 0, 0);
  more.bodyParts.push_back(more.bodyParts[0]);  // a spawned body: the parts no longer match
  viewer::interpolateScene(prev, more, 0.5f, &out);
  EXPECT_EQ(out.bodyParts[0].model, more.bodyParts[0].model);
  EXPECT_NEAR(out.tufts[0].topY, 1.5f, 1e-6f) << "the tufts still match";
}

// ---- simgrass render ------------------------------------------------------------------------------

TEST(RenderFeaturesCli, FeatureFlagsRenderAndBadValuesExit2) {
  TempDir dir;
  json j = json::parse(readFile(test::sourcePath("scenarios/mesh-bodies.json")));
  j["field"]["patchesX"] = 31;
  j["field"]["patchesZ"] = 31;
  // Meshes resolve against the scenario's folder: point them at the repository's.
  for (auto& b : j["bodies"]["list"])
    if (b.contains("mesh")) b["mesh"] = test::sourcePath("scenarios/" + b["mesh"].get<std::string>());
  const std::string scenario = dir.write("small-mesh.json", j.dump(2));
  const std::string out = " -o " + quote(dir.file("out"));
  const CliResult r =
      runCli("render " + quote(scenario) +
             " --size 64x48 --ssao --alpha-test --no-rock --debug particles,cells,contacts --json" + out);
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  const json res = parseJson(r);
  EXPECT_EQ(res.value("ssao", false), true);
  EXPECT_EQ(res.value("rockBlend", true), false);
  EXPECT_EQ(res.value("alphaToCoverage", true), false);
  EXPECT_FALSE(res.contains("assetError")) << r.out;
  for (const std::string args : {"--debug bogus", "--debug particles,", "--debug particles,,cells", "--debug ,"}) {
    const CliResult bad = runCli("render " + quote(scenario) + " " + args + out);
    EXPECT_EQ(bad.exitCode, 2) << args << "\n" << bad.describe();
    EXPECT_TRUE(isOneLine(bad.err)) << args;
  }
}

}  // namespace
}  // namespace sg
