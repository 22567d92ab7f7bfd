// The GPU physics path (sim/gpu/, docs/gpu-physics.md) under OSMesa's compute shaders: the same
// bits as the CPU's fixed point, tick by tick, on the golden scenes it runs; across save and
// restore in both directions; on faults (the same report and the same failed state); and
// operation by operation on particle states drawn over the formats' whole range (RapidCheck),
// where the device's fault report must be the reference's too.
#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "replay/physics_devices.h"
#include "replay/player.h"
#include "sim/gpu/gl_physics.h"
#include "sim/particles/blade.h"
#include "sim/particles/particle_row.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"
#include "viewer/offscreen/osmesa_context.h"
#include "viewer/render/scene.h"

namespace sg {
namespace viewer_test {
CliResult runViewer(const std::string& args, bool xvfb = true, const std::string& cwd = "");  // tests/viewer_test.cpp
}  // namespace viewer_test

namespace {

/// One provider for the whole test program, never destroyed (as replay/physics_devices.cpp keeps
/// the tools' one: destroying an OSMesa context from a static destructor races Mesa's teardown).
ParticleDeviceProvider& provider() {
  static ParticleDeviceProvider* const p = [] {
    std::string error;
    auto made = gpu::makeOsmesaPhysicsProvider(&error);
    if (!made) ADD_FAILURE() << error;
    return made.release();
  }();
  if (!p) throw std::runtime_error("no GPU physics provider");
  return *p;
}

std::string hex(uint64_t h) {
  char buf[19];
  std::snprintf(buf, sizeof buf, "%016llx", (unsigned long long)h);
  return buf;
}

Scenario scenarioNamed(const std::string& name, const std::string& scalar) {
  Scenario s = loadScenarioFile(test::sourcePath("scenarios/" + name + ".json"));
  s.scalar = *parseScalarKind(scalar);
  return s;
}

std::unique_ptr<SimWorld> onPath(const Scenario& s, PhysicsPath path, int threads = 1) {
  auto w = makeWorld(s, threads);
  const std::string why = w->setPhysicsPath(path, &provider());
  EXPECT_EQ(why, "");
  EXPECT_EQ(w->physicsPath(), path);
  return w;
}

/// The device's own patch stage (derivePatches, what a renderer in its context draws) against
/// the host's, which derives its copy from the device's displacement when the state is copied
/// back: every tip offset, top and tilt level, bit for bit.
template <class S>
::testing::AssertionResult devicePatchesAreTheHosts(const World<S>& w) {
  PatchArrays<S> device;
  if (!w.downloadDevicePatches(&device)) return ::testing::AssertionFailure() << "no device patches";
  const PatchArrays<S>& host = w.patches();  // copies the state back, derives the host's
  const size_t n = host.topY.size();
  for (size_t p = 0; p < n; ++p)
    if (!(device.tipOffsetX[p] == host.tipOffsetX[p]) || !(device.tipOffsetZ[p] == host.tipOffsetZ[p]) ||
        !(device.topY[p] == host.topY[p]) || device.tiltLevel[p] != host.tiltLevel[p])
      return ::testing::AssertionFailure()
             << "patch slot " << p << " of " << n << ": top " << ScalarTraits<S>::toDouble(device.topY[p])
             << " on the device, " << ScalarTraits<S>::toDouble(host.topY[p]) << " on the host";
  return ::testing::AssertionSuccess() << n << " patches";
}
::testing::AssertionResult devicePatchesAreTheHosts(const SimWorld& w) {
  if (const auto* a = dynamic_cast<const World<Fx32>*>(&w)) return devicePatchesAreTheHosts(*a);
  if (const auto* b = dynamic_cast<const World<Fx16>*>(&w)) return devicePatchesAreTheHosts(*b);
  return ::testing::AssertionFailure() << "not a fixed-point world";
}

// ---- goldens ---------------------------------------------------------------------------------

struct GoldenRun {
  std::string scenario, scalar;
  PhysicsPath path;
};
void PrintTo(const GoldenRun& r, std::ostream* os) {
  *os << r.scenario << " " << r.scalar << " " << physicsPathName(r.path);
}

class GpuGolden : public ::testing::TestWithParam<GoldenRun> {};

/// 600 ticks beside the CPU: the thesis' readback design compared every tick; the resident path
/// at ticks spread over the run (each comparison copies its state back, so comparing every tick
/// would test the readback path again), then the committed golden at tick 600.
TEST_P(GpuGolden, EveryComparedTickEqualsTheCpuAndTheGolden) {
  const GoldenRun& r = GetParam();
  const Scenario s = scenarioNamed(r.scenario, r.scalar);
  auto cpu = makeWorld(s, 2);
  auto gpu = onPath(s, r.path);
  for (int64_t t = 1; t <= 600; ++t) {
    ASSERT_TRUE(cpu->step(scriptedInput(s, cpu->tick())).ok);
    ASSERT_TRUE(gpu->step(scriptedInput(s, gpu->tick())).ok) << "tick " << t;
    const bool compare = r.path == PhysicsPath::GpuReadback || t <= 3 || t % 97 == 0 || t == 600;
    if (compare) {
      if (r.path == PhysicsPath::Gpu) {
        ASSERT_TRUE(devicePatchesAreTheHosts(*gpu)) << "tick " << t;
      }
      ASSERT_EQ(hex(gpu->stateHash()), hex(cpu->stateHash())) << "tick " << t;
    }
  }
  std::ifstream in(test::sourcePath("tests/golden/state_hashes.json"));
  const auto golden = nlohmann::json::parse(in);
  EXPECT_EQ(hex(gpu->stateHash()), golden.at(r.scenario + "/" + r.scalar).get<std::string>());
  // The renderer's view (patches) too: derived on the host from the device's displacement.
  Observation a, b;
  cpu->observe(a);
  gpu->observe(b);
  EXPECT_EQ(a.tipX, b.tipX);
  EXPECT_EQ(a.tipY, b.tipY);
  EXPECT_EQ(a.tipZ, b.tipZ);
}

std::vector<GoldenRun> goldenRuns() {
  std::vector<GoldenRun> runs;
  // Every golden on the resident path (with bodies, the rows under them go to the host and back
  // each tick; with the window, a move copies everything); the readback path, whose copy back is
  // the same code every tick, on the meadow in both formats and once with bodies.
  for (const char* scenario :
       {"thesis-meadow", "hilly-meadow", "wind-fronts", "thesis-bodies", "mower-field", "blade-bodies", "lod-crossing"})
    for (const char* scalar : {"fx32", "fx16"}) runs.push_back({scenario, scalar, PhysicsPath::Gpu});
  for (const char* scalar : {"fx32", "fx16"}) runs.push_back({"thesis-meadow", scalar, PhysicsPath::GpuReadback});
  runs.push_back({"thesis-bodies", "fx16", PhysicsPath::GpuReadback});
  return runs;
}
INSTANTIATE_TEST_SUITE_P(Goldens, GpuGolden, ::testing::ValuesIn(goldenRuns()),
                         [](const ::testing::TestParamInfo<GoldenRun>& info) {
                           std::string n =
                               info.param.scenario + "_" + info.param.scalar + "_" + physicsPathName(info.param.path);
                           for (char& c : n)
                             if (c == '-') c = '_';
                           return n;
                         });

/// wind-fronts (gust fronts) under a level-of-detail window of side x side particles.
Scenario windowedWindFronts(const char* scalar, int side) {
  Scenario s = scenarioNamed("wind-fronts", scalar);
  s.lod.mode = LodMode::Window;
  s.lod.windowX = s.lod.windowZ = side;
  s.lod.edgeRows = 4;
  return s;
}

/// The camera at tick t, drifting from the field's -x/-z corner (-14.06 m) across it by x256 and
/// z256 / 256 m a tick (as Q32.32), which moves the window.
TickInput driftingCamera(int64_t t, int64_t x256, int64_t z256) {
  TickInput in;
  in.hasCamera = true;
  in.camera = {(-3600 + x256 * t) << 24, 0, (-3600 + z256 * t) << 24};
  return in;
}

/// A level-of-detail window moving under gust fronts (the golden lod-crossing has row-uniform
/// wind): each move copies the particles back, writes the entering cells and uploads them again,
/// and a gust run that wraps round the window's toroidal storage is split as the CPU splits it.
TEST(GpuPhysics, AMovingWindowUnderGustFrontsMatchesTheCpu) {
  for (const char* scalar : {"fx32", "fx16"}) {
    const Scenario s = windowedWindFronts(scalar, 31);
    auto cpu = makeWorld(s, 1);
    auto gpu = onPath(s, PhysicsPath::Gpu);
    for (int64_t t = 1; t <= 300; ++t) {
      const TickInput in = driftingCamera(t, 24, 17);
      ASSERT_TRUE(cpu->step(in).ok);
      ASSERT_TRUE(gpu->step(in).ok);
      if (t % 30 == 0) {
        ASSERT_EQ(hex(gpu->stateHash()), hex(cpu->stateHash())) << scalar << " tick " << t;
      }
    }
    EXPECT_NE(cpu->counts().windowOriginI, 0) << "the window was meant to move";
  }
}

/// The device's patch stage at every interpolation k (k = 3's weights are not powers of two),
/// under a level-of-detail window drifting across the field, whose patch and particle storage
/// wrap independently.
TEST(GpuPhysics, DevicePatchStageIsTheHostsAtEveryInterpolation) {
  for (const char* scalar : {"fx32", "fx16"})
    for (int k : {1, 2, 3, 4}) {
      Scenario s = windowedWindFronts(scalar, 23);
      s.particles.interpolation = k;
      auto gpu = onPath(s, PhysicsPath::Gpu);
      for (int64_t t = 1; t <= 120; ++t) {
        ASSERT_TRUE(gpu->step(driftingCamera(t, 30, 21)).ok);
        if (t % 40 == 0) {
          ASSERT_TRUE(devicePatchesAreTheHosts(*gpu)) << scalar << " k " << k << " tick " << t;
        }
      }
      EXPECT_NE(gpu->counts().windowOriginI, 0) << "the window was meant to move";
    }
}

/// The resident path's promise: between ticks nothing comes back but the 4-byte fault word,
/// until the host reads the state (a hash here), which copies the particles and displacement.
TEST(GpuPhysics, TheResidentPathCopiesBackOnlyTheFaultWord) {
  const Scenario s = scenarioNamed("thesis-meadow", "fx32");
  auto gpu = onPath(s, PhysicsPath::Gpu);
  for (int t = 0; t < 30; ++t) ASSERT_TRUE(gpu->step(TickInput{}).ok);
  EXPECT_EQ(gpu->deviceTraffic().toHost, 30 * 4);
  EXPECT_NE(gpu->devicePatchDrawBuffer(), 0u);
  (void)gpu->stateHash();
  const int64_t particles = gpu->counts().particles();
  // positions and velocities, and the displacement the host derives its patches from: 9 arrays
  EXPECT_EQ(gpu->deviceTraffic().toHost, 30 * 4 + 9 * particles * 8);
  EXPECT_NE(gpu->devicePatchDrawBuffer(), 0u) << "a copy back leaves the device's patches current";
  gpu->restoreState(gpu->saveState());
  EXPECT_EQ(gpu->devicePatchDrawBuffer(), 0u) << "the host set the state: the device's patches are stale";
  ASSERT_TRUE(gpu->step(TickInput{}).ok);
  EXPECT_NE(gpu->devicePatchDrawBuffer(), 0u);
  // A level-of-detail window moving under the camera: the host writes the entering cells and
  // sends just those up; nothing comes back.
  auto window = onPath(windowedWindFronts("fx32", 31), PhysicsPath::Gpu);
  for (int64_t t = 1; t <= 90; ++t) ASSERT_TRUE(window->step(driftingCamera(t, 40, 25)).ok);
  EXPECT_GT(window->counts().windowOriginI, 0) << "the window was meant to move";
  EXPECT_EQ(window->deviceTraffic().toHost, 90 * 4);
  auto readback = onPath(s, PhysicsPath::GpuReadback);
  ASSERT_TRUE(readback->step(TickInput{}).ok);
  EXPECT_EQ(readback->devicePatchDrawBuffer(), 0u) << "gpu-readback derives the patches on the host";
}

/// `render --physics gpu`: the device lives in the renderer's context and the frames draw the
/// tufts' tops from its buffer. The frames are the CPU's, byte for byte, and 60 ticks copy back
/// 240 bytes: one fault word a tick.
TEST(GpuPhysics, RenderDrawsTheDevicesTopsWithoutCopyingThemBack) {
  TempDir dir;
  // The meadow; and blade-bodies, whose bodies push the grass on the device and leave trampled
  // blades there, drawn darker and flatter from the device's trample levels.
  struct Case {
    const char* scenario;
    const char* ticks;
    int64_t lastTick;
    std::vector<const char*> frames;
  };
  for (const Case& c :
       {Case{"thesis-meadow", "0:60:30", 60, {"frame-000000.png", "frame-000030.png", "frame-000060.png"}},
        Case{"blade-bodies", "90:180:90", 180, {"frame-000090.png", "frame-000180.png"}}}) {
    const std::string scenario = quote(test::sourcePath(std::string("scenarios/") + c.scenario + ".json"));
    for (const char* path : {"cpu", "gpu"}) {
      const CliResult r = runCli("render " + scenario + " -o " + quote(dir.file(std::string(c.scenario) + path)) +
                                 " --ticks " + c.ticks + " --size 200x120 --json --physics " + path);
      ASSERT_EQ(r.exitCode, 0) << r.describe();
      const json j = parseJson(r);
      // The pass's fault word a tick, and the push's where bodies push the grass.
      const int64_t back = j.at("deviceBytesToHost").get<int64_t>();
      const bool bodies = std::string(c.scenario) != "thesis-meadow", onGpu = std::string(path) == "gpu";
      EXPECT_GE(back, onGpu ? c.lastTick * 4 : 0) << r.out;
      EXPECT_LE(back, onGpu ? c.lastTick * (bodies ? 8 : 4) : 0) << r.out;
    }
    for (const char* frame : c.frames) {
      const std::vector<uint8_t> cpu = readBytes(dir.file(std::string(c.scenario) + "cpu/" + frame));
      ASSERT_FALSE(cpu.empty()) << frame;
      EXPECT_TRUE(cpu == readBytes(dir.file(std::string(c.scenario) + "gpu/" + frame)))
          << c.scenario << " " << frame << " differs";
    }
  }
  const std::string scenario = quote(test::sourcePath("scenarios/thesis-meadow.json"));
  const CliResult bad = runCli("render " + scenario + " -o " + quote(dir.file("bad")) + " --physics cuda");
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_TRUE(isOneLine(bad.err));
}

/// The viewer's display interpolation between ticks (interpolateScene) on the device path: the
/// renderer blends the tops from the device's two draw buffers, the tick before and this one, as
/// the host blends its own: the CPU path's interpolated frame, which is neither tick's (the
/// meadow's tips move up to 1.7 mm a tick at tick 40).
TEST(GpuPhysics, DisplayInterpolationBlendsTheDevicesTwoTicks) {
  std::string error;
  auto offscreen = viewer::OffscreenRenderer::create(240, 160, 0, &error);
  ASSERT_TRUE(offscreen) << error;
  auto inContext = gpu::makeCurrentContextPhysicsProvider(&error);
  ASSERT_TRUE(inContext) << error;
  const Scenario s = scenarioNamed("thesis-meadow", "fx32");
  auto cpu = makeWorld(s, 1);
  auto gpu = makeWorld(s, 1);
  ASSERT_EQ(gpu->setPhysicsPath(PhysicsPath::Gpu, inContext.get()), "");
  for (int64_t t = 0; t < 40; ++t) {
    ASSERT_TRUE(cpu->step(TickInput{}).ok);
    ASSERT_TRUE(gpu->step(TickInput{}).ok);
  }
  viewer::Scene beforeCpu, beforeGpu, nowCpu, nowGpu, shownCpu, shownGpu;
  viewer::extractScene(*cpu, s, &beforeCpu);
  viewer::extractScene(*gpu, s, &beforeGpu);
  ASSERT_TRUE(cpu->step(TickInput{}).ok);
  ASSERT_TRUE(gpu->step(TickInput{}).ok);
  viewer::extractScene(*cpu, s, &nowCpu);
  viewer::extractScene(*gpu, s, &nowGpu);
  ASSERT_NE(beforeGpu.deviceTops, 0u);
  ASSERT_NE(nowGpu.deviceTops, beforeGpu.deviceTops) << "the device alternates its draw buffers";
  viewer::interpolateScene(beforeCpu, nowCpu, 0.5f, &shownCpu);
  viewer::interpolateScene(beforeGpu, nowGpu, 0.5f, &shownGpu);
  ASSERT_EQ(shownGpu.deviceTopsPrevious, beforeGpu.deviceTops);
  const viewer::Camera camera = viewer::Camera::lookingAt(-1.5f, 0.9f, -1.5f, 0, 0.4f, 0);
  const viewer::Image cpuHalf = offscreen->render(shownCpu, camera), gpuHalf = offscreen->render(shownGpu, camera);
  const viewer::Image gpuNow = offscreen->render(nowGpu, camera), gpuBefore = offscreen->render(beforeGpu, camera);
  EXPECT_TRUE(gpuHalf.rgba == cpuHalf.rgba) << "half way between two ticks: the CPU path's frame";
  EXPECT_FALSE(gpuHalf.rgba == gpuNow.rgba);
  EXPECT_FALSE(gpuHalf.rgba == gpuBefore.rgba) << "the tick before's buffer still holds its own state";
  gpu.reset();  // its device, while the provider's context is current
}

/// The viewer runs the device in its window's GLX context (`--physics gpu`, the script's and the
/// Physics panel's `physics`), switches paths mid-run with the state carried over, and draws the
/// tufts from the device's buffer: the same pixels and hashes as a CPU session. A recording plays
/// there with every recorded hash matching.
TEST(GpuPhysics, TheViewerDrawsFromTheDeviceInItsOwnContext) {
  TempDir dir;
  const std::string scenario = quote(test::sourcePath("scenarios/wind-fronts.json"));
  const std::string window = " --size 240x136 --msaa 0";
  // The panels hidden (F2): they show timings. On the device from tick 0, to the CPU at tick 8
  // and back at 12; drawn at tick 20 from the device's buffer.
  dir.write("cpu.txt", "tap f2\nframes 20\nscreenshot " + dir.file("cpu.png") + "\nprint\nframes 6\nprint\nquit\n");
  dir.write("gpu.txt", "tap f2\nframes 8\nphysics cpu\nframes 4\nphysics gpu\nframes 8\nscreenshot " +
                           dir.file("gpu.png") +
                           "\nprint\nphysics gpu-readback\nframes 3\nphysics cpu\nframes 3\nprint\nquit\n");
  const CliResult cpu = viewer_test::runViewer(scenario + " --script " + quote(dir.file("cpu.txt")) + window);
  const CliResult gpu =
      viewer_test::runViewer(scenario + " --physics gpu --script " + quote(dir.file("gpu.txt")) + window);
  ASSERT_EQ(cpu.exitCode, 0) << cpu.describe();
  ASSERT_EQ(gpu.exitCode, 0) << gpu.describe();
  const auto line = [](const std::string& out, size_t n) {
    size_t at = 0;
    for (size_t i = 0; i < n; ++i) at = out.find('\n', at) + 1;
    return out.substr(at, out.find('\n', at) - at);
  };
  EXPECT_NE(line(cpu.out, 0).find("tick 20"), std::string::npos) << cpu.out;
  EXPECT_EQ(line(gpu.out, 0), line(cpu.out, 0));  // tick 20: the same hash
  EXPECT_EQ(line(gpu.out, 1), line(cpu.out, 1));  // tick 26, after gpu-readback and the CPU
  const std::vector<uint8_t> a = readBytes(dir.file("cpu.png")), b = readBytes(dir.file("gpu.png"));
  ASSERT_FALSE(a.empty());
  EXPECT_TRUE(a == b) << "the frame drawn from the device differs from the CPU's";
  // A recording plays on the device too, every recorded hash checked as it plays.
  dir.write("play.txt", "play\nframes 12\npause\nprint\nquit\n");
  const CliResult play = viewer_test::runViewer(quote(test::sourcePath("scenarios/recordings/thesis-meadow-fx32.sgr")) +
                                                " --physics gpu --script " + quote(dir.file("play.txt")) + window);
  ASSERT_EQ(play.exitCode, 0) << play.describe();
  EXPECT_NE(play.out.find("mismatch -1"), std::string::npos) << play.out;
  EXPECT_EQ(play.out.find("hashes ok 0,"), std::string::npos) << play.out;
}

/// `sweep --physics cpu,gpu`: each fx32 row gets a device twin with the same errors (the same
/// bits), double stays on the CPU (it has no device path), and the CSV and JSON name the path.
TEST(GpuPhysics, SweepHasAPhysicsAxis) {
  TempDir dir;
  const CliResult r = runCli("sweep --scenarios " + quote(test::sourcePath("scenarios/sweep-bodies.json")) +
                             " --scalars fx32,double --k 1 --dt 1/60 --lod off --physics cpu,gpu --seconds 0.25 "
                             "--repeats 1 --json --out " +
                             quote(dir.file("out")));
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  const json j = parseJson(r);
  std::map<std::string, json> rows;
  for (const json& row : j.at("rows"))
    rows[row.at("scalar").get<std::string>() + "/" + row.at("physics").get<std::string>()] = row;
  ASSERT_EQ(rows.size(), 3u) << j.at("rows").dump();
  ASSERT_TRUE(rows.count("fx32/gpu") && rows.count("fx32/cpu") && rows.count("double/cpu"));
  for (const char* key : {"tip_rms_m", "tip_max_m", "body_pos_max_m"})
    EXPECT_EQ(rows["fx32/gpu"].at(key), rows["fx32/cpu"].at(key)) << key;
  EXPECT_NE(readFile(dir.file("out/sweep.csv")).find(",gpu\n"), std::string::npos);
  const CliResult bad = runCli("sweep --scalars double --physics gpu --out " + quote(dir.file("bad")));
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_TRUE(isOneLine(bad.err));
}

/// What no golden runs on this path: the pbd constraint mode with gust fronts at k = 2, and the
/// blade model with trample levels (which only bodies raise: here they decay from zero, but are
/// state, uploaded, stepped and hashed all the same).
TEST(GpuPhysics, PbdFrontsAndTramplingBladesMatchTheCpu) {
  for (const char* scalar : {"fx32", "fx16"})
    for (GrassModel model : {GrassModel::Pbd, GrassModel::Blade}) {
      Scenario s = scenarioNamed("wind-fronts", scalar);
      s.particles.model = model;
      if (model == GrassModel::Blade) s.particles.blade.trampleSeconds = Rational{2, 1};
      auto cpu = makeWorld(s, 1);
      auto gpu = onPath(s, PhysicsPath::Gpu);
      for (int64_t t = 1; t <= 300; ++t) {
        ASSERT_TRUE(cpu->step(TickInput{}).ok);
        ASSERT_TRUE(gpu->step(TickInput{}).ok);
        if (t % 50 == 0) {
          ASSERT_EQ(hex(gpu->stateHash()), hex(cpu->stateHash())) << scalar << " tick " << t;
        }
      }
    }
}

// ---- save and restore across devices ---------------------------------------------------------

TEST(GpuPhysics, SaveOnCpuRestoreOnGpuAndBack) {
  for (const char* scalar : {"fx32", "fx16"}) {
    const Scenario s = scenarioNamed("hilly-meadow", scalar);
    auto reference = makeWorld(s, 1);
    for (int t = 0; t < 240; ++t) ASSERT_TRUE(reference->step(TickInput{}).ok);
    // CPU 0..80 -> GPU 80..160 -> CPU 160..240.
    auto cpu = makeWorld(s, 1);
    for (int t = 0; t < 80; ++t) ASSERT_TRUE(cpu->step(TickInput{}).ok);
    auto gpu = onPath(s, PhysicsPath::Gpu);
    gpu->restoreState(cpu->saveState());
    for (int t = 0; t < 80; ++t) ASSERT_TRUE(gpu->step(TickInput{}).ok);
    auto back = makeWorld(s, 1);
    back->restoreState(gpu->saveState());
    for (int t = 0; t < 80; ++t) ASSERT_TRUE(back->step(TickInput{}).ok);
    EXPECT_EQ(hex(back->stateHash()), hex(reference->stateHash())) << scalar;
    // And one world switching paths in the middle of a run.
    auto switching = makeWorld(s, 1);
    for (int t = 0; t < 240; ++t) {
      if (t == 60) {
        ASSERT_EQ(applyPhysicsPath(*switching, PhysicsPath::Cpu), "");
        ASSERT_EQ(switching->setPhysicsPath(PhysicsPath::Gpu, &provider()), "");
      } else if (t == 120) {
        ASSERT_EQ(switching->setPhysicsPath(PhysicsPath::GpuReadback, &provider()), "");
      } else if (t == 180) {
        ASSERT_EQ(switching->setPhysicsPath(PhysicsPath::Cpu, nullptr), "");
      }
      ASSERT_TRUE(switching->step(TickInput{}).ok);
    }
    EXPECT_EQ(hex(switching->stateHash()), hex(reference->stateHash())) << scalar;
  }
}

// ---- recordings -----------------------------------------------------------------------------

/// The committed recordings made on the CPU verify on the device path (replay --physics gpu).
TEST(GpuPhysics, CpuRecordingsVerifyOnTheDevice) {
  registerGpuPhysics(&gpu::makeOsmesaPhysicsProvider);
  for (const char* name : {"thesis-meadow-fx32", "thesis-bodies-fx32", "mower-field-fx16", "drive-football-interp2",
                           "lod-crossing-fx32"}) {
    const sgr::Recording rec =
        sgr::readRecording(test::sourcePath(std::string("scenarios/recordings/") + name + ".sgr"));
    VariantSettings onDevice;
    onDevice.physics = PhysicsPath::Gpu;
    Player player(rec, 1, onDevice);
    ASSERT_EQ(player.world().physicsPath(), PhysicsPath::Gpu) << name;
    const VerifyReport report = player.verify();
    EXPECT_TRUE(report.ok) << name << ": first mismatch at tick " << report.firstMismatchTick;
    EXPECT_GT(report.checksVerified, 100) << name;
  }
}

// ---- faults ----------------------------------------------------------------------------------

/// A meadow whose tufts speed up until fx16 overflows (8000 m/s^2 upward, no damping): the GPU
/// world fails at the CPU's tick, stage and particle, and holds the CPU's failed state (the
/// faulting tick is redone by the reference from the device's untouched input).
TEST(GpuPhysics, AFaultIsTheReferencesReportAndState) {
  Scenario s = scenarioNamed("thesis-meadow", "fx16");
  s.particles.acceleration = {Rational{0, 1}, Rational{8000, 1}, Rational{0, 1}};
  s.particles.damping = Rational{1, 1};
  for (PhysicsPath path : {PhysicsPath::Gpu, PhysicsPath::GpuReadback}) {
    auto cpu = makeWorld(s, 1);
    auto gpu = onPath(s, path);
    StepResult a, b;
    for (int t = 0; t < 600 && a.ok; ++t) {
      a = cpu->step(TickInput{});
      b = gpu->step(TickInput{});
      ASSERT_EQ(a.ok, b.ok) << "tick " << t;
    }
    ASSERT_FALSE(a.ok) << "the scene was meant to overflow";
    EXPECT_EQ(b.error.message(), a.error.message());
    EXPECT_EQ(hex(gpu->stateHash()), hex(cpu->stateHash()));
    EXPECT_FALSE(gpu->step(TickInput{}).ok);  // failed stays failed
  }
}

// ---- what the path does not run --------------------------------------------------------------

/// double has no device path: refused in one line, the world left on the CPU and still stepping.
TEST(GpuPhysics, DoubleIsRefusedInOneLine) {
  auto w = makeWorld(scenarioNamed("thesis-meadow", "double"), 1);
  const std::string why = w->setPhysicsPath(PhysicsPath::GpuReadback, &provider());
  EXPECT_NE(why.find("fx32 and fx16"), std::string::npos) << why;
  EXPECT_EQ(why.find('\n'), std::string::npos);
  EXPECT_EQ(w->physicsPath(), PhysicsPath::Cpu);
  EXPECT_TRUE(w->step(TickInput{}).ok);
}

/// float on the device is a comparison variant with no promise of the CPU's bits, but it must be
/// as accurate as the CPU's float: against a double run of the same scene, its largest tip error
/// over 600 ticks stays within twice the CPU float's own (the same operations, rounded by another
/// implementation of IEEE float) plus a micrometre.
TEST(GpuPhysics, FloatOnTheDeviceIsAsAccurateAsTheCpusFloat) {
  for (const char* name : {"thesis-bodies", "wind-fronts"}) {
    const Scenario s = scenarioNamed(name, "float");
    Scenario sd = s;
    sd.scalar = ScalarKind::Double;
    auto reference = makeWorld(sd, 1);
    auto cpu = makeWorld(s, 1);
    auto gpu = onPath(s, PhysicsPath::Gpu);
    double cpuError = 0, gpuError = 0;
    Observation r, a, b;
    for (int t = 0; t < 600; ++t) {
      ASSERT_TRUE(reference->step(scriptedInput(s, t)).ok);
      ASSERT_TRUE(cpu->step(scriptedInput(s, t)).ok);
      ASSERT_TRUE(gpu->step(scriptedInput(s, t)).ok);
      if (t % 20 != 19) continue;
      reference->observe(r);
      cpu->observe(a);
      gpu->observe(b);
      for (size_t i = 0; i < r.tipX.size(); ++i) {
        const auto error = [&](const Observation& o) {
          return std::max(
              {std::abs(o.tipX[i] - r.tipX[i]), std::abs(o.tipY[i] - r.tipY[i]), std::abs(o.tipZ[i] - r.tipZ[i])});
        };
        cpuError = std::max(cpuError, error(a));
        gpuError = std::max(gpuError, error(b));
      }
    }
    EXPECT_GT(cpuError, 0.0) << name;
    EXPECT_LE(gpuError, 2 * cpuError + 1e-6)
        << name << ": device float " << gpuError << " m, CPU float " << cpuError << " m";
    RecordProperty(std::string(name) + "_identical_to_cpu_float", hex(gpu->stateHash()) == hex(cpu->stateHash()));
  }
}

// ---- the arithmetic, state by state ----------------------------------------------------------

/// A raw value of S whose magnitude is 2^b for b drawn over the whole format (so products,
/// roots and quotients meet every carry and every overflow boundary), or a value at one of the
/// format's edges.
template <class S>
rc::Gen<typename S::RawType> genRaw() {
  using Raw = typename S::RawType;
  constexpr int kBits = int(sizeof(Raw) * 8) - 1;
  return rc::gen::oneOf(
      rc::gen::map(rc::gen::tuple(rc::gen::inRange(0, kBits + 1), rc::gen::arbitrary<Raw>()),
                   [](const std::tuple<int, Raw>& t) {
                     const auto [bits, noise] = t;
                     using U = std::make_unsigned_t<Raw>;
                     const U mask = bits >= kBits ? U(~U(0)) : U((U(1) << bits) - 1);
                     return Raw(U(noise) & mask) * (noise < 0 ? Raw(-1) : Raw(1));
                   }),
      rc::gen::element(std::numeric_limits<Raw>::min(), std::numeric_limits<Raw>::max(), Raw(0), Raw(1), Raw(-1)));
}

/// Particle states of a small grid (countX x countZ) in which each value is drawn near a base
/// scale (so most particles step without faulting and the comparison covers their bits), with a
/// few drawn from the whole range; each row split into runs of columns under their own wind, as
/// gust fronts split them; any grass model, the blade with or without trample levels.
template <class S>
void deviceMatchesTheReference(GrassModel model, bool tramples) {
  using Raw = typename S::RawType;
  tramples = tramples && model == GrassModel::Blade;
  const int64_t countX = *rc::gen::inRange<int64_t>(1, 40);
  const int64_t countZ = *rc::gen::inRange<int64_t>(1, 6);
  const int64_t n = countX * countZ;
  // Bits of a typical value: up to three quarters of the format, where products still fit.
  const int scale = *rc::gen::inRange(1, int(sizeof(Raw) * 6) + 1);
  const auto typical = rc::gen::map(rc::gen::arbitrary<Raw>(), [scale](Raw v) {
    using U = std::make_unsigned_t<Raw>;
    return Raw(U(v) & ((U(1) << scale) - 1)) - (Raw(1) << (scale > 0 ? scale - 1 : 0));
  });
  const auto value = rc::gen::weightedOneOf<Raw>({{19, typical}, {1, genRaw<S>()}});
  ParticleArrays<S> p;
  p.resize(size_t(n), tramples);
  for (auto* v : {&p.px, &p.py, &p.pz, &p.vx, &p.vy, &p.vz, &p.anchorX, &p.anchorY, &p.anchorZ})
    for (S& x : *v) x = S::fromRaw(*value);
  for (S& t : p.trample) t = S::fromRaw(*rc::gen::inRange<Raw>(0, Raw(1) << S::kFracBits));  // [0, 1)
  ParticleConstants<S> c;
  for (S* k : {&c.dt, &c.dampingPerTick, &c.invDt, &c.bladeStiffnessDt, &c.bladeDampingPerTick, &c.trampleDecayPerTick,
               &c.invRodLength})
    *k = S::fromRaw(*value);
  c.rodLength = S::fromRaw(*rc::gen::suchThat(value, [](Raw v) { return v > 0; }));
  DeviceWind<S> wind;
  for (int64_t r = 0; r < countZ; ++r) {
    wind.rowFirstRun.push_back(int32_t(wind.runBegin.size()));
    std::vector<int64_t> starts = {0};
    for (int64_t col = 1; col < countX; ++col)
      if (*rc::gen::inRange(0, 8) == 0) starts.push_back(col);
    for (int64_t begin : starts) {
      wind.runBegin.push_back(int32_t(begin));
      wind.dvx.push_back(S::fromRaw(*value));
      wind.dvy.push_back(S::fromRaw(*value));
      wind.dvz.push_back(S::fromRaw(*value));
    }
  }
  wind.rowFirstRun.push_back(int32_t(wind.runBegin.size()));

  // The reference: row by row, run by run in column order, stopping at the first fault, as the
  // world's integrate stage does.
  ParticleArrays<S> ref = p;
  std::vector<S> rdx(static_cast<size_t>(n)), rdy(rdx), rdz(rdx);
  RowFault expected;
  uint32_t expectedBits = 0;
  takeFixedFaults();
  for (int64_t r = 0; r < countZ && expected.particle < 0; ++r) {
    const int32_t first = wind.rowFirstRun[size_t(r)], end = wind.rowFirstRun[size_t(r) + 1];
    for (int32_t k = first; k < end && expected.particle < 0; ++k) {
      const int64_t b = r * countX + wind.runBegin[size_t(k)];
      const int64_t e = r * countX + (k + 1 < end ? wind.runBegin[size_t(k) + 1] : countX);
      const S dvx = wind.dvx[size_t(k)], dvy = wind.dvy[size_t(k)], dvz = wind.dvz[size_t(k)];
      if (model == GrassModel::Blade) {
        expected.stage = Stage::Integrate;
        expected.particle = tramples ? advanceBladeRowScalar<S, true>(ref, b, e, dvx, dvy, dvz, c, rdx, rdy, rdz)
                                     : advanceBladeRowScalar<S, false>(ref, b, e, dvx, dvy, dvz, c, rdx, rdy, rdz);
      } else {
        expected = model == GrassModel::Pbd
                       ? advanceParticleRowScalar<S, true>(ref, b, e, dvx, dvy, dvz, c, rdx, rdy, rdz)
                       : advanceParticleRowScalar<S, false>(ref, b, e, dvx, dvy, dvz, c, rdx, rdy, rdz);
      }
      if (expected.particle >= 0) expectedBits = takeFixedFaults();
    }
  }
  takeFixedFaults();

  std::string error;
  std::unique_ptr<ParticleDevice<S>> device;
  if constexpr (std::is_same_v<S, Fx32>)
    device = provider().makeFx32(countX, countZ, model, tramples, &error);
  else
    device = provider().makeFx16(countX, countZ, model, tramples, &error);
  RC_ASSERT(device != nullptr);
  device->upload(p);
  uint32_t bits = 0;
  const RowFault got = device->advance(wind, c, &bits);
  RC_ASSERT(got.particle == expected.particle);
  ParticleArrays<S> out = p;
  std::vector<S> dx(static_cast<size_t>(n)), dy(dx), dz(dx);
  device->download(out, &dx, &dy, &dz);
  if (expected.particle >= 0) {
    RC_ASSERT(got.stage == expected.stage);
    RC_ASSERT(bits == expectedBits);
    // The tick's input, kept for the reference to redo.
    RC_ASSERT(out.px == p.px && out.vz == p.vz && out.trample == p.trample);
    return;
  }
  RC_TAG("no fault");
  RC_ASSERT(out.px == ref.px && out.py == ref.py && out.pz == ref.pz);
  RC_ASSERT(out.vx == ref.vx && out.vy == ref.vy && out.vz == ref.vz);
  RC_ASSERT(out.trample == ref.trample);
  RC_ASSERT(dx == rdx && dy == rdy && dz == rdz);
}

rc::Gen<GrassModel> genModel() { return rc::gen::element(GrassModel::Thesis, GrassModel::Pbd, GrassModel::Blade); }

RC_GTEST_PROP(GpuArithmetic, Fx32PassIsTheReference, ()) {
  deviceMatchesTheReference<Fx32>(*genModel(), *rc::gen::arbitrary<bool>());
}
RC_GTEST_PROP(GpuArithmetic, Fx16PassIsTheReference, ()) {
  deviceMatchesTheReference<Fx16>(*genModel(), *rc::gen::arbitrary<bool>());
}

// ---- bodies pushing the grass on the device ---------------------------------------------------

/// A random scene of bodies in a small meadow (thesis-bodies' grass): 1 to 6 spheres, boxes and
/// two-part compounds, turned every way, thrown into the tufts at up to 4 m/s, with masses from
/// 1 to 1000 kg; every grass model, box normal, tip contact, grass broad phase and grass drag;
/// sometimes a level-of-detail window the camera drags across the field, so rows and columns
/// wrap in storage. The device's fused push must give the CPU's state, tick by tick.
template <class S>
void bodyPushesAreTheCpus() {
  Scenario s = scenarioNamed("thesis-bodies", ScalarTraits<S>::kind == ScalarKind::Fx32 ? "fx32" : "fx16");
  s.field.patchesX = *rc::gen::inRange<int64_t>(12, 29);
  s.field.patchesZ = *rc::gen::inRange<int64_t>(12, 29);
  s.particles.model = *genModel();
  if (s.particles.model == GrassModel::Blade && *rc::gen::arbitrary<bool>())
    s.particles.blade.trampleSeconds = Rational{2, 1};
  s.bodies.boxParticleNormal = *rc::gen::element(BoxParticleNormal::Up, BoxParticleNormal::NearestFace);
  s.bodies.tipContact = *rc::gen::element(TipContact::Push, TipContact::Hold);
  s.bodies.particleBroadphase = *rc::gen::element(ParticleBroadphase::Grid, ParticleBroadphase::Brute);
  s.bodies.grassDrag = *rc::gen::element(Rational{0, 1}, Rational{1, 2});
  s.script.clear();
  s.bodies.list.clear();
  const auto cm = [](int v) { return *Rational::make(v, 100); };
  const auto halfWidth = [&](int64_t patches) { return int(patches * 25 / 2); };  // cm (0.25 m spacing)
  const int bodies = *rc::gen::inRange(1, 7);
  for (int b = 0; b < bodies; ++b) {
    BodySpec body;
    body.name = "b" + std::to_string(b);
    const int kind = *rc::gen::inRange(0, 3);  // sphere, box, compound
    for (int k = 0; k < (kind == 2 ? 2 : 1); ++k) {
      ShapeSpec part;
      part.type = (kind == 0 || (kind == 2 && k == 0)) ? ShapeType::Sphere : ShapeType::Box;
      part.radius = cm(*rc::gen::inRange(8, 80));
      part.halfExtents = {cm(*rc::gen::inRange(5, 70)), cm(*rc::gen::inRange(5, 70)), cm(*rc::gen::inRange(5, 70))};
      if (kind == 2) part.offset = {cm(k == 0 ? -30 : 30), cm(0), cm(*rc::gen::inRange(-20, 21))};
      body.parts.push_back(part);
    }
    body.compound = kind == 2;
    body.mass = Rational{*rc::gen::element<int64_t>(1, 5, 80, 1000), 1};
    const int wx = halfWidth(s.field.patchesX), wz = halfWidth(s.field.patchesZ);
    body.position = {cm(*rc::gen::inRange(-wx, wx + 1)), cm(*rc::gen::inRange(5, 90)),
                     cm(*rc::gen::inRange(-wz, wz + 1))};
    body.orientation = {cm(*rc::gen::inRange(1, 101)), cm(*rc::gen::inRange(-100, 101)),
                        cm(*rc::gen::inRange(-100, 101)), cm(*rc::gen::inRange(-100, 101))};
    body.velocity = {cm(*rc::gen::inRange(-400, 401)), cm(*rc::gen::inRange(-100, 101)),
                     cm(*rc::gen::inRange(-400, 401))};
    body.angularVelocity = {cm(*rc::gen::inRange(-300, 301)), cm(*rc::gen::inRange(-300, 301)),
                            cm(*rc::gen::inRange(-300, 301))};
    s.bodies.list.push_back(body);
  }
  const bool window = *rc::gen::arbitrary<bool>();
  if (window) {
    s.lod.mode = LodMode::Window;
    s.lod.windowX = s.field.patchesX - 4;
    s.lod.windowZ = s.field.patchesZ - 3;
    s.lod.edgeRows = 2;
  }
  RC_TAG(s.particles.model == GrassModel::Blade ? "blade"
         : s.particles.model == GrassModel::Pbd ? "pbd"
                                                : "thesis",
         s.bodies.boxParticleNormal == BoxParticleNormal::Up ? "up" : "nearest-face",
         s.bodies.tipContact == TipContact::Hold ? "hold" : "push", window ? "window" : "field");
  auto cpu = makeWorld(s, 1);
  auto gpu = onPath(s, PhysicsPath::Gpu);
  for (int64_t t = 0; t < 24; ++t) {
    TickInput in = scriptedInput(s, t);
    if (window) {  // from the -x/-z corner, a particle spacing a tick along x, half of one along z
      in.hasCamera = true;
      in.camera = {(int64_t(-halfWidth(s.field.patchesX) + 25 * t) << 32) / 100, 0,
                   (int64_t(-halfWidth(s.field.patchesZ) + 12 * t) << 32) / 100};
    }
    const bool cpuOk = cpu->step(in).ok, gpuOk = gpu->step(in).ok;
    RC_ASSERT(cpuOk == gpuOk);
    if (!cpuOk) {
      RC_TAG("failed");
      RC_ASSERT(gpu->stateHash() == cpu->stateHash());
      return;
    }
    if (t % 8 == 7) RC_ASSERT(hex(gpu->stateHash()) == hex(cpu->stateHash()));
  }
  // It ran on the device: only the fault words and the hashes' copies came back (a pass handed
  // back to the CPU would copy the whole state back besides).
  const DeviceTraffic traffic = gpu->deviceTraffic();
  const WorldCounts counts = gpu->counts();
  const int64_t stateBytes = counts.particlesX * counts.particlesZ * int64_t(sizeof(S)) * 10;
  // A tick: the pass's fault word, the push's, and up to 6 bodies' counts.
  RC_ASSERT(traffic.toHost <= 3 * stateBytes + 24 * (4 + 4 + 4 * 6));
}

// Spheres in a line pass a tuft tip on (grass_candidates_test.cpp's chain; here four heavy
// spheres asleep in the air, so no contact moves them): each pushes the tip out of its far side
// into the next, two radii beyond the lattice ranges' allowance, to a sphere whose range does not
// hold the tip's root, so the tip must meet every later part in order (the escape), along x
// within its row and along z through parts bucketed in other rows. One tick on each path.
template <class S>
void chainedPushesAreTheCpus(bool alongZ) {
  Scenario scenario = test::thesisMeadow();
  scenario.field.patchesX = scenario.field.patchesZ = 40;
  scenario.wind.schedule.clear();
  scenario.bodies.gravity = test::r3(0, 0, 0);
  for (int k = 0; k < 4; ++k) {
    BodySpec b = test::sphere("link", Rational{1, 2}, test::r3(0, 5, 0));
    b.name += std::to_string(k);
    b.mass = Rational{1000, 1};
    scenario.bodies.list.push_back(b);
  }
  auto cpu = test::makeTyped<S>(scenario);
  auto gpu = test::makeTyped<S>(scenario);
  ASSERT_EQ(gpu->setPhysicsPath(PhysicsPath::Gpu, &provider()), "");
  for (World<S>* w : {cpu.get(), gpu.get()}) {
    ParticleArrays<S>& particles = w->mutableParticles();
    const size_t tip = particles.px.size() / 2 + 7;
    for (size_t i = 0; i < particles.px.size(); ++i) particles.py[i] = particles.anchorY[i] + S(1);  // upright
    const S ax = particles.anchorX[tip], ay = particles.anchorY[tip], az = particles.anchorZ[tip];
    const auto cm = [](int v) { return S(v) / S(100); };
    // The tip 0.99 m out from its root at 0.6 m, 1 cm past the first sphere's centre; each next
    // sphere sits 1 cm short of where the last one leaves it.
    const auto along = [&](int centimetres) {
      return alongZ ? Vec3<S>(ax, ay + cm(60), az + cm(centimetres)) : Vec3<S>(ax + cm(centimetres), ay + cm(60), az);
    };
    const Vec3<S> start = along(99);
    particles.px[tip] = start.x();
    particles.py[tip] = start.y();
    particles.pz[tip] = start.z();
    std::vector<RigidBody<S>>& bodies = w->mutableBodies();
    for (size_t k = 0; k < bodies.size(); ++k) {
      bodies[k].position = along(98 + 49 * int(k));
      bodies[k].asleep = true;
    }
  }
  ASSERT_TRUE(cpu->step(TickInput{}).ok);
  ASSERT_TRUE(gpu->step(TickInput{}).ok);
  // The chain carried the tip through all four, to 2.95 m out and 0.6 m up before the rod took
  // it back: 0.980 m out on the rod (through three, 2.46 m out: 0.971 m).
  const ParticleArrays<S>& moved = cpu->particles();
  const size_t tip = moved.px.size() / 2 + 7;
  const S out = alongZ ? moved.pz[tip] - moved.anchorZ[tip] : moved.px[tip] - moved.anchorX[tip];
  EXPECT_GT(ScalarTraits<S>::toDouble(out), 0.975) << "the tip went through every sphere";
  EXPECT_EQ(hex(gpu->stateHash()), hex(cpu->stateHash())) << (alongZ ? "along z" : "along x");
}

TEST(GpuBodies, ChainedPushesAreTheCpus) {
  for (bool alongZ : {false, true}) {
    chainedPushesAreTheCpus<Fx32>(alongZ);
    chainedPushesAreTheCpus<Fx16>(alongZ);
  }
}

// The grass drag from the device's tuft counts, and a push that faults (a tuft 32 km down under a
// ball 800 m up: the difference overflows Q16.16 in the push's reach test): the push pass puts
// its candidates back, and the host pushes from that state and reports the reference's fault,
// with the reference's state.
TEST(GpuBodies, GrassDragAndAPushFaultAreTheCpus) {
  Scenario scenario = scenarioNamed("thesis-bodies", "fx16");
  scenario.field.patchesX = scenario.field.patchesZ = 20;
  scenario.script.clear();
  scenario.bodies.gravity = test::r3(0, 0, 0);
  scenario.bodies.grassDrag = Rational{1, 2};
  scenario.bodies.list = {test::sphere("rolling", Rational{3, 10}, test::r3(-1, 3, 0, 10)),
                          test::sphere("high", Rational{1, 2}, test::r3(1, 800, 0))};
  scenario.bodies.list[0].velocity = test::r3(1, 0, 0);
  auto cpu = test::makeTyped<Fx16>(scenario);
  auto gpu = test::makeTyped<Fx16>(scenario);
  ASSERT_EQ(gpu->setPhysicsPath(PhysicsPath::Gpu, &provider()), "");
  for (int64_t t = 0; t < 3; ++t) {
    ASSERT_TRUE(cpu->step(TickInput{}).ok);
    ASSERT_TRUE(gpu->step(TickInput{}).ok);
  }
  EXPECT_EQ(gpu->bodies()[0].velocity, cpu->bodies()[0].velocity);
  EXPECT_LT(cpu->bodies()[0].velocity.x(), Fx16(1)) << "the grass drags the rolling ball";
  for (World<Fx16>* w : {cpu.get(), gpu.get()}) {  // the tuft under the high ball
    ParticleArrays<Fx16>& p = w->mutableParticles();
    size_t under = 0;
    const auto away = [&](size_t i) { return abs(p.anchorX[i] - Fx16(1)) + abs(p.anchorZ[i]); };
    for (size_t i = 1; i < p.px.size(); ++i) under = away(i) < away(under) ? i : under;
    p.py[under] = Fx16(-32000);
  }
  ASSERT_EQ(hex(gpu->stateHash()), hex(cpu->stateHash()));
  const StepResult onCpu = cpu->step(TickInput{}), onGpu = gpu->step(TickInput{});
  ASSERT_FALSE(onCpu.ok);
  EXPECT_EQ(onCpu.error.stage, Stage::Response);
  EXPECT_EQ(onGpu.error.message(), onCpu.error.message());
  EXPECT_EQ(hex(gpu->stateHash()), hex(cpu->stateHash()));
}

RC_GTEST_PROP(GpuBodies, Fx32PushesAreTheCpus, ()) { bodyPushesAreTheCpus<Fx32>(); }
RC_GTEST_PROP(GpuBodies, Fx16PushesAreTheCpus, ()) { bodyPushesAreTheCpus<Fx16>(); }

}  // namespace
}  // namespace sg
