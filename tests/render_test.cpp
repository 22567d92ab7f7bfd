// The renderer and `simgrass render` (docs/rendering.md): four fixed views of fixed ticks are
// rendered offscreen (OSMesa, 320x240, 4x MSAA) and compared with the committed PNGs in
// tests/golden/images/ within a tolerance meant for other Mesa versions; each view must also
// differ substantially from a sky-only frame, so a renderer that draws nothing fails. The command
// writes one frame per tick and rejects bad arguments with one line and exit code 2.
//
// Regenerate the goldens with .ci/update-golden-images (SIMGRASS_UPDATE_GOLDEN_IMAGES=1 makes
// the golden tests write their frames instead of comparing them).
#include <gtest/gtest.h>
#include <stb/stb_image.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "tests/cli_support.h"
#include "tests/test_support.h"
#include "viewer/offscreen/osmesa_context.h"
#include "viewer/render/scene.h"

namespace sg {
namespace {
namespace fs = std::filesystem;
using viewer::Camera;
using viewer::Image;

constexpr int kWidth = 320, kHeight = 240, kSamples = 4;

/// Golden-image tolerance (docs/rendering.md): a pixel "differs" when a channel is off by more
/// than 24; at most 1% of pixels may differ and the mean absolute channel difference must stay
/// below 2.0. Against the sky-only frame at least 30% of pixels must differ.
constexpr int kChannelTolerance = 24;
constexpr double kMaxDifferingFraction = 0.01;
constexpr double kMaxMeanAbsDiff = 2.0;
constexpr double kMinFractionOffSky = 0.30;

struct ImageDiff {
  double differingFraction = 1.0;  ///< pixels with a channel off by more than kChannelTolerance
  double meanAbsDiff = 255.0;      ///< over all RGB channels
};

ImageDiff compare(const Image& a, const Image& b) {
  ImageDiff d;
  if (a.width != b.width || a.height != b.height) return d;
  size_t differing = 0;
  double sum = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      int worst = 0;
      for (int c = 0; c < 3; ++c) {
        const int diff = std::abs(int(a.at(x, y)[c]) - int(b.at(x, y)[c]));
        worst = std::max(worst, diff);
        sum += diff;
      }
      if (worst > kChannelTolerance) ++differing;
    }
  const double pixels = double(a.width) * double(a.height);
  d.differingFraction = double(differing) / pixels;
  d.meanAbsDiff = sum / (3 * pixels);
  return d;
}

std::optional<Image> readPng(const std::string& path) {
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &n, 4);
  if (!data) return std::nullopt;
  Image img;
  img.width = w;
  img.height = h;
  img.rgba.assign(data, data + size_t(w) * size_t(h) * 4);
  stbi_image_free(data);
  return img;
}

/// One offscreen renderer for the whole suite (creating the context and compiling shaders costs
/// about a second on llvmpipe). Torn down at exit, context last.
viewer::OffscreenRenderer& offscreen() {
  static std::unique_ptr<viewer::OffscreenRenderer> r = [] {
    std::string error;
    auto made = viewer::OffscreenRenderer::create(kWidth, kHeight, kSamples, &error);
    if (!made) ADD_FAILURE() << error;
    return made;
  }();
  if (!r) throw std::runtime_error("no offscreen renderer");
  return *r;
}

struct GoldenView {
  const char* name;      ///< tests/golden/images/<name>.png
  const char* scenario;  ///< scenarios/<scenario>
  int64_t tick;
  std::optional<Camera> camera;  ///< nullopt: the default camera
  bool ssao = false;             ///< RenderOptions::ssao (the rest: defaults)
};

Camera fixedCamera(float x, float y, float z, float yaw, float pitch) {
  Camera c;
  c.x = x;
  c.y = y;
  c.z = z;
  c.yawDegrees = yaw;
  c.pitchDegrees = pitch;
  return c;
}

/// Runs the scenario to the view's tick and renders it; *sky gets the sky-only frame of the
/// same camera.
Image renderView(const GoldenView& v, Image* sky) {
  const Scenario scenario = loadScenarioFile(test::sourcePath(std::string("scenarios/") + v.scenario));
  std::unique_ptr<SimWorld> world = makeWorld(scenario);
  while (world->tick() < v.tick) {
    const StepResult r = world->step(scriptedInput(scenario, world->tick()));
    if (!r.ok) throw std::runtime_error(r.error.message());
  }
  viewer::OffscreenRenderer& r = offscreen();
  // A scene of its own: extractScene remembers body trails between extractions into one scene,
  // and a golden must not depend on which test ran before it.
  viewer::Scene scene;
  viewer::extractScene(*world, scenario, &scene);
  const Camera camera = v.camera ? *v.camera : viewer::defaultCamera(scene, *world);
  r.options().ssao = v.ssao;
  Image image = r.render(scene, camera);
  r.options().ssao = false;
  if (sky) {
    viewer::Scene empty;  // no tufts, no bodies, no ground: only the sky pass draws
    empty.atlasVariants = scene.atlasVariants;
    empty.atlasSeed = scene.atlasSeed;
    *sky = r.render(empty, camera);
  }
  return image;
}

void checkGolden(const GoldenView& v) {
  Image sky;
  const Image image = renderView(v, &sky);
  const fs::path golden = fs::path(test::sourcePath("tests/golden/images")) / (std::string(v.name) + ".png");
  if (std::getenv("SIMGRASS_UPDATE_GOLDEN_IMAGES")) {
    fs::create_directories(golden.parent_path());
    std::string error;
    ASSERT_TRUE(viewer::writePng(golden.string(), image, &error)) << error;
    std::printf("wrote %s\n", golden.c_str());
    return;
  }
  // The frame must show something: far from the sky alone.
  const ImageDiff offSky = compare(image, sky);
  testing::Test::RecordProperty("offSkyPercent", std::to_string(offSky.differingFraction * 100));
  EXPECT_GT(offSky.differingFraction, kMinFractionOffSky) << v.name << ": the frame looks like the sky alone";

  const std::optional<Image> expected = readPng(golden.string());
  ASSERT_TRUE(expected) << golden << " is missing: run .ci/update-golden-images";
  ASSERT_EQ(expected->width, kWidth);
  ASSERT_EQ(expected->height, kHeight);
  EXPECT_GT(compare(*expected, sky).differingFraction, kMinFractionOffSky) << golden << " looks like the sky alone";
  const ImageDiff d = compare(image, *expected);
  std::printf("%s: %.1f%% of pixels differ from the sky alone; against the golden %.3f%% differ, mean |diff| %.3f\n",
              v.name, offSky.differingFraction * 100, d.differingFraction * 100, d.meanAbsDiff);
  const bool ok = d.differingFraction <= kMaxDifferingFraction && d.meanAbsDiff < kMaxMeanAbsDiff;
  if (!ok) {
    // Leave the frame and a difference image for a look.
    const fs::path dir = fs::temp_directory_path() / "simgrass-render-failures";
    fs::create_directories(dir);
    Image diff = image;
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x)
        for (int c = 0; c < 3; ++c)
          diff.at(x, y)[c] = uint8_t(std::min(255, 4 * std::abs(int(image.at(x, y)[c]) - int(expected->at(x, y)[c]))));
    std::string error;
    viewer::writePng((dir / (std::string(v.name) + "-actual.png")).string(), image, &error);
    viewer::writePng((dir / (std::string(v.name) + "-diff.png")).string(), diff, &error);
    ADD_FAILURE() << v.name << ": " << d.differingFraction * 100 << "% of pixels differ by more than "
                  << kChannelTolerance << " (at most " << kMaxDifferingFraction * 100
                  << "% allowed), mean absolute difference " << d.meanAbsDiff << " (below " << kMaxMeanAbsDiff
                  << " required); the frame and a 4x difference image are in " << dir;
  }
}

// ---- golden images -----------------------------------------------------------------------------

// The thesis meadow after 2 s (the first gust has crossed it) from the default camera: 1.7 m
// above the ground at the field's -z edge, looking at its centre.
TEST(Render, GoldenThesisMeadowTick120) { checkGolden({"thesis-meadow-120", "thesis-meadow.json", 120, std::nullopt}); }

// The football, the "bunny" and the box in the grass, seen from 3.5 m.
TEST(Render, GoldenThesisBodiesTick90) {
  checkGolden({"thesis-bodies-90", "thesis-bodies.json", 90, fixedCamera(-0.5f, 3, -9, 0, -17)});
}

// The painted football field and the mower's cut lane, from above and behind the mower.
TEST(Render, GoldenMowerFieldTick200) {
  checkGolden({"mower-field-200", "mower-field.json", 200, fixedCamera(-19, 4.5f, -1, 60, -30)});
}

// The hills with ambient occlusion and the rock blend, looking over the steepest slopes (under
// the grass, and bare beyond the field).
TEST(Render, GoldenHillyMeadowSsaoTick60) {
  GoldenView v{"hilly-meadow-ssao-60", "hilly-meadow.json", 60, fixedCamera(-6, 12, -14, 52, -24)};
  v.ssao = true;
  checkGolden(v);
}

// ---- renderer properties ---------------------------------------------------------------------

TEST(Render, SameFrameTwiceIsIdentical) {
  const GoldenView v{"meadow-repeat", "thesis-meadow.json", 10, std::nullopt};
  const Image a = renderView(v, nullptr);
  const Image b = renderView(v, nullptr);
  EXPECT_TRUE(a.rgba == b.rgba) << "llvmpipe rendering of the same state must be reproducible";
}

// The bodies cover under 1% of the bodies view (the grass hides their lower half), too little for
// the golden tolerance to notice them missing: check them on their own.
TEST(Render, BodiesShowInTheBodiesView) {
  const Scenario scenario = loadScenarioFile(test::sourcePath("scenarios/thesis-bodies.json"));
  std::unique_ptr<SimWorld> world = makeWorld(scenario);
  while (world->tick() < 90) ASSERT_TRUE(world->step(scriptedInput(scenario, world->tick())).ok);
  viewer::OffscreenRenderer& r = offscreen();
  viewer::Scene scene;
  viewer::extractScene(*world, scenario, &scene);
  ASSERT_EQ(scene.bodyParts.size(), size_t(3));
  const Camera camera = fixedCamera(-0.5f, 3, -9, 0, -17);
  const Image with = r.render(scene, camera);
  scene.bodyParts.clear();
  const Image without = r.render(scene, camera);
  EXPECT_GT(compare(with, without).differingFraction, 0.003) << "the football, the bunny and the box";
}

TEST(Render, BodiesAndMarkingsReachTheScene) {
  const Scenario scenario = loadScenarioFile(test::sourcePath("scenarios/mower-field.json"));
  std::unique_ptr<SimWorld> world = makeWorld(scenario);
  viewer::Scene scene;
  viewer::extractScene(*world, scenario, &scene);
  EXPECT_EQ(scene.tufts.size(), size_t(151 * 151));
  EXPECT_EQ(scene.bodyParts.size(), size_t(5)) << "the mower: a deck and four wheels";
  const size_t marking =
      size_t(std::count_if(scene.tufts.begin(), scene.tufts.end(),
                           [&](const viewer::TuftInstance& t) { return t.variant == scene.atlasVariants; }));
  EXPECT_GT(marking, size_t(500)) << "white marking tufts";
  EXPECT_FALSE(scene.ground.heights.empty());
  EXPECT_EQ(scene.ground.heights.size(), scene.ground.xs.size() * scene.ground.zs.size());
}

TEST(Render, EdgeRingTuftsAreDrawnWithTheLevelOfDetail) {
  const Scenario scenario = loadScenarioFile(test::sourcePath("scenarios/lod-crossing.json"));
  std::unique_ptr<SimWorld> world = makeWorld(scenario);
  viewer::Scene scene;
  viewer::extractScene(*world, scenario, &scene);
  EXPECT_EQ(scene.simulatedTufts, size_t(world->counts().simulatedPatches()));
  EXPECT_GT(scene.tufts.size(), scene.simulatedTufts) << "the edge-grass ring";
}

// ---- simgrass render -------------------------------------------------------------------------

/// A small meadow (31 x 31 tufts) written into `dir`.
std::string smallScenario(const TempDir& dir) {
  json j = json::parse(readFile(test::sourcePath("scenarios/thesis-meadow.json")));
  j["name"] = "small-meadow";
  j["field"]["patchesX"] = 31;
  j["field"]["patchesZ"] = 31;
  return dir.write("small.json", j.dump(2));
}

TEST(RenderCli, SixtyTicksOfAReplayGiveSixtyFrames) {
  TempDir dir;
  const std::string scenario = smallScenario(dir);
  const std::string rec = dir.file("small.sgr");
  const CliResult recorded = runCli("record " + quote(scenario) + " --ticks 60 -o " + quote(rec) + " --json");
  ASSERT_EQ(recorded.exitCode, 0) << recorded.describe();
  const std::string frames = dir.file("frames");
  const CliResult r = runCli("render " + quote(rec) + " --ticks 1:60 --size 64x48 --msaa 0 -o " + quote(frames) +
                             " --contact-sheet " + quote(dir.file("sheet.png")) + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  EXPECT_EQ(r.err, "") << "a successful --json render writes nothing on stderr";
  const json j = parseJson(r);
  EXPECT_EQ(j.value("frames", 0), 60) << r.out;
  size_t pngs = 0;
  for (const auto& e : fs::directory_iterator(frames)) pngs += e.path().extension() == ".png" ? 1 : 0;
  EXPECT_EQ(pngs, size_t(60));
  for (const char* name : {"frame-000001.png", "frame-000030.png", "frame-000060.png"}) {
    const std::optional<Image> img = readPng((fs::path(frames) / name).string());
    ASSERT_TRUE(img) << name;
    EXPECT_EQ(img->width, 64);
    EXPECT_EQ(img->height, 48);
  }
  EXPECT_TRUE(fs::exists(dir.file("sheet.png")));
}

TEST(RenderCli, ScenarioTicksWithAStep) {
  TempDir dir;
  const std::string scenario = smallScenario(dir);
  const CliResult r =
      runCli("render " + quote(scenario) + " --ticks 0:20:10 --size 48x32 -o " + quote(dir.file("out")));
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  for (const char* name : {"frame-000000.png", "frame-000010.png", "frame-000020.png"})
    EXPECT_TRUE(fs::exists(fs::path(dir.file("out")) / name)) << name;
}

TEST(RenderCli, BadArgumentsGiveOneLineAndExitCode2) {
  TempDir dir;
  const std::string scenario = smallScenario(dir);
  const std::string out = " -o " + quote(dir.file("out"));
  const char* bad[] = {"--ticks 5:1",           "--ticks abc",  "--ticks 1:2:0", "--ticks -3", "--ticks 1:2:3:4",
                       "--ticks 0:99999999999", "--size 10x10", "--size 64",     "--size 64x", "--size axb",
                       "--camera 1,2,3",        "--msaa 3"};
  for (const std::string args : bad) {
    const CliResult r = runCli("render " + quote(scenario) + " " + args + out);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << args;
  }
  const CliResult missing = runCli("render " + quote(dir.file("nope.json")) + out);
  EXPECT_EQ(missing.exitCode, 2) << missing.describe();
  EXPECT_TRUE(isOneLine(missing.err));
}

TEST(RenderCli, TicksPastTheEndOfARecording) {
  TempDir dir;
  const std::string rec = dir.file("small.sgr");
  ASSERT_EQ(runCli("record " + quote(smallScenario(dir)) + " --ticks 10 -o " + quote(rec)).exitCode, 0);
  const CliResult r = runCli("render " + quote(rec) + " --ticks 5:11 -o " + quote(dir.file("out")));
  EXPECT_EQ(r.exitCode, 2) << r.describe();
  EXPECT_TRUE(isOneLine(r.err));
}

}  // namespace
}  // namespace sg
