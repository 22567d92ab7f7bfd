// Renderer features (docs/rendering.md): SSAO, the rock blend, OBJ meshes, the debug overlay, the
// divergence heat map and display interpolation; culling, crossed tufts on the terrain, body
// trails, the meadow's colour variation and the edge ring's rows; `simgrass render`'s flags. Rendered
// offscreen with OSMesa like tests/render_test.cpp; every check compares two renders that differ
// in one option, or compares against independently computed geometry (projections, ray casts,
// analytic midpoints), never against hard-coded pixel values.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

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

TEST(RenderObj, VertexLinesHaveNoTrailingJunk) {
  // "v 1 2 3 junk" loaded as a vertex (an independent pass, 2026-11-28). v takes x y z, an optional
  // w, or r g b colours (ignored); vn exactly x y z.
  const std::string face = "f 1 2 3\n";
  EXPECT_EQ(objError("v 0 0 0\nv 1 0 0\nv 0 1 0\n" + face), "");
  EXPECT_EQ(objError("v 0 0 0 1\nv 1 0 0 1\nv 0 1 0 0.5 0.5 0.5\n" + face), "");
  EXPECT_EQ(objError("v 0 0 0\nv 1 0 0 junk\nv 0 1 0\n" + face),
            "m.obj:2: expected a finite number within +-1e6, got 'junk'");
  EXPECT_EQ(objError("v 0 0 0 1 1\n"), "m.obj:1: expected 'v x y z', 'v x y z w' or 'v x y z r g b', got 5 values");
  EXPECT_EQ(objError("v 0 0 0\nvn 0 0 1 0\n"), "m.obj:2: expected 'vn x y z', got 4 values");
}

TEST(RenderObj, AFaceCornerNamesWhatIsWrongWithIt) {
  // "f 1/// 2 3" said "a normal index in 1..0", an empty range (an independent pass, 2026-11-29).
  const std::string three = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  EXPECT_EQ(objError(three + "f 1/// 2 3\n"), "m.obj:4: expected a face corner v, v/vt, v//vn or v/vt/vn, got '1///'");
  EXPECT_EQ(objError(three + "f 1//1 2 3\n"),
            "m.obj:4: expected no normal index (no vn line comes before this face), got '1//1'");
  EXPECT_EQ(objError(three + "f 1/1 2 3\n"),
            "m.obj:4: expected no texture index (no vt line comes before this face), got '1/1'");
  EXPECT_EQ(objError(three + "vn 0 0 1\nf 1//2 2 3\n"), "m.obj:5: expected a normal index in 1..1, got '1//2'");
  EXPECT_EQ(objError(three + "vn 0 0 1\nf 1//1 2//1 3//1\n"), "");
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
  t.halfWidth = 1.0f / offscreen().renderer().lighting().crossWidth;  // a quad 2 m wide
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

// ---- issue 18: culling, crossed tufts, terrain, trails, colour, edge ring, SSAO ------------------

// Looking from the meadow's centre along +x, 10 degrees down: half of it is behind the camera.
// The culled frame must be bit-identical to the unculled one (a culled tuft has no fragment), and
// every tuft whose root projects into the frame must have been drawn.
TEST(RenderCull, OffscreenTuftsAreSkippedAndTheFrameIsUnchanged) {
  const Loaded l = load("thesis-meadow.json", 30);
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  Camera camera;
  camera.x = 0, camera.y = 1.7f, camera.z = 0, camera.yawDegrees = 90, camera.pitchDegrees = -10;
  viewer::OffscreenRenderer& r = offscreen();
  const viewer::RenderOptions saved = r.options();
  double culledMs = 0, allMs = 0;
  r.options().cull = true;
  const Image culled = r.render(scene, camera, &culledMs);
  const viewer::FrameStats stats = r.renderer().lastFrameStats();
  r.options().cull = false;
  const Image all = r.render(scene, camera, &allMs);
  const viewer::FrameStats unculled = r.renderer().lastFrameStats();
  r.options() = saved;
  EXPECT_EQ(differingFraction(culled, all, 0), 0.0) << "culling must not change a pixel";
  EXPECT_EQ(unculled.drawn, scene.tufts.size());
  EXPECT_EQ(stats.tufts, scene.tufts.size());
  EXPECT_EQ(stats.drawn + stats.frustumCulled + stats.distanceCulled, stats.tufts);
  EXPECT_EQ(stats.distanceCulled, size_t(0)) << "the whole meadow lies within the fog distance";
  size_t inFrame = 0;
  for (const viewer::TuftInstance& t : scene.tufts) {
    int px, py;
    inFrame += project(camera, t.x, t.y, t.z, &px, &py) ? 1 : 0;
  }
  EXPECT_GE(stats.drawn, inFrame) << "every tuft rooted in the frame is drawn";
  EXPECT_LT(stats.drawn, scene.tufts.size() * 6 / 10) << "the half behind the camera and the sides are culled";
  std::printf(
      "cull: %zu of %zu tufts drawn (%zu frustum-culled); frame %.1f ms (cull+sort+upload %.2f ms), "
      "unculled %.1f ms (%.2f ms); 320x240 4x MSAA, one frame each\n",
      stats.drawn, stats.tufts, stats.frustumCulled, culledMs, stats.cullAndSortMs, allMs, unculled.cullAndSortMs);
}

// Tufts past the fog distance (where the fog leaves under 1/255 of their colour) are not drawn.
TEST(RenderCull, TuftsBeyondTheFogDistanceAreNotDrawn) {
  viewer::OffscreenRenderer& r = offscreen();
  const float d = r.renderer().cullDistance();
  const float density = r.renderer().lighting().fogDensity;
  EXPECT_LE(std::exp(-(d * density) * (d * density)), 1.0f / 255.0f + 1e-6f);
  EXPECT_GT(d, 300.0f);
  Scene scene;  // a line of tufts straight ahead, 50 m to 1 km
  for (int k = 0; k < 20; ++k) {
    viewer::TuftInstance t{};
    t.z = 50.0f * float(k + 1);
    t.halfWidth = 0.5f;
    t.topY = 1.0f;
    scene.tufts.push_back(t);
  }
  scene.simulatedTufts = scene.tufts.size();
  Camera camera;
  camera.y = 1.0f;
  renderWith(scene, camera, {});
  const viewer::FrameStats stats = r.renderer().lastFrameStats();
  size_t beyond = 0;
  for (const viewer::TuftInstance& t : scene.tufts) beyond += t.z - 1.5f > d ? 1 : 0;
  EXPECT_EQ(stats.distanceCulled, beyond);
  EXPECT_EQ(stats.drawn, scene.tufts.size() - beyond);
  EXPECT_GT(beyond, size_t(10));
}

/// Corner c (0 bottom-left, 1 bottom-right, 2 top-left, 3 top-right) of quad q of tuft k.
std::array<float, 3> corner(const std::vector<std::array<float, 3>>& v, size_t k, int q, int c) {
  return v[k * 8 + size_t(q) * 4 + size_t(c)];
}

// Both quads of a tuft: bottom edges through the root, 2 x halfWidth x crossWidth long, at right
// angles; the top corners the bottom ones raised by the tuft's height and shifted by its tip
// offset.
TEST(RenderTufts, CrossedQuadsStandAtRightAnglesAndBothBend) {
  Scene scene;
  const float angles[3] = {0.0f, 0.7f, 2.5f};
  for (int k = 0; k < 3; ++k) {
    viewer::TuftInstance t{};
    t.x = float(k), t.y = 0.2f, t.z = -1.0f;
    t.halfWidth = 0.5f;
    t.topY = 0.8f;
    t.tipX = 0.1f * float(k + 1), t.tipZ = -0.15f;
    t.angle = angles[k];
    scene.tufts.push_back(t);
  }
  const auto v = offscreen().renderer().captureTuftCorners(scene);
  const float crossWidth = offscreen().renderer().lighting().crossWidth;
  ASSERT_EQ(v.size(), scene.tufts.size() * 8);
  for (size_t k = 0; k < scene.tufts.size(); ++k) {
    const viewer::TuftInstance& t = scene.tufts[k];
    float dir[2][2];
    for (int q = 0; q < 2; ++q) {
      const auto bl = corner(v, k, q, 0), br = corner(v, k, q, 1), tl = corner(v, k, q, 2), tr = corner(v, k, q, 3);
      EXPECT_NEAR(0.5f * (bl[0] + br[0]), t.x, 1e-5f);
      EXPECT_NEAR(0.5f * (bl[2] + br[2]), t.z, 1e-5f);
      EXPECT_NEAR(bl[1], t.y, 1e-5f);
      EXPECT_NEAR(std::hypot(br[0] - bl[0], br[2] - bl[2]), 2 * t.halfWidth * crossWidth, 1e-5f);
      dir[q][0] = br[0] - bl[0], dir[q][1] = br[2] - bl[2];
      for (const auto& [b, top] : {std::pair{bl, tl}, std::pair{br, tr}}) {
        EXPECT_NEAR(top[0] - b[0], t.tipX, 1e-5f) << "tuft " << k << " quad " << q;
        EXPECT_NEAR(top[2] - b[2], t.tipZ, 1e-5f) << "tuft " << k << " quad " << q;
        EXPECT_NEAR(top[1], t.topY, 1e-5f);
      }
    }
    EXPECT_NEAR(dir[0][0] * dir[1][0] + dir[0][1] * dir[1][1], 0.0f, 1e-5f) << "at right angles";
    EXPECT_NEAR(dir[0][0] / std::hypot(dir[0][0], dir[0][1]), std::cos(t.angle), 1e-5f)
        << "the first quad keeps the tuft's angle";
  }
}

// One upright tuft seen from above (60 degrees down), turned in 10-degree steps: a single quad
// turns edge-on (a line) twice per half turn; the crossed pair always shows at least half of its
// broadest view, so no tuft reads as a flat card from above.
TEST(RenderTufts, FromAboveATuftNeverTurnsEdgeOn) {
  Scene ground = flatGround();
  const Camera camera = Camera::lookingAt(0, 2.6f, -1.5f, 0, 0.3f, 0);
  const Image bare = renderWith(ground, camera, {});
  int least = 1 << 30, most = 0;
  for (int step = 0; step < 18; ++step) {
    Scene s = ground;
    viewer::TuftInstance t{};
    t.halfWidth = 0.5f;
    t.topY = 0.6f;
    t.angle = float(step) * 10.0f * Camera::kRadians;
    s.tufts.push_back(t);
    s.simulatedTufts = 1;
    const Image img = renderWith(s, camera, {});
    int covered = 0;
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x)
        for (int c = 0; c < 3; ++c)
          if (std::abs(int(img.at(x, y)[c]) - int(bare.at(x, y)[c])) > 8) {
            ++covered;
            break;
          }
    least = std::min(least, covered);
    most = std::max(most, covered);
  }
  std::printf("tuft from above: %d to %d covered pixels over half a turn\n", least, most);
  ASSERT_GT(most, 150);
  EXPECT_GT(double(least) / most, 0.45) << "a single quad would vanish edge-on";
}

// On hilly-meadow every bottom corner of every tuft lies on the simulation's terrain (the quad's
// flat bottom edge would float or sink by up to half a width times the slope), and the top edge
// keeps the tuft's height above it.
TEST(RenderTerrain, BottomCornersFollowTheHills) {
  const Loaded l = load("hilly-meadow.json", 10);
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  const auto v = offscreen().renderer().captureTuftCorners(scene);
  ASSERT_EQ(v.size(), scene.tufts.size() * 8);
  double worst = 0, flatWorst = 0, heightWorst = 0;
  for (size_t k = 0; k < scene.tufts.size(); k += 7) {  // every 7th tuft: 3,258 of them
    const viewer::TuftInstance& t = scene.tufts[k];
    for (int q = 0; q < 2; ++q)
      for (int c = 0; c < 2; ++c) {
        const auto b = corner(v, k, q, c), top = corner(v, k, q, c + 2);
        const double terrain = viewer::groundHeight(*l.world, b[0], b[2]);
        worst = std::max(worst, std::fabs(b[1] - terrain));
        flatWorst = std::max(flatWorst, std::fabs(double(t.y) - terrain));
        heightWorst = std::max(heightWorst, std::fabs(double(top[1] - b[1]) - double(t.topY - t.y)));
      }
  }
  std::printf("terrain: bottom corners within %.2f mm of the terrain (a flat bottom edge: %.0f mm)\n", worst * 1e3,
              flatWorst * 1e3);
  EXPECT_LT(worst, 0.002) << "m";
  EXPECT_GT(flatWorst, 0.05) << "the hills are steep enough for the test to mean something";
  EXPECT_LT(heightWorst, 0.002) << "the blades keep their height above the slope";
}

/// The patch nearest to (x, z) among the scene's simulated tufts (the window is the field here).
size_t nearestTuft(const Scene& s, float x, float z) {
  size_t best = 0;
  float bestD = 1e30f;
  for (size_t k = 0; k < s.simulatedTufts; ++k) {
    const float d = std::hypot(s.tufts[k].x - x, s.tufts[k].z - z);
    if (d < bestD) bestD = d, best = k;
  }
  return best;
}

/// thesis-bodies extracted every `every` ticks up to `last` into one scene; the football's
/// centre at each tick in `at` is recorded (x, z).
Scene bodiesTrail(int64_t every, int64_t last, std::map<int64_t, std::array<float, 2>>* at = nullptr) {
  Loaded l = load("thesis-bodies.json");
  Scene scene;
  while (true) {
    if (l.world->tick() % every == 0) viewer::extractScene(*l.world, l.scenario, &scene);
    if (at) {
      const auto* w = dynamic_cast<const World<Fx32>*>(l.world.get());
      const auto& p = w->bodies()[0].position;
      (*at)[l.world->tick()] = {float(p.x().toDouble()), float(p.z().toDouble())};
    }
    if (l.world->tick() >= last) break;
    const StepResult r = l.world->step(scriptedInput(l.scenario, l.world->tick()));
    if (!r.ok) throw std::runtime_error(r.error.message());
  }
  return scene;
}

// The football rolls from x = -10 from tick 10. At tick 120 the grass it crossed around ticks
// 40-70 (well behind it now) carries a trail; grass far from every body carries none; the trail is
// drawn flatter and darker; it fades after kTrailSeconds; the same frames give the same trails,
// and frames 40 ticks apart give the same path (swept between them).
TEST(RenderTrail, APassedBodyLeavesADarkerFlatterTrailThatFades) {
  std::map<int64_t, std::array<float, 2>> ball;
  const Scene scene = bodiesTrail(1, 120, &ball);
  const auto& now = ball[120];
  std::vector<size_t> trail;
  for (int64_t t = 40; t <= 70; t += 5) {
    const auto& p = ball[t];
    ASSERT_GT(std::hypot(p[0] - now[0], p[1] - now[1]), 1.5f) << "the ball has moved on";
    const size_t k = nearestTuft(scene, p[0], p[1]);
    EXPECT_GT(scene.tufts[k].trail, 128) << "tick " << t;
    trail.push_back(k);
  }
  size_t far = 0;  // untouched: tufts 4 m or more from the ball's path and every body
  for (size_t k = 0; k < scene.simulatedTufts; ++k) {
    const viewer::TuftInstance& t = scene.tufts[k];
    bool away = true;
    for (const auto& [tick, p] : ball) away = away && std::hypot(t.x - p[0], t.z - p[1]) > 4.0f;
    for (const viewer::BodyPartDraw& b : scene.bodyParts)
      away = away && std::hypot(t.x - b.model[12], t.z - b.model[14]) > 4.0f;
    if (!away) continue;
    ++far;
    ASSERT_EQ(t.trail, 0) << "tuft " << k << " at " << t.x << ", " << t.z;
  }
  EXPECT_GT(far, size_t(10000));

  // Flatter: the drawn top of a trail tuft is lower than its simulated top.
  const auto v = offscreen().renderer().captureTuftCorners(scene);
  for (size_t k : trail) {
    const viewer::TuftInstance& t = scene.tufts[k];
    const float drawn = corner(v, k, 0, 2)[1] - corner(v, k, 0, 0)[1];
    EXPECT_LT(drawn, 0.8f * (t.topY - t.y)) << "tuft " << k;
  }
  // Darker: the same frame without the trail is brighter where the trail is, identical elsewhere.
  const Camera camera = Camera::lookingAt(ball[55][0], 6, ball[55][1] - 4, ball[55][0], 0, ball[55][1]);
  Scene plain = scene;
  for (viewer::TuftInstance& t : plain.tufts) t.trail = 0;
  const Image with = renderWith(scene, camera, {}), without = renderWith(plain, camera, {});
  int px, py;
  ASSERT_TRUE(project(camera, ball[55][0], 0.3f, ball[55][1], &px, &py));
  const double ratio = meanLuminance(with, px, py, 4) / meanLuminance(without, px, py, 4);
  std::printf("trail: %.2f of the untouched brightness on the path\n", ratio);
  EXPECT_LT(ratio, 0.9);

  // Deterministic, and the same path from frames 40 ticks apart (swept between them).
  const Scene again = bodiesTrail(1, 120), sparse = bodiesTrail(40, 120);
  for (size_t k = 0; k < scene.tufts.size(); ++k) ASSERT_EQ(scene.tufts[k].trail, again.tufts[k].trail) << k;
  for (size_t k : trail) EXPECT_GT(sparse.tufts[k].trail, 64) << "tuft " << k;

  // Faded: kTrailSeconds (480 ticks) after the ball left, nothing of the early path remains.
  const Scene later = bodiesTrail(10, 120 + 500);
  for (size_t k : trail) EXPECT_LT(later.tufts[k].trail, scene.tufts[k].trail);
  const auto earliest = trail.front();
  EXPECT_EQ(later.tufts[earliest].trail, 0) << "pressed at tick 40, faded by tick 520";
}

/// Mean luminance per `block` x `block` pixel block.
std::vector<double> blockMeans(const Image& img, int block) {
  std::vector<double> out;
  for (int by = 0; by + block <= img.height; by += block)
    for (int bx = 0; bx + block <= img.width; bx += block)
      out.push_back(meanLuminance(img, bx + block / 2, by + block / 2, block / 2));
  return out;
}

double stddev(const std::vector<double>& v) {
  double m = 0, s = 0;
  for (double x : v) m += x;
  m /= double(v.size());
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / double(v.size()));
}

// The meadow from 20 m above (23 x 17 m of it in view), rendered with and without the colour
// variation. Their ratio (the variation alone, whatever the view itself does to brightness) spans
// well over 20 % across the view and changes slowly: 16 x 16 pixel blocks (1.2 m of meadow) are
// like their neighbours, large-scale variation and not noise. The blocks' own brightness varies
// clearly more with it than without.
TEST(RenderColour, TheMeadowVariesAtLargeScale) {
  const Loaded l = load("thesis-meadow.json");
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  Camera camera;
  camera.y = 20, camera.pitchDegrees = -89.9f;
  viewer::OffscreenRenderer& r = offscreen();
  const Image varied = renderWith(scene, camera, {});
  const float saved = r.renderer().lighting().colourVariation;
  r.renderer().lighting().colourVariation = 0;
  const Image uniform = renderWith(scene, camera, {});
  r.renderer().lighting().colourVariation = saved;
  constexpr int kBlock = 16, perRow = kWidth / kBlock;
  const std::vector<double> a = blockMeans(varied, kBlock), b = blockMeans(uniform, kBlock);
  std::vector<double> ratio(a.size());
  for (size_t i = 0; i < a.size(); ++i) ratio[i] = a[i] / b[i];
  const auto [lo, hi] = std::minmax_element(ratio.begin(), ratio.end());
  double mean = 0, num = 0, den = 0;
  for (double x : ratio) mean += x;
  mean /= double(ratio.size());
  for (size_t i = 0; i < ratio.size(); ++i) {
    den += (ratio[i] - mean) * (ratio[i] - mean);
    if ((i + 1) % size_t(perRow) != 0 && i + 1 < ratio.size()) num += (ratio[i] - mean) * (ratio[i + 1] - mean);
  }
  const double correlation = num / den;
  std::printf(
      "colour: brightness ratio %.2f to %.2f across the view, neighbour correlation %.2f; block brightness "
      "std %.1f with the variation, %.1f without\n",
      *lo, *hi, correlation, stddev(a), stddev(b));
  EXPECT_GT(*hi - *lo, 0.2);
  EXPECT_GT(correlation, 0.8);
  EXPECT_GT(stddev(a), 1.5 * stddev(b));
}

// lod-crossing: ring tufts stand on the grass lattice, on lines through the ring cells' centre
// patches (every edgeSpacing-th row or column); along a line they are one grass spacing apart,
// and two neighbouring parallel lines are edgeSpacing spacings apart.
TEST(RenderEdgeRing, RowsAreEdgeSpacingApartAndTuftsOneSpacingApart) {
  const Loaded l = load("lod-crossing.json");
  const auto* w = dynamic_cast<const World<Fx32>*>(l.world.get());
  ASSERT_NE(w, nullptr);
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  const int64_t m = w->edgeRing().spacingMultiple;
  ASSERT_EQ(m, 4);
  const double spacing = w->lattice().spacing.toDouble(), ox = w->lattice().originX.toDouble(),
               oz = w->lattice().originZ.toDouble(), jitter = w->lattice().jitterAmplitude.toDouble();
  ASSERT_LT(jitter, 0.5 * spacing) << "rounding recovers the lattice index";
  std::set<std::pair<int64_t, int64_t>> ring;
  for (size_t k = scene.simulatedTufts; k < scene.tufts.size(); ++k) {
    const viewer::TuftInstance& t = scene.tufts[k];
    const int64_t i = std::llround((t.x - ox) / spacing), j = std::llround((t.z - oz) / spacing);
    EXPECT_LT(std::fabs(t.x - (ox + double(i) * spacing)), jitter + 1e-3);
    ring.insert({i, j});
    EXPECT_FALSE(i >= scene.windowOriginI && i < scene.windowOriginI + scene.windowWidth && j >= scene.windowOriginJ &&
                 j < scene.windowOriginJ + scene.windowHeight)
        << "a ring tuft inside the simulated window";
    EXPECT_TRUE((i - m / 2) % m == 0 || (j - m / 2) % m == 0) << i << ", " << j << " is on no ring line";
    EXPECT_EQ(t.halfWidth, float(l.scenario.field.scaleXZ.toDouble())) << "as wide as the grass";
  }
  EXPECT_EQ(ring.size(), scene.tufts.size() - scene.simulatedTufts) << "no tuft twice";
  // Beyond the window's +z side: rows along x. Their lines j are m apart; along a row, the tufts
  // over the window's width are consecutive lattice columns.
  const int64_t i0 = scene.windowOriginI, i1 = scene.windowOriginI + scene.windowWidth;
  const int64_t jEnd = scene.windowOriginJ + scene.windowHeight;
  std::map<int64_t, std::set<int64_t>> rows;
  for (const auto& [i, j] : ring)
    if (j >= jEnd && i >= i0 && i < i1) rows[j].insert(i);
  ASSERT_GE(rows.size(), size_t(10));
  int64_t previous = -1;
  for (const auto& [j, columns] : rows) {
    if (previous >= 0) {
      EXPECT_EQ(j - previous, m) << "rows " << previous << " and " << j;
    }
    previous = j;
    EXPECT_EQ(int64_t(columns.size()), i1 - i0) << "row " << j << ": a tuft at every grass spacing";
  }
  EXPECT_LT(rows.begin()->first - jEnd, m) << "the first row follows the window within a cell";
  // In metres: a tuft's nearest neighbour in its row is about one grass spacing away.
  const auto& row = rows.begin()->second;
  std::vector<double> xs;
  for (size_t k = scene.simulatedTufts; k < scene.tufts.size(); ++k) {
    const viewer::TuftInstance& t = scene.tufts[k];
    if (std::llround((t.z - oz) / spacing) == rows.begin()->first && row.count(std::llround((t.x - ox) / spacing)))
      xs.push_back(t.x);
  }
  std::sort(xs.begin(), xs.end());
  double gaps = 0;
  for (size_t k = 1; k < xs.size(); ++k) gaps += xs[k] - xs[k - 1];
  EXPECT_NEAR(gaps / double(xs.size() - 1), spacing, 0.01);
  // Every ring line closes around the window: each of the first rows' 4 sides holds tufts.
  EXPECT_GT(scene.tufts.size() - scene.simulatedTufts, size_t(m) * 1000);
}

/// Pixels of `img` that differ from the sky-only frame `sky` (the grass and ground region).
std::vector<std::pair<int, int>> notSky(const Image& img, const Image& sky) {
  std::vector<std::pair<int, int>> out;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c)
        if (img.at(x, y)[c] != sky.at(x, y)[c]) {
          out.push_back({x, y});
          break;
        }
  return out;
}

// The thesis meadow at tick 120 from the default camera: SSAO darkens the grass clearly (today's
// ambient-only AO: ~5/255) but not to black, and leaves every sky pixel bit-identical.
TEST(RenderSsao, DarkensTheGrassVisiblyButNotToBlack) {
  const Loaded l = load("thesis-meadow.json", 120);
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  const Camera camera = viewer::defaultCamera(scene, *l.world, float(kWidth) / kHeight);
  viewer::RenderOptions off, on;
  on.ssao = true;
  const Image a = renderWith(scene, camera, off), b = renderWith(scene, camera, on);
  Scene empty;
  empty.atlasVariants = scene.atlasVariants, empty.atlasSeed = scene.atlasSeed;
  const Image sky = renderWith(empty, camera, off);
  const auto grass = notSky(a, sky);
  ASSERT_GT(grass.size(), size_t(kWidth * kHeight / 3));
  double la = 0, lb = 0;
  for (const auto& [x, y] : grass) la += luminance(a, x, y), lb += luminance(b, x, y);
  la /= double(grass.size());
  lb /= double(grass.size());
  std::printf("SSAO: grass mean luminance %.1f without, %.1f with (%.1f levels, %.0f %% darker)\n", la, lb, la - lb,
              100 * (1 - lb / la));
  EXPECT_GT(la - lb, 12.0) << "visible";
  EXPECT_GT(lb / la, 0.6) << "not black";
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      bool isSky = true;
      for (int c = 0; c < 3; ++c) isSky = isSky && a.at(x, y)[c] == sky.at(x, y)[c];
      if (!isSky) continue;
      for (int c = 0; c < 3; ++c) ASSERT_EQ(a.at(x, y)[c], b.at(x, y)[c]) << "sky pixel " << x << ", " << y;
    }
}

// Bare hills: the terrain receives occlusion from grass and bodies only, so with neither its AO
// is 1 everywhere (the old prepass let the hills and the grazing far ground darken themselves).
TEST(RenderSsao, BareTerrainDoesNotOccludeItself) {
  const Loaded l = load("hilly-meadow.json");
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  scene.tufts.clear();
  scene.simulatedTufts = 0;
  viewer::RenderOptions on;
  on.ssao = true;
  renderWith(scene, Camera::lookingAt(-6, 12, -14, 12, 2, 0), on);
  const Image ao = offscreen().renderer().readAmbientOcclusion();
  ASSERT_FALSE(ao.rgba.empty());
  int lowest = 255;
  for (size_t i = 0; i < ao.rgba.size(); i += 4) lowest = std::min(lowest, int(ao.rgba[i]));
  EXPECT_EQ(lowest, 255) << "no terrain pixel occluded";
}

// A box floating 1.8 m above the meadow, seen from above: on screen its faces meet the grass, 2 m
// and more behind it and more occluded. Along the silhouette the blurred AO of a box pixel must be
// the mean of the raw (unblurred) AO of the box pixels around it, not of all of them: the blur
// ignores neighbours at another depth (which surface a pixel shows comes from a render of the box
// alone, not from depth). A plain box blur (every neighbour counted; the test runs it too) mixes
// the grass' darker AO into the box.
TEST(RenderSsao, TheBlurKeepsTheGrassOcclusionOffABodyInFrontOfIt) {
  const Loaded l = load("thesis-meadow.json", 60);
  Scene scene;
  viewer::extractScene(*l.world, l.scenario, &scene);
  const viewer::BodyPartDraw box = boxPart(0, 2.2f, 0, 0.4f);
  scene.bodyParts.push_back(box);
  const Camera camera = Camera::lookingAt(0, 4.0f, -2.5f, 0, 0, 1.5f);
  viewer::RenderOptions on;
  on.ssao = true;
  Scene alone, sky;
  alone.atlasVariants = sky.atlasVariants = scene.atlasVariants;
  alone.atlasSeed = sky.atlasSeed = scene.atlasSeed;
  alone.bodyParts.push_back(box);
  const Image boxOnly = renderWith(alone, camera, {}), skyOnly = renderWith(sky, camera, {});
  // Half-resolution pixel (x, y) shows the box when the full-resolution pixel it stands for does.
  auto onBox = [&](int x, int y) {
    for (int c = 0; c < 3; ++c)
      if (boxOnly.at(2 * x, 2 * y + 1)[c] != skyOnly.at(2 * x, 2 * y + 1)[c]) return true;
    return false;
  };
  struct Rim {
    double offBoxMean = 0;  ///< mean |blurred - mean raw AO of the box pixels of the 4x4 window|
    double grassShare = 0;  ///< mean (box-only raw mean - all-pixel raw mean): what a box blur mixes in
    double blurred = 0;     ///< mean blurred AO
    int pixels = 0;
  };
  auto measure = [&] {
    renderWith(scene, camera, on);
    const Image ao = offscreen().renderer().readAmbientOcclusion();
    const Image raw = offscreen().renderer().readAmbientOcclusion(false);
    Rim rim;
    for (int y = 2; y < ao.height - 2; ++y)
      for (int x = 2; x < ao.width - 2; ++x) {
        if (!onBox(x, y)) continue;
        // The blur's 4x4 window: GL rows y - 2 .. y + 1 bottom up, so image rows y - 1 .. y + 2.
        double boxSum = 0, allSum = 0;
        int boxN = 0;
        for (int dy = -1; dy <= 2; ++dy)
          for (int dx = -2; dx <= 1; ++dx) {
            const double v = raw.at(x + dx, y + dy)[0];
            allSum += v;
            if (onBox(x + dx, y + dy)) boxSum += v, ++boxN;
          }
        if (boxN == 16) continue;  // not at the silhouette
        ++rim.pixels;
        rim.offBoxMean += std::fabs(ao.at(x, y)[0] - boxSum / boxN);
        rim.grassShare += boxSum / boxN - allSum / 16;
        rim.blurred += ao.at(x, y)[0];
      }
    rim.offBoxMean /= std::max(1, rim.pixels);
    rim.grassShare /= std::max(1, rim.pixels);
    rim.blurred /= std::max(1, rim.pixels);
    return rim;
  };
  const Rim bilateral = measure();
  float& tolerance = offscreen().renderer().lighting().ssaoBlurDepthTolerance;
  const float saved = tolerance;
  tolerance = 1e9f;
  const Rim plain = measure();
  tolerance = saved;
  std::printf(
      "SSAO blur: at the box's silhouette (%d pixels) the blurred AO is %.1f/255 from the box pixels' own "
      "mean (mean %.0f/255); a box blur: %.1f/255 (mean %.0f/255); the grass would pull it down by %.1f\n",
      bilateral.pixels, bilateral.offBoxMean, bilateral.blurred, plain.offBoxMean, plain.blurred, bilateral.grassShare);
  ASSERT_GT(bilateral.pixels, 100);
  ASSERT_GT(bilateral.grassShare, 10.0) << "the grass around the box is more occluded than the box";
  // (Not 0: neighbours on the box at a slightly different depth count a little less.)
  EXPECT_LT(bilateral.offBoxMean, 8.0) << "the grass' occlusion bleeds onto the box in front of it";
  EXPECT_LT(bilateral.offBoxMean, 0.4 * plain.offBoxMean);
  EXPECT_GT(bilateral.blurred, plain.blurred + 10.0);
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
