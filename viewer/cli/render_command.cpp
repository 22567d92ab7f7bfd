// `simgrass render`: run a scenario (or replay a `.sgr` recording) and write PNG frames of chosen
// ticks, rendered offscreen (OSMesa); optionally a contact sheet and a video (docs/rendering.md).
// Lives on the viewer side of the layers (it draws with viewer/); the `simgrass` executable links
// it when the viewer is built, through the hook declared in replay/cli/render_hook.h.
#include "replay/cli/render_hook.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "replay/cli/cli_common.h"
#include "replay/cli/option_checks.h"
#include "replay/format/sgr_format.h"
#include "replay/format/sgr_reader.h"
#include "replay/input_file.h"
#include "replay/physics_devices.h"
#include "replay/player.h"
#include "replay/progress.h"
#include "replay/scenario_files.h"
#include "sim/gpu/gl_physics.h"
#include "sim/scenario/json_bounds.h"
#include "viewer/offscreen/osmesa_context.h"
#include "viewer/render/scene.h"

namespace sg {
namespace {
namespace fs = std::filesystem;

struct RenderOptions {
  std::string input, output, ticks = "0", size = "800x600", camera, contactSheet, video, debug;
  std::string physics = "cpu";
  int msaa = 4;
  int threads = 1;
  bool json = false;
  bool ssao = false, alphaTest = false, noRock = false;
};

/// "particles,constraints,primitives,cells,contacts" (any subset, comma-separated).
bool parseDebugList(const std::string& list, viewer::DebugFlags* flags, std::string* bad) {
  *flags = {};
  if (list.empty()) return true;
  std::string item;
  std::istringstream in(list);
  bool any = false;
  while (std::getline(in, item, ',')) {
    any = true;
    if (item == "particles")
      flags->particles = true;
    else if (item == "constraints")
      flags->constraints = true;
    else if (item == "primitives")
      flags->primitives = true;
    else if (item == "cells")
      flags->cells = true;
    else if (item == "contacts")
      flags->contacts = true;
    else
      return *bad = item, false;
  }
  if (!any || list.back() == ',') return *bad = "", false;
  return true;
}

constexpr int64_t kMaxFrames = 1000000;
/// Samples one frame may take (width x height x max(1, msaa)): 8192x8192 without MSAA, 4096x4096
/// at 4x; at about 8 bytes a sample (colour + depth) that is 512 MiB of framebuffer at most.
constexpr int64_t kMaxFrameSamples = int64_t(1) << 26;
/// Frames a contact sheet may hold (each keeps a thumbnail of up to 320 px wide in memory).
constexpr int64_t kMaxContactSheetFrames = 256;

struct TickRange {
  int64_t first = 0, last = 0, step = 1;
};

bool parseInt(const std::string& s, int64_t* v) {
  if (s.empty() || s.size() > 15) return false;
  for (char c : s)
    if (c < '0' || c > '9') return false;
  *v = std::stoll(s);
  return true;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(s);
  while (std::getline(in, part, sep)) parts.push_back(part);
  if (!s.empty() && s.back() == sep) parts.push_back("");
  return parts;
}

/// "T", "A:B" or "A:B:STEP" with 0 <= A <= B, STEP >= 1, at most kMaxFrames frames.
std::optional<TickRange> parseTicks(const std::string& s) {
  const std::vector<std::string> p = split(s, ':');
  TickRange r;
  if (p.empty() || p.size() > 3 || !parseInt(p[0], &r.first)) return std::nullopt;
  r.last = r.first;
  if (p.size() >= 2 && !parseInt(p[1], &r.last)) return std::nullopt;
  if (p.size() == 3 && !parseInt(p[2], &r.step)) return std::nullopt;
  if (r.last < r.first || r.step < 1) return std::nullopt;
  if ((r.last - r.first) / r.step >= kMaxFrames) return std::nullopt;
  return r;
}

/// "WxH", both 16..8192.
bool parseSize(const std::string& s, int* w, int* h) {
  const std::vector<std::string> p = split(s, 'x');
  int64_t a = 0, b = 0;
  if (p.size() != 2 || !parseInt(p[0], &a) || !parseInt(p[1], &b)) return false;
  if (a < 16 || b < 16 || a > 8192 || b > 8192) return false;
  *w = int(a);
  *h = int(b);
  return true;
}

/// "x,y,z,yaw,pitch" (m, degrees).
std::optional<viewer::Camera> parseCamera(const std::string& s) {
  const std::vector<std::string> p = split(s, ',');
  if (p.size() != 5) return std::nullopt;
  float v[5];
  for (size_t i = 0; i < 5; ++i) {
    char* end = nullptr;
    const double d = std::strtod(p[i].c_str(), &end);
    const bool whole = !p[i].empty() && end == p[i].c_str() + p[i].size();
    if (!whole || !std::isfinite(d) || std::fabs(d) > 1e6) return std::nullopt;
    v[i] = float(d);
  }
  if (std::fabs(v[4]) > 90) return std::nullopt;
  viewer::Camera c;
  c.x = v[0];
  c.y = v[1];
  c.z = v[2];
  c.yawDegrees = v[3];
  c.pitchDegrees = v[4];
  return c;
}

double rawToMetres(int64_t raw) { return double(raw) / 4294967296.0; }

/// The camera of the input track at the frame: at the input camera, looking where the track goes
/// (or at the simulated grass when it stands still), 12 degrees down.
viewer::Camera trackCamera(const TickInput& now, const TickInput& ahead, const viewer::Scene& scene,
                           const SimWorld& world) {
  viewer::Camera c;
  c.x = float(rawToMetres(now.camera.x));
  c.y = float(rawToMetres(now.camera.y));
  c.z = float(rawToMetres(now.camera.z));
  c.y = std::max(c.y, viewer::groundHeight(world, c.x, c.z) + 0.3f);
  float dx = float(rawToMetres(ahead.camera.x)) - c.x, dz = float(rawToMetres(ahead.camera.z)) - c.z;
  if (!ahead.hasCamera || dx * dx + dz * dz < 1e-4f) {
    dx = 0.5f * (scene.focusMinX + scene.focusMaxX) - c.x;
    dz = 0.5f * (scene.focusMinZ + scene.focusMaxZ) - c.z;
  }
  if (dx * dx + dz * dz > 1e-8f) c.yawDegrees = std::atan2(dx, dz) / viewer::Camera::kRadians;
  c.pitchDegrees = -12;
  return c;
}

/// Box-filtered downscale.
viewer::Image shrink(const viewer::Image& src, int w, int h) {
  viewer::Image out;
  out.width = w;
  out.height = h;
  out.rgba.assign(size_t(w) * size_t(h) * 4, 0);
  for (int y = 0; y < h; ++y) {
    const int y0 = y * src.height / h, y1 = std::max(y0 + 1, (y + 1) * src.height / h);
    for (int x = 0; x < w; ++x) {
      const int x0 = x * src.width / w, x1 = std::max(x0 + 1, (x + 1) * src.width / w);
      uint32_t sum[4] = {0, 0, 0, 0};
      for (int sy = y0; sy < y1; ++sy)
        for (int sx = x0; sx < x1; ++sx)
          for (int c = 0; c < 4; ++c) sum[c] += src.at(sx, sy)[c];
      const uint32_t n = uint32_t((y1 - y0) * (x1 - x0));
      for (int c = 0; c < 4; ++c) out.at(x, y)[c] = uint8_t((sum[c] + n / 2) / n);
    }
  }
  return out;
}

/// A 3x5 pixel font for the tick labels of the contact sheet (digits only).
void drawNumber(viewer::Image& img, int x, int y, int64_t value, int scale) {
  static const uint16_t kDigits[10] = {0x7B6F, 0x2C97, 0x73E7, 0x73CF, 0x5BC9, 0x79CF, 0x79EF, 0x7249, 0x7BEF, 0x7BCF};
  const std::string text = std::to_string(value);
  // Dark backing box, then white digits.
  const int boxW = int(text.size()) * 4 * scale + scale, boxH = 7 * scale;
  for (int yy = y; yy < std::min(img.height, y + boxH); ++yy)
    for (int xx = x; xx < std::min(img.width, x + boxW); ++xx)
      for (int c = 0; c < 3; ++c) img.at(xx, yy)[c] = uint8_t(img.at(xx, yy)[c] / 3);
  for (size_t k = 0; k < text.size(); ++k) {
    const uint16_t bits = kDigits[text[k] - '0'];
    for (int row = 0; row < 5; ++row)
      for (int col = 0; col < 3; ++col) {
        if (!((bits >> (14 - (row * 3 + col))) & 1)) continue;
        for (int sy = 0; sy < scale; ++sy)
          for (int sx = 0; sx < scale; ++sx) {
            const int px = x + scale + int(k) * 4 * scale + col * scale + sx, py = y + scale + row * scale + sy;
            if (px < img.width && py < img.height)
              for (int c = 0; c < 3; ++c) img.at(px, py)[c] = 255;
          }
      }
  }
}

viewer::Image contactSheet(const std::vector<viewer::Image>& thumbs, const std::vector<int64_t>& ticks) {
  constexpr int kGap = 4;
  const int columns = int(std::min<size_t>(thumbs.size(), 4));
  const int rows = int((thumbs.size() + size_t(columns) - 1) / size_t(columns));
  const int tw = thumbs[0].width, th = thumbs[0].height;
  viewer::Image sheet;
  sheet.width = columns * tw + (columns + 1) * kGap;
  sheet.height = rows * th + (rows + 1) * kGap;
  sheet.rgba.assign(size_t(sheet.width) * size_t(sheet.height) * 4, 0);
  for (size_t i = 0; i < sheet.rgba.size(); i += 4) {
    sheet.rgba[i] = sheet.rgba[i + 1] = sheet.rgba[i + 2] = 40;
    sheet.rgba[i + 3] = 255;
  }
  for (size_t k = 0; k < thumbs.size(); ++k) {
    const int ox = kGap + int(k % size_t(columns)) * (tw + kGap), oy = kGap + int(k / size_t(columns)) * (th + kGap);
    for (int y = 0; y < th; ++y) std::copy_n(thumbs[k].at(0, y), size_t(tw) * 4, sheet.at(ox, oy + y));
    drawNumber(sheet, ox + 3, oy + 3, ticks[k], 2);
  }
  return sheet;
}

std::string findOnPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (!path) return {};
  for (const std::string& dir : split(path, ':')) {
    if (dir.empty()) continue;
    const fs::path p = fs::path(dir) / program;
    if (access(p.c_str(), X_OK) == 0) return p.string();
  }
  return {};
}

std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// An argument quoted in a message: control characters escaped, at most 60 characters.
std::string shown(const std::string& s) { return echoText(s); }

int fail(int code, const std::string& message) {
  printError("simgrass render: %s", message.c_str());
  return code;
}

int render(const RenderOptions& o) {
  // ---- arguments ----
  const std::optional<TickRange> range = parseTicks(o.ticks);
  if (!range)
    return fail(kExitBadInput, "--ticks: expected T, A:B or A:B:STEP with 0 <= A <= B, STEP >= 1 and at most " +
                                   std::to_string(kMaxFrames) + " frames, got '" + shown(o.ticks) + "'");
  int width = 0, height = 0;
  if (!parseSize(o.size, &width, &height))
    return fail(kExitBadInput, "--size: expected WxH with both from 16 to 8192, got '" + shown(o.size) + "'");
  std::optional<viewer::Camera> fixedCamera, framed;  // --camera; the default view, framed once
  if (!o.camera.empty()) {
    fixedCamera = parseCamera(o.camera);
    if (!fixedCamera)
      return fail(kExitBadInput,
                  "--camera: expected x,y,z,yaw,pitch (m, degrees; |pitch| <= 90), got '" + shown(o.camera) + "'");
  }
  if (o.msaa != 0 && o.msaa != 2 && o.msaa != 4 && o.msaa != 8)
    return fail(kExitBadInput, "--msaa: expected 0, 2, 4 or 8, got " + std::to_string(o.msaa));
  const int64_t samples = int64_t(width) * int64_t(height) * std::max(1, o.msaa);
  if (samples > kMaxFrameSamples)
    return fail(kExitBadInput, "--size, --msaa: expected at most " + std::to_string(kMaxFrameSamples) +
                                   " samples a frame (width x height x msaa), got " + std::to_string(samples) + " (" +
                                   shown(o.size) + ", msaa " + std::to_string(o.msaa) + ")");
  const int64_t frameCount = (range->last - range->first) / range->step + 1;
  if (!o.contactSheet.empty() && frameCount > kMaxContactSheetFrames)
    return fail(kExitBadInput, "--contact-sheet: expected at most " + std::to_string(kMaxContactSheetFrames) +
                                   " frames on a sheet, got " + std::to_string(frameCount) + " (--ticks " +
                                   shown(o.ticks) + ")");
  // No output may replace an input of this command (a frame, the sheet or the video named as
  // the scenario or recording being rendered).
  for (const std::string* out : {&o.contactSheet, &o.video})
    if (!out->empty() && sameFile(*out, o.input))
      return fail(kExitBadInput, *out + ": expected an output file other than the input " + o.input);
  const std::optional<PhysicsPath> physics = parsePhysicsPath(o.physics);
  if (!physics)
    return fail(kExitBadInput, "--physics: expected cpu, gpu or gpu-readback, got '" + shown(o.physics) + "'");
  viewer::DebugFlags debug;
  std::string badItem;
  if (!parseDebugList(o.debug, &debug, &badItem))
    return fail(kExitBadInput,
                "--debug: expected a comma list of particles, constraints, primitives, cells, contacts, got '" +
                    shown(o.debug) + "'" +
                    (badItem.empty() || badItem == o.debug ? "" : " ('" + shown(badItem) + "' is none of them)"));

  // ---- the world ----
  Scenario scenario;
  std::unique_ptr<SimWorld> ownWorld;
  std::unique_ptr<sgr::Recording> recording;
  std::unique_ptr<Player> player;
  std::vector<sgr::EmbeddedFile> scenarioFiles;  // what a scenario input read beside itself (heightmap)
  try {
    if (sgr::hasRecordingMagic(o.input)) {
      recording = std::make_unique<sgr::Recording>(sgr::readRecording(o.input));
      player = std::make_unique<Player>(*recording, o.threads);
      scenario = player->scenario();
      if (range->last > recording->lastTick())
        return fail(kExitBadInput, "--ticks: the recording " + o.input + " ends at tick " +
                                       std::to_string(recording->lastTick()) + ", got " + o.ticks);
      // As replay, compare and diff say it (exit 3 below): a cut recording rendered silently.
      if (recording->truncated)
        printError(
            "simgrass render: warning: %s: byte %" PRIu64 ": expected %s; rendering the %" PRId64 " ticks before it",
            o.input.c_str(), recording->truncatedAt, recording->truncatedExpected.c_str(), recording->lastTick());
    } else {
      scenario = loadScenarioFile(o.input, &scenarioFiles);
      ownWorld = makeWorld(scenario, o.threads, physicalMemoryBytes());
    }
  } catch (const sgr::RecordingError& e) {
    return fail(kExitBadInput, e.what());
  } catch (const ScenarioError& e) {
    return fail(kExitBadInput, e.what());
  }
  SimWorld& world = player ? player->world() : *ownWorld;
  auto inputAt = [&](int64_t tick) { return recording ? recording->inputAt(tick) : scriptedInput(scenario, tick); };

  // ---- outputs against inputs and each other, before anything is written ----
  // Inputs: the scenario or recording, the heightmap a scenario read, the meshes its bodies name
  // (relative to the input's folder; a recording's heightmap is inside it). `-o r5` once wrote
  // frame-000003.png over the scenario's heightmap r5/frame-000003.png.
  const std::string inputFolder = fs::path(o.input).parent_path().string();
  std::vector<std::string> inputs = filesNamedBy(scenario, scenarioFiles, inputFolder);
  inputs.push_back(o.input);
  auto isRenderedFrame = [&](const fs::path& file) {  // one of this run's frame-TTTTTT.png in -o
    const std::string name = file.filename().string();
    if (name.size() < 16 || name.rfind("frame-", 0) != 0 || name.substr(name.size() - 4) != ".png") return false;
    const std::string digits = name.substr(6, name.size() - 10);
    if (digits.size() > 18 || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
      return false;
    const int64_t tick = std::stoll(digits);
    char canonical[32];
    std::snprintf(canonical, sizeof canonical, "frame-%06" PRId64 ".png", tick);
    if (name != canonical || tick < range->first || tick > range->last || (tick - range->first) % range->step != 0)
      return false;
    auto folderOf = [](const fs::path& p) {  // symbolic links resolved, "." and ".." gone, no trailing '/'
      std::error_code ec;
      fs::path f = fs::weakly_canonical(fs::absolute(p, ec), ec);
      if (ec) f = fs::absolute(p, ec).lexically_normal();
      return f.has_filename() ? f : f.parent_path();
    };
    return folderOf(file.parent_path()) == folderOf(o.output);
  };
  {
    std::error_code listed;
    for (const fs::directory_entry& entry : fs::directory_iterator(o.output, listed)) {
      if (!isRenderedFrame(entry.path())) continue;
      if (overwritesInput("render", "-o", entry.path().string(), inputs)) return kExitBadInput;
    }
  }
  for (const auto& [option, file] : {std::pair<const char*, const std::string*>{"--contact-sheet", &o.contactSheet},
                                     std::pair<const char*, const std::string*>{"--video", &o.video}}) {
    if (file->empty()) continue;
    if (overwritesInput("render", option, *file, inputs)) return kExitBadInput;
    if (isRenderedFrame(*file))
      return fail(kExitBadInput, std::string(option) + " " + *file + ": expected a file other than a frame of -o");
  }
  if (sameOutputTwice("render", "--contact-sheet", o.contactSheet, "--video", o.video)) return kExitBadInput;

  std::error_code ec;
  fs::create_directories(o.output, ec);
  if (ec || !fs::is_directory(o.output)) return fail(kExitBadInput, o.output + ": cannot create the output folder");

  std::string error;
  std::unique_ptr<viewer::OffscreenRenderer> renderer =
      viewer::OffscreenRenderer::create(width, height, o.msaa, &error);
  if (!renderer) return fail(kExitMismatch, error);
  if (*physics != PhysicsPath::Cpu) {
    // The device in the renderer's own context, so the frames draw the tufts' tops straight from
    // its buffers (docs/gpu-physics.md): nothing is copied back to draw a frame.
    registerGpuPhysics(&gpu::makeCurrentContextPhysicsProvider);
    if (const std::string why = applyPhysicsPath(world, *physics); !why.empty())
      return fail(kExitBadInput, "--physics " + o.physics + ": " + why);
  }
  renderer->options().ssao = o.ssao;
  renderer->options().alphaToCoverage = !o.alphaTest;
  renderer->options().rockBlend = !o.noRock;
  renderer->options().debug = debug;
  // Scenario meshes are named relative to the scenario file (a recording carries its scenario
  // text, not its folder: relative meshes resolve against the recording's folder).
  renderer->renderer().setAssetDirectory(fs::path(o.input).parent_path().string());

  // ---- frames ----
  std::vector<int64_t> ticks;
  for (int64_t t = range->first; t <= range->last; t += range->step) ticks.push_back(t);
  ProgressBar progress("render", int64_t(ticks.size()), !o.json);
  std::vector<double> simMsPerTick, extractMs, renderMs, writeMs;
  std::vector<viewer::Image> thumbs;
  std::vector<std::string> files;
  const int thumbW = std::min(width, 320), thumbH = std::max(1, height * thumbW / width);
  using Clock = std::chrono::steady_clock;
  auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  try {
    if (player && range->first > 0) {
      const StepResult r = player->seek(range->first);
      if (!r.ok) return fail(kExitMismatch, r.error.message());
    }
    for (size_t k = 0; k < ticks.size(); ++k) {
      const int64_t tick = ticks[k];
      const auto t0 = Clock::now();
      const int64_t steps = tick - world.tick();
      while (world.tick() < tick) {
        const StepResult r = player ? player->stepForward() : world.step(inputAt(world.tick()));
        if (!r.ok) return fail(kExitMismatch, r.error.message());
      }
      const auto t1 = Clock::now();
      if (steps > 0) simMsPerTick.push_back(ms(t0, t1) / double(steps));

      viewer::Scene& scene = renderer->scene();
      viewer::extractScene(world, scenario, &scene);
      viewer::extractDebug(world, scenario, debug, &scene);
      const auto t2 = Clock::now();
      extractMs.push_back(ms(t1, t2));
      viewer::Camera camera;
      // The camera input that moved the level-of-detail window to this state (the previous step's).
      const TickInput input = inputAt(std::max<int64_t>(tick - 1, 0));
      if (fixedCamera)
        camera = *fixedCamera;
      else if (input.hasCamera)
        camera = trackCamera(input, inputAt(tick + 30), scene, world);
      else {
        // Framed once, at the first frame rendered: the frames of a sheet share one view.
        if (!framed) framed = viewer::defaultCamera(scene, world, float(width) / float(height));
        camera = *framed;
      }
      double frameMs = 0;
      const viewer::Image image = renderer->render(scene, camera, &frameMs);
      renderMs.push_back(frameMs);
      // A mesh that does not load is bad input: the frames would silently show the wrong looks
      // (the interactive viewer draws the primitives and says so in its window instead).
      if (!renderer->renderer().lastAssetError().empty())
        return fail(kExitBadInput, renderer->renderer().lastAssetError());

      char name[32];
      std::snprintf(name, sizeof name, "frame-%06" PRId64 ".png", tick);
      const std::string file = (fs::path(o.output) / name).string();
      if (overwritesInput("render", "-o", file, inputs)) return kExitBadInput;
      const auto t3 = Clock::now();
      if (!viewer::writePng(file, image, &error)) return fail(kExitBadInput, error);
      writeMs.push_back(ms(t3, Clock::now()));
      files.push_back(file);
      if (!o.contactSheet.empty()) thumbs.push_back(shrink(image, thumbW, thumbH));
      progress.update(int64_t(k + 1));
    }
  } catch (const sgr::RecordingError& e) {
    return fail(kExitBadInput, e.what());
  }
  progress.finish();

  if (!o.contactSheet.empty() && !thumbs.empty()) {
    if (!viewer::writePng(o.contactSheet, contactSheet(thumbs, ticks), &error)) return fail(kExitBadInput, error);
  }

  // ---- video (optional; needs ffmpeg) ----
  std::string videoNote;
  int code = kExitOk;
  if (!o.video.empty()) {
    const std::string ffmpeg = findOnPath("ffmpeg");
    if (ffmpeg.empty()) {
      videoNote = "ffmpeg is not on PATH: --video skipped";
      std::fprintf(stderr, "simgrass render: note: %s\n", videoNote.c_str());
    } else {
      const double fps = 1.0 / (scenario.timeStep.toDouble() * double(range->step));
      const std::string cmd = shellQuote(ffmpeg) + " -y -loglevel error -framerate " + std::to_string(fps) +
                              " -pattern_type glob -i " + shellQuote((fs::path(o.output) / "frame-*.png").string()) +
                              " -c:v libx264 -pix_fmt yuv420p " + shellQuote(o.video) + " </dev/null";
      if (std::system(cmd.c_str()) != 0) {
        videoNote = "ffmpeg failed: " + o.video + " not written";
        std::fprintf(stderr, "simgrass render: %s\n", videoNote.c_str());
        code = kExitMismatch;
      } else {
        videoNote = "written";
      }
    }
  }

  const std::string gl = renderer->context().describe();
  if (o.json) {
    nlohmann::json j;
    j["input"] = o.input;
    j["scenario"] = scenario.name;
    j["output"] = o.output;
    j["frames"] = files.size();
    j["ticks"] = ticks;
    j["width"] = width;
    j["height"] = height;
    j["msaa"] = renderer->samples();
    j["alphaToCoverage"] = renderer->samples() > 0 && !o.alphaTest;
    j["ssao"] = o.ssao;
    j["rockBlend"] = !o.noRock;
    j["debug"] = o.debug;
    j["renderer"] = gl;
    j["physics"] = describePhysics(world);
    j["deviceBytesToHost"] = world.deviceTraffic().toHost;
    j["deviceBytesToDevice"] = world.deviceTraffic().toDevice;
    j["tufts"] = renderer->scene().tufts.size();
    j["medianSimulationMsPerTick"] = median(simMsPerTick);
    j["medianExtractMs"] = median(extractMs);
    j["medianRenderMs"] = median(renderMs);
    j["medianPngMs"] = median(writeMs);
    if (!o.contactSheet.empty()) j["contactSheet"] = o.contactSheet;
    if (!o.video.empty()) j["video"] = videoNote;
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("rendered   %zu frame%s of %s, %dx%d, msaa %d, to %s\n", files.size(), files.size() == 1 ? "" : "s",
                scenario.name.c_str(), width, height, renderer->samples(), o.output.c_str());
    std::printf("renderer   %s\n", gl.c_str());
    if (*physics != PhysicsPath::Cpu)
      std::printf("physics    %s; %" PRId64 " bytes copied back\n", describePhysics(world).c_str(),
                  world.deviceTraffic().toHost);
    std::printf("time       median %.1f ms/frame rendering (%zu tufts), %.1f ms extracting, %.3f ms/tick simulating\n",
                median(renderMs), renderer->scene().tufts.size(), median(extractMs), median(simMsPerTick));
    if (!o.contactSheet.empty()) std::printf("sheet      %s\n", o.contactSheet.c_str());
  }
  if (code == kExitOk && recording && recording->truncated) code = kExitTruncated;
  return code;
}
}  // namespace

void addRenderCommand(CLI::App& app, int* exitCode) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* cmd =
      app.add_subcommand("render", "Render frames of a scenario run or a .sgr replay to PNG (offscreen, OSMesa)");
  cmd->add_option("input", o->input, "Scenario JSON (run from tick 0 with its script) or recording (.sgr, replayed)")
      ->required();
  cmd->add_option("-o,--output", o->output, "Folder for frame-TTTTTT.png")->required();
  cmd->add_option("--ticks", o->ticks, "Ticks to render: T, A:B or A:B:STEP (default 0)");
  cmd->add_option("--size", o->size, "Frame size WxH (default 800x600)");
  cmd->add_option("--camera", o->camera,
                  "x,y,z,yaw,pitch: a fixed camera (m, degrees; yaw 0 looks along +z, 90 along +x). Default: the "
                  "input's camera track if any, else a view framing the bodies at the first frame rendered (25 degrees "
                  "above, from -z), else 1.7 m above the ground at the -z edge of the simulated grass, looking at its "
                  "centre")
      ->check(nonEmptyValue("x,y,z,yaw,pitch", "X,Y,Z,YAW,PITCH"));
  cmd->add_option("--msaa", o->msaa, "Samples per pixel: 0 (alpha test) or 2/4/8 (alpha to coverage; default 4)");
  cmd->add_flag("--ssao", o->ssao,
                "Screen-space ambient occlusion (depth prepass where the tufts' alpha passes, half resolution)");
  cmd->add_flag("--alpha-test", o->alphaTest, "Alpha-test the tufts even with MSAA (no alpha to coverage)");
  cmd->add_option("--debug", o->debug,
                  "Debug overlay, a comma list of: particles, constraints (root-particle rods), primitives (body "
                  "collision shapes), cells (body-particle broad-phase cells), contacts (points + normals)");
  cmd->add_flag("--no-rock", o->noRock, "No rock texture on steep terrain (grass texture everywhere)");
  cmd->add_option("--contact-sheet", o->contactSheet, "Also write a grid of thumbnails of every frame (PNG)");
  cmd->add_option("--video", o->video,
                  "Also encode the frames with ffmpeg (skipped with a note when ffmpeg is missing)");
  cmd->add_option("--threads", o->threads, "Simulation worker threads")->check(CLI::Range(1, 256));
  cmd->add_option("--physics", o->physics,
                  "Where the grass stages run: cpu, gpu (in the renderer's context: the frames draw the tops "
                  "from the device, nothing copied back) or gpu-readback (docs/gpu-physics.md)");
  cmd->add_flag("--json", o->json, "Machine-readable output");
  cmd->footer(
      "Exit codes: 0 ok, 1 simulation fault or no OpenGL context, 2 bad input, 3 recording cut off before END "
      "(rendered up to the cut).");
  cmd->callback([o, exitCode] { *exitCode = render(*o); });
}
}  // namespace sg
