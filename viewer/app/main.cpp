// simgrass-viewer: the interactive host (docs/viewer.md). A GLFW window (OpenGL 3.3 core, GLEW),
// the shared Renderer (viewer/render/) drawing the world every frame, Dear ImGui panels, a
// first-person camera whose position goes into every tick's input (the level-of-detail window
// follows it), thesis body controls and recording to `.sgr`.
//
// The simulation never reads a clock: the frame loop decides how many ticks to run (a fixed-step
// accumulator at the scenario's dt, or exactly one per frame with --script) and hands each one a
// TickInput, which is all a recording needs to reproduce the session.
#include <GL/glew.h>
// GLEW's header first; GLFW must not pull in another GL header.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <dlfcn.h>
#include <link.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "replay/recorder.h"
#include "replay/scenario_files.h"
#include "replay/stage_clock.h"
#include "sim/world/world.h"
#include "viewer/app/script.h"
#include "viewer/render/renderer.h"
#include "viewer/render/scene.h"

// Sanitizer builds: the GL driver (Mesa's GLX and llvmpipe, LLVM) and libX11 keep allocations
// to the end of the process; LeakSanitizer would report them as ours. (This executable never
// links the offscreen library, whose hooks are for OSMesa: each executable defines its own.)
#if defined(__SANITIZE_ADDRESS__)
#define SIMGRASS_VIEWER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SIMGRASS_VIEWER_ASAN 1
#endif
#endif
#ifdef SIMGRASS_VIEWER_ASAN
extern "C" __attribute__((visibility("default"), used)) const char* __lsan_default_suppressions() {
  return "leak:libGLX_mesa.so\nleak:libGLX.so\nleak:swrast_dri.so\nleak:libgallium\nleak:libLLVM\n"
         "leak:libglapi.so\nleak:libX11.so\nleak:libxcb\nleak:libglfw.so\nleak:libdbus\n";
}
extern "C" __attribute__((visibility("default"), used)) const char* __lsan_default_options() {
  return "print_suppressions=0";
}
#endif

namespace {
/// Sanitizer builds: keeps every library loaded so far (the GL driver included) mapped until the
/// process ends. GLVND unloads the driver at glfwTerminate, and a leak whose stack lies in an
/// unloaded library has "<unknown module>" frames that no suppression can name.
void pinLoadedLibraries() {
#ifdef SIMGRASS_VIEWER_ASAN
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void*) {
        if (info->dlpi_name && info->dlpi_name[0]) dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
        return 0;
      },
      nullptr);
#endif
}
}  // namespace

namespace sg::viewer {
namespace {

constexpr int kExitOk = 0, kExitFailure = 1, kExitBadInput = 2;

int64_t toRaw(double metres) { return std::llround(metres * 4294967296.0); }

std::string hex(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
  return buf;
}

struct Options {
  std::string scenario, script, record, size = "1280x720";
  int64_t frames = -1;
  int threads = 1;
  int msaa = 4;
  bool noScenarioInput = false;
};

/// Controls (docs/viewer.md).
struct Tuning {
  float walkSpeed = 4.0f;        ///< m/s (x4 with shift)
  float lookDegreesPerPixel = 0.15f;
  float bodyAcceleration = 8.0f; ///< m/s^2 while a drive key is held (velocity mode)
  float bodySpeed = 2.0f;        ///< m/s while a drive key is held (position mode)
  float minEyeHeight = 0.3f;     ///< m above the terrain
};

/// The simulated session: the world, every tick's input since tick 0, the recorder.
class Session {
 public:
  Scenario scenario;
  std::vector<sgr::EmbeddedFile> files;
  std::unique_ptr<SimWorld> world;
  std::vector<TickInput> history;  ///< history[t]: the input of tick t
  std::unique_ptr<Recorder> recorder;
  std::string recordPath;
  int threads = 1;
  StageClock clock;

  StepResult step(const TickInput& input) {
    history.push_back(input);
    return recorder ? recorder->step(input, &clock) : world->step(input, &clock);
  }

  /// Records the whole session, from tick 0, to `path`: a fresh world replays the inputs so far
  /// under a Recorder (a recording must start from a state a replay can build), must reach the
  /// live world's hash, and then takes its place.
  bool startRecording(const std::string& path, std::string* error) {
    if (recorder) {
      *error = "already recording to " + recordPath;
      return false;
    }
    try {
      std::unique_ptr<SimWorld> fresh = makeWorld(scenario, threads, physicalMemoryBytes());
      RecordSettings settings;
      settings.checkEvery = defaultCheckEvery(fresh->counts().patches());
      auto rec = std::make_unique<Recorder>(path, scenario, files, *fresh, settings);
      for (const TickInput& in : history) {
        const StepResult r = rec->step(in);
        if (!r.ok) {
          *error = "catching up the recording faulted: " + r.error.message();
          return false;
        }
      }
      if (fresh->stateHash() != world->stateHash()) {
        *error = "catching up the recording reached hash " + hex(fresh->stateHash()) + ", the live world has " +
                 hex(world->stateHash());
        return false;
      }
      world = std::move(fresh);
      recorder = std::move(rec);
      recordPath = path;
      return true;
    } catch (const std::exception& e) {
      *error = path + ": " + e.what();
      return false;
    }
  }

  bool stopRecording(std::string* error) {
    if (!recorder) {
      *error = "not recording";
      return false;
    }
    try {
      recorder->finish();
    } catch (const std::exception& e) {
      *error = recordPath + ": " + e.what();
      recorder.reset();
      return false;
    }
    std::printf("recorded   %" PRId64 " ticks to %s (hash %s)\n", world->tick(), recordPath.c_str(),
                hex(world->stateHash()).c_str());
    std::fflush(stdout);
    recorder.reset();
    return true;
  }
};

class App {
 public:
  App(Options o, Session* s) : opt_(std::move(o)), s_(*s) {}
  int run(const std::vector<ScriptCommand>* script);

 private:
  bool open(int width, int height, std::string* error);
  void close();
  bool key(int k) const;
  bool pressed(int k);  ///< went down since the last frame
  void updateCamera(float dt);
  TickInput tickInput() const;
  void renderScene(int fbw, int fbh);
  void drawPanels();
  bool screenshot(const std::string& path, std::string* error);
  int fail(int code, const std::string& message) {
    std::fprintf(stderr, "simgrass-viewer: %s\n", message.c_str());
    return code;
  }

  Options opt_;
  Session& s_;
  Tuning tune_;
  GLFWwindow* window_ = nullptr;
  bool imgui_ = false;
  std::unique_ptr<Renderer> renderer_;
  std::unique_ptr<Scene> scene_;
  Camera camera_;
  float eyeHeight_ = 1.7f;
  bool scripted_ = false;
  std::array<bool, GLFW_KEY_LAST + 1> scriptKeys_{};
  std::array<bool, GLFW_KEY_LAST + 1> wasDown_{};
  int selected_ = 0;
  bool positionMode_ = false;
  int samples_ = 0;
  double lastCursorX_ = 0, lastCursorY_ = 0;
  bool looking_ = false;
  // Stats.
  double renderMs_ = 0, frameMs_ = 0;
  std::array<double, size_t(Stage::Count)> stageMs_{};
  double simMsPerTick_ = 0;
  int64_t clockTicks_ = 0;
  std::string status_;
};

bool App::open(int width, int height, std::string* error) {
  if (!glfwInit()) {
    const char* desc = nullptr;
    glfwGetError(&desc);
    *error = std::string("cannot open a window (glfwInit failed: ") + (desc ? desc : "no display?") + ")";
    return false;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, opt_.msaa);
  window_ = glfwCreateWindow(width, height, ("SimGrass - " + s_.scenario.name).c_str(), nullptr, nullptr);
  if (!window_) {
    const char* desc = nullptr;
    glfwGetError(&desc);
    *error = std::string("cannot create an OpenGL 3.3 core window: ") + (desc ? desc : "unknown GLFW error");
    return false;
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(scripted_ ? 0 : 1);
  glewExperimental = GL_TRUE;
  const GLenum glew = glewInit();
  if (glew != GLEW_OK) {
    *error = std::string("glewInit failed: ") + reinterpret_cast<const char*>(glewGetErrorString(glew));
    return false;
  }
  while (glGetError() != GL_NO_ERROR) {
  }
  glGetIntegerv(GL_SAMPLES, &samples_);
  pinLoadedLibraries();
  try {
    renderer_ = std::make_unique<Renderer>();
  } catch (const std::exception& e) {
    *error = e.what();
    return false;
  }
  scene_ = std::make_unique<Scene>();
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini next to the user's files
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window_, true);
  ImGui_ImplOpenGL3_Init("#version 330");
  imgui_ = true;
  return true;
}

void App::close() {
  if (imgui_) {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    imgui_ = false;
  }
  scene_.reset();
  renderer_.reset();  // GL objects go while the context is current
  if (window_) glfwDestroyWindow(window_);
  window_ = nullptr;
  glfwTerminate();
}

bool App::key(int k) const {
  if (scripted_) return scriptKeys_[size_t(k)];
  if (imgui_ && ImGui::GetIO().WantCaptureKeyboard) return false;
  return glfwGetKey(window_, k) == GLFW_PRESS;
}

bool App::pressed(int k) {
  const bool down = key(k);
  const bool edge = down && !wasDown_[size_t(k)];
  wasDown_[size_t(k)] = down;
  return edge;
}

void App::updateCamera(float dt) {
  // Mouse look while the right button is held (interactive only).
  if (!scripted_) {
    double cx = 0, cy = 0;
    glfwGetCursorPos(window_, &cx, &cy);
    const bool held = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS &&
                      !(ImGui::GetIO().WantCaptureMouse && !looking_);
    if (held && looking_) {
      camera_.yawDegrees -= float(cx - lastCursorX_) * tune_.lookDegreesPerPixel;
      camera_.pitchDegrees = std::clamp(camera_.pitchDegrees - float(cy - lastCursorY_) * tune_.lookDegreesPerPixel,
                                        -89.0f, 89.0f);
    }
    looking_ = held;
    lastCursorX_ = cx;
    lastCursorY_ = cy;
  }
  const float yaw = camera_.yawDegrees * Camera::kRadians;
  const float fx = std::sin(yaw), fz = std::cos(yaw);    // forward on the ground
  const float rx = -std::cos(yaw), rz = std::sin(yaw);   // right on the ground
  const float f = float(key(GLFW_KEY_W)) - float(key(GLFW_KEY_S));
  const float r = float(key(GLFW_KEY_D)) - float(key(GLFW_KEY_A));
  const float up = float(key(GLFW_KEY_E)) - float(key(GLFW_KEY_Q));
  const float speed = tune_.walkSpeed * (key(GLFW_KEY_LEFT_SHIFT) ? 4.0f : 1.0f);
  camera_.x += (f * fx + r * rx) * speed * dt;
  camera_.z += (f * fz + r * rz) * speed * dt;
  eyeHeight_ = std::max(tune_.minEyeHeight, eyeHeight_ + up * speed * dt);
  camera_.y = groundHeight(*s_.world, camera_.x, camera_.z) + eyeHeight_;
}

TickInput App::tickInput() const {
  TickInput in;
  in.hasCamera = true;
  in.camera = {toRaw(camera_.x), toRaw(camera_.y), toRaw(camera_.z)};
  // The scenario's own scripted commands still play (the thesis scene kicks the football); the
  // user's drive command comes after them. Its camera track is replaced by the user's camera.
  if (!opt_.noScenarioInput) in.bodies = scriptedInput(s_.scenario, s_.world->tick()).bodies;
  const int64_t bodies = s_.world->counts().bodies;
  if (selected_ < 0 || selected_ >= bodies) return in;
  const float yaw = camera_.yawDegrees * Camera::kRadians;
  const float fx = std::sin(yaw), fz = std::cos(yaw), rx = -std::cos(yaw), rz = std::sin(yaw);
  const float f = float(key(GLFW_KEY_T)) - float(key(GLFW_KEY_G));
  const float r = float(key(GLFW_KEY_H)) - float(key(GLFW_KEY_F));
  const float u = float(key(GLFW_KEY_U)) - float(key(GLFW_KEY_J));
  if (f == 0 && r == 0 && u == 0) return in;
  const double dt = s_.scenario.timeStep.toDouble();
  const double scale = positionMode_ ? tune_.bodySpeed * dt : tune_.bodyAcceleration * dt;
  BodyCommand c;
  c.body = selected_;
  c.kind = positionMode_ ? BodyCommandKind::Displace : BodyCommandKind::AddVelocity;
  c.value = {toRaw((f * fx + r * rx) * scale), toRaw(u * scale), toRaw((f * fz + r * rz) * scale)};
  in.bodies.push_back(c);
  return in;
}

void App::renderScene(int fbw, int fbh) {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, fbw, fbh);
  renderer_->draw(*scene_, camera_, fbw, fbh, samples_ > 0);
}

bool App::screenshot(const std::string& path, std::string* error) {
  int fbw = 0, fbh = 0;
  glfwGetFramebufferSize(window_, &fbw, &fbh);
  renderScene(fbw, fbh);
  // The panels of the last frame (ImGui's draw data stays valid until the next NewFrame).
  if (imgui_ && ImGui::GetDrawData() && ImGui::GetDrawData()->Valid) ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  Image img;
  img.width = fbw;
  img.height = fbh;
  img.rgba.assign(size_t(fbw) * size_t(fbh) * 4, 0);
  std::vector<uint8_t> rows(img.rgba.size());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, fbw, fbh, GL_RGBA, GL_UNSIGNED_BYTE, rows.data());
  const size_t stride = size_t(fbw) * 4;
  for (int y = 0; y < fbh; ++y)
    std::copy_n(rows.data() + size_t(fbh - 1 - y) * stride, stride, img.rgba.data() + size_t(y) * stride);
  for (size_t i = 3; i < img.rgba.size(); i += 4) img.rgba[i] = 255;
  return writePng(path, img, error);
}

void App::drawPanels() {
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(330, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("SimGrass");
  const WorldCounts counts = s_.world->counts();
  if (ImGui::CollapsingHeader("Stats", ImGuiTreeNodeFlags_DefaultOpen)) {
    ImGui::Text("%s, tick %" PRId64 " (%.2f s)", s_.scenario.name.c_str(), s_.world->tick(),
                double(s_.world->tick()) * s_.scenario.timeStep.toDouble());
    ImGui::Text("frame %.1f ms, render %.1f ms (%zu tufts)", frameMs_, renderMs_, scene_->tufts.size());
    ImGui::Text("simulation %.2f ms/tick", simMsPerTick_);
    for (size_t st = 0; st < size_t(Stage::Count); ++st)
      ImGui::Text("  %-12s %.3f ms", stageName(Stage(st)), stageMs_[st]);
    ImGui::Text("hash %s", hex(s_.world->stateHash()).c_str());
  }
  if (ImGui::CollapsingHeader("Camera", ImGuiTreeNodeFlags_DefaultOpen)) {
    ImGui::Text("position %.2f %.2f %.2f m", camera_.x, camera_.y, camera_.z);
    ImGui::Text("yaw %.1f, pitch %.1f degrees", camera_.yawDegrees, camera_.pitchDegrees);
    ImGui::SliderFloat("speed m/s", &tune_.walkSpeed, 0.5f, 40.0f);
    ImGui::SliderFloat("eye height", &eyeHeight_, tune_.minEyeHeight, 50.0f);
  }
  if (ImGui::CollapsingHeader("Level of detail", ImGuiTreeNodeFlags_DefaultOpen)) {
    if (counts.lodWindow)
      ImGui::Text("on: window %" PRId64 " x %" PRId64 " patches of %" PRId64 " x %" PRId64, counts.windowPatchesX,
                  counts.windowPatchesZ, counts.patchesX, counts.patchesZ);
    else
      ImGui::Text("off: all %" PRId64 " x %" PRId64 " patches simulated", counts.patchesX, counts.patchesZ);
    ImGui::TextDisabled("(set by the scenario's \"lod\"; fixed for a run)");
  }
  if (ImGui::CollapsingHeader("Bodies", ImGuiTreeNodeFlags_DefaultOpen)) {
    if (counts.bodies == 0) {
      ImGui::Text("none");
    } else {
      const std::string name = size_t(selected_) < s_.scenario.bodies.list.size()
                                   ? s_.scenario.bodies.list[size_t(selected_)].name
                                   : std::string("?");
      ImGui::Text("selected %d/%" PRId64 ": %s (Tab)", selected_, counts.bodies, name.c_str());
      ImGui::Text("mode: %s (P)", positionMode_ ? "position (Displace)" : "velocity (AddVelocity)");
      ImGui::Text("drive: T/F/G/H, up/down: U/J");
    }
  }
  if (ImGui::CollapsingHeader("Recording", ImGuiTreeNodeFlags_DefaultOpen)) {
    if (s_.recorder)
      ImGui::Text("recording to %s\n%.1f KiB (R stops)", s_.recordPath.c_str(),
                  double(s_.recorder->bytesWritten()) / 1024.0);
    else
      ImGui::Text("not recording (R starts)");
    if (!status_.empty()) ImGui::TextWrapped("%s", status_.c_str());
  }
  ImGui::End();
}

int App::run(const std::vector<ScriptCommand>* script) {
  scripted_ = script != nullptr;
  int width = 1280, height = 720;
  {
    const size_t x = opt_.size.find('x');
    char* end = nullptr;
    bool ok = x != std::string::npos;
    if (ok) {
      width = int(std::strtol(opt_.size.c_str(), &end, 10));
      ok = end == opt_.size.c_str() + x;
      height = int(std::strtol(opt_.size.c_str() + x + 1, &end, 10));
      ok = ok && end == opt_.size.c_str() + opt_.size.size() && x > 0 && x + 1 < opt_.size.size();
    }
    if (!ok || width < 64 || height < 64 || width > 8192 || height > 8192)
      return fail(kExitBadInput, "--size: expected WxH with both from 64 to 8192, got '" + opt_.size + "'");
  }
  std::string error;
  if (!open(width, height, &error)) {
    close();
    return fail(kExitFailure, error);
  }
  extractScene(*s_.world, s_.scenario, scene_.get());
  camera_ = defaultCamera(*scene_, *s_.world);
  eyeHeight_ = camera_.y - groundHeight(*s_.world, camera_.x, camera_.z);

  int code = kExitOk;
  auto finish = [&](int c) {
    if (s_.recorder) {
      std::string e;
      if (!s_.stopRecording(&e) && c == kExitOk) c = fail(kExitFailure, e);
    }
    std::printf("final      tick %" PRId64 ", hash %s\n", s_.world->tick(), hex(s_.world->stateHash()).c_str());
    close();
    return c;
  };
  if (!opt_.record.empty() && !s_.startRecording(opt_.record, &error)) return finish(fail(kExitFailure, error));

  const double dt = s_.scenario.timeStep.toDouble();
  using Clock = std::chrono::steady_clock;
  auto last = Clock::now();
  double accumulator = 0;
  size_t next = 0;          // next script command
  int64_t pendingFrames = 0;
  int64_t frames = 0;
  while (!glfwWindowShouldClose(window_)) {
    // ---- script: run commands until one asks for frames ----
    if (scripted_) {
      while (pendingFrames == 0) {
        if (next >= script->size()) return finish(code);
        const ScriptCommand& c = (*script)[next++];
        const std::string where = opt_.script + ":" + std::to_string(c.line) + ": ";
        switch (c.kind) {
          case ScriptCommand::Kind::Frames: pendingFrames = c.count; break;
          case ScriptCommand::Kind::Key: scriptKeys_[size_t(c.key)] = c.down; break;
          case ScriptCommand::Kind::Camera:
            camera_.x = c.camera[0];
            camera_.z = c.camera[2];
            camera_.yawDegrees = c.camera[3];
            camera_.pitchDegrees = c.camera[4];
            eyeHeight_ = std::max(tune_.minEyeHeight, c.camera[1] - groundHeight(*s_.world, camera_.x, camera_.z));
            camera_.y = groundHeight(*s_.world, camera_.x, camera_.z) + eyeHeight_;
            break;
          case ScriptCommand::Kind::Select:
            if (c.count >= s_.world->counts().bodies)
              return finish(fail(kExitBadInput, where + "select " + std::to_string(c.count) + ": the scenario has " +
                                                    std::to_string(s_.world->counts().bodies) + " bodies"));
            selected_ = int(c.count);
            break;
          case ScriptCommand::Kind::RecordStart:
            if (!s_.startRecording(c.path, &error)) return finish(fail(kExitFailure, where + error));
            break;
          case ScriptCommand::Kind::RecordStop:
            if (!s_.stopRecording(&error)) return finish(fail(kExitFailure, where + error));
            break;
          case ScriptCommand::Kind::Screenshot:
            if (!screenshot(c.path, &error)) return finish(fail(kExitFailure, where + error));
            break;
          case ScriptCommand::Kind::Quit: return finish(code);
        }
      }
    } else if (opt_.frames >= 0 && frames >= opt_.frames) {
      break;
    }

    glfwPollEvents();
    if (imgui_) {
      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
    }
    const auto now = Clock::now();
    const double wall = std::chrono::duration<double>(now - last).count();
    last = now;
    frameMs_ = 0.9 * frameMs_ + 0.1 * wall * 1e3;

    // ---- toggles ----
    if (pressed(GLFW_KEY_TAB) && s_.world->counts().bodies > 0)
      selected_ = int((selected_ + 1) % s_.world->counts().bodies);
    if (pressed(GLFW_KEY_P)) positionMode_ = !positionMode_;
    if (pressed(GLFW_KEY_R)) {
      if (s_.recorder) {
        if (!s_.stopRecording(&error)) status_ = error;
        else status_ = "saved " + s_.recordPath;
      } else {
        const std::string path = "simgrass-" + s_.scenario.name + "-" +
                                 std::to_string(std::chrono::system_clock::now().time_since_epoch().count() / 1000000000) +
                                 ".sgr";
        status_ = s_.startRecording(path, &error) ? "" : error;
      }
    }
    if (!scripted_ && pressed(GLFW_KEY_ESCAPE)) glfwSetWindowShouldClose(window_, GLFW_TRUE);

    // ---- simulation: fixed steps, the count decided here ----
    int steps = 1;
    if (!scripted_) {
      accumulator = std::min(accumulator + wall, 0.25);
      steps = int(accumulator / dt);
      accumulator -= steps * dt;
      steps = std::min(steps, 8);
    }
    updateCamera(scripted_ ? float(dt) : float(wall));
    for (int i = 0; i < steps; ++i) {
      const StepResult r = s_.step(tickInput());
      if (!r.ok) return finish(fail(kExitFailure, "the simulation faulted: " + r.error.message()));
      ++clockTicks_;
    }
    if (clockTicks_ >= 30) {
      double total = 0;
      for (size_t st = 0; st < size_t(Stage::Count); ++st) {
        stageMs_[st] = double(s_.clock.nanos[st]) / 1e6 / double(clockTicks_);
        total += stageMs_[st];
        s_.clock.nanos[st] = 0;
      }
      simMsPerTick_ = total;
      clockTicks_ = 0;
    }

    // ---- frame ----
    extractScene(*s_.world, s_.scenario, scene_.get());
    int fbw = 0, fbh = 0;
    glfwGetFramebufferSize(window_, &fbw, &fbh);
    if (fbw > 0 && fbh > 0) {
      const auto r0 = Clock::now();
      renderScene(fbw, fbh);
      glFinish();
      renderMs_ = 0.9 * renderMs_ + 0.1 * std::chrono::duration<double, std::milli>(Clock::now() - r0).count();
    }
    if (imgui_) {
      drawPanels();
      ImGui::Render();
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    }
    glfwSwapBuffers(window_);
    ++frames;
    if (pendingFrames > 0) --pendingFrames;
  }
  return finish(code);
}

}  // namespace
}  // namespace sg::viewer

int main(int argc, char** argv) {
  using namespace sg;
  viewer::Options o;
  CLI::App app("simgrass-viewer: the interactive SimGrass viewer (docs/viewer.md)");
  app.add_option("scenario", o.scenario, "Scenario JSON (default: the built-in thesis meadow)");
  app.add_option("--script", o.script, "Run a test script (frame-locked: one tick per frame)");
  app.add_option("--record", o.record, "Record the session from its first tick to this .sgr");
  app.add_option("--frames", o.frames, "Quit after N frames")->check(CLI::NonNegativeNumber);
  app.add_option("--size", o.size, "Window size WxH (default 1280x720)");
  app.add_option("--msaa", o.msaa, "Samples per pixel: 0 (alpha test) or 2/4/8 (alpha to coverage; default 4)")
      ->check(CLI::IsMember({0, 2, 4, 8}));
  app.add_flag("--no-scenario-input", o.noScenarioInput, "Do not play the scenario's scripted body commands");
  app.add_option("--threads", o.threads, "Simulation worker threads")->check(CLI::Range(1, 256));
  app.footer("Exit codes: 0 ok, 1 no window / OpenGL, simulation fault or I/O error, 2 bad input.");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "simgrass-viewer: %s\n", e.what());
    return 2;
  }
  std::vector<viewer::ScriptCommand> script;
  if (!o.script.empty()) {
    std::ifstream in(o.script, std::ios::binary);
    if (!in) {
      std::fprintf(stderr, "simgrass-viewer: %s: cannot read the script\n", o.script.c_str());
      return 2;
    }
    std::stringstream text;
    text << in.rdbuf();
    std::string error;
    if (!viewer::parseScript(text.str(), o.script, &script, &error)) {
      std::fprintf(stderr, "simgrass-viewer: %s\n", error.c_str());
      return 2;
    }
  }
  viewer::Session session;
  session.threads = o.threads;
  try {
    session.scenario = loadScenarioFile(o.scenario, &session.files);
    session.world = makeWorld(session.scenario, o.threads, physicalMemoryBytes());
  } catch (const ScenarioError& e) {
    std::fprintf(stderr, "simgrass-viewer: %s\n", e.what());
    return 2;
  }
  viewer::App appHost(o, &session);
  return appHost.run(o.script.empty() ? nullptr : &script);
}
