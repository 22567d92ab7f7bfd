#include "viewer/app/app.h"

#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <dlfcn.h>
#include <link.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>

#include "replay/input_file.h"
#include "replay/physics_devices.h"
#include "sim/gpu/gl_physics.h"
#include "viewer/app/text.h"

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

namespace sg::viewer {
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

App::App(Options o, std::unique_ptr<Session> live, std::unique_ptr<Playback> playback)
    : opt_(std::move(o)), live_(std::move(live)), play_(std::move(playback)) {
  resetEdits();
}

std::function<float(float, float)> App::ground() {
  return [this](float x, float z) { return groundHeight(world(), x, z); };
}

bool App::open(std::string* error) {
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
  window_ = glfwCreateWindow(opt_.width, opt_.height, ("SimGrass - " + scenario().name).c_str(), nullptr, nullptr);
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
  if (!live_->scenarioDir.empty()) renderer_->setAssetDirectory(live_->scenarioDir);
  // GPU physics runs in this window's context (docs/gpu-physics.md): the renderer draws the
  // tufts' tops straight from the device's buffers.
  registerGpuPhysics(&gpu::makeCurrentContextPhysicsProvider);
  if (const std::optional<PhysicsPath> path = parsePhysicsPath(opt_.physics); path && *path != PhysicsPath::Cpu) {
    live_->physics = *path;  // a recording opened later plays there too (App::openFile)
    if (const std::string why = play_ ? play_->setPhysics(*path) : live_->setPhysics(*path); !why.empty()) {
      *error = "--physics " + opt_.physics + ": " + why;
      return false;
    }
  }
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  // The layout lives with the app's settings (settings.h), never next to the user's files; a
  // scripted run without --config-dir keeps none.
  ImGui::GetIO().IniFilename = imguiIni_.empty() ? nullptr : imguiIni_.c_str();
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window_, true);
  ImGui_ImplOpenGL3_Init("#version 330");
  imgui_ = true;
  // Ours after ImGui's: every key, character and button reaches App::deliver first, which hands
  // it to ImGui's callback (saved here) or to the app, never both (input_events.h).
  glfwSetWindowUserPointer(window_, this);
  uiKey_ = glfwSetKeyCallback(window_, &App::onKey);
  uiChar_ = glfwSetCharCallback(window_, &App::onChar);
  uiMouseButton_ = glfwSetMouseButtonCallback(window_, &App::onMouseButton);
  return true;
}

void App::close() {
  if (imgui_) {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    imgui_ = false;
  }
  renderer_.reset();  // GL objects go while the context is current
  if (window_) {      // a device's buffers too
    if (live_ && live_->world) live_->world->setPhysicsPath(PhysicsPath::Cpu, nullptr);
    if (play_) play_->setPhysics(PhysicsPath::Cpu);
  }
  if (window_) glfwDestroyWindow(window_);
  window_ = nullptr;
  glfwTerminate();
}

int App::finish(int code) {
  if (recordingFailed_ && code == kExitOk) code = kExitFailure;  // a recording lost ticks: not a clean run
  saveSettings();
  if (live_->recorder) {
    std::string e;
    if (!live_->stopRecording(&e) && code == kExitOk) {
      std::fprintf(stderr, "simgrass-viewer: %s\n", e.c_str());
      code = kExitFailure;
    }
  }
  std::printf("final      tick %" PRId64 ", hash %s\n", world().tick(), hex(world().stateHash()).c_str());
  std::fflush(stdout);
  close();
  return code;
}

void App::showError(const std::string& message) {
  std::fprintf(stderr, "simgrass-viewer: %s\n", message.c_str());
  std::fflush(stderr);
  errorText_ = message;
}

// ---- input ------------------------------------------------------------------------------------

TickInput App::tickInput() {
  TickInput in;
  in.hasCamera = true;
  in.camera = {toRaw(cam_.camera.x), toRaw(cam_.camera.y), toRaw(cam_.camera.z)};
  // F3 off: the simulated window stays where it stood (the thesis' "grass follows camera" off).
  if (!grassFollows_) in.camera = frozenCamera_;
  // The scenario's own scripted commands still play (the thesis scene kicks the football); the
  // user's commands come after them. Its camera track is replaced by the user's camera.
  const Session& s = *live_;
  if (!opt_.noScenarioInput) in.bodies = scriptedInput(s.scenario, s.world->tick()).bodies;
  // One-shot commands (reset, spawn, mower, shoot) go into the first tick after the key. A
  // shot's AddVelocity names the body its Spawn makes: the next index after every body and every
  // spawn before it in this tick (kShotBody marks it until then).
  const int64_t bodies = s.world->counts().bodies;
  for (BodyCommand c : pendingCommands_) {
    if (c.body == kShotBody) {
      const auto spawns = std::count_if(in.bodies.begin(), in.bodies.end(),
                                        [](const BodyCommand& b) { return b.kind == BodyCommandKind::Spawn; });
      c.body = int32_t(bodies + spawns - 1);
    }
    in.bodies.push_back(c);
  }
  pendingCommands_.clear();
  // The mouse drag: the spring's target for the grabbed body's centre of mass, every tick it is held.
  if (dragging_ && dragBody_ >= 0 && dragBody_ < bodies) {
    BodyCommand c;
    c.body = dragBody_;
    c.kind = BodyCommandKind::DragTo;
    c.value = {toRaw(dragPoint_[0] + dragOffset_[0]), toRaw(dragPoint_[1] + dragOffset_[1]),
               toRaw(dragPoint_[2] + dragOffset_[2])};
    in.bodies.push_back(c);
  }
  if (selected_ < 0 || selected_ >= bodies) return in;
  float fx, fz, rx, rz;
  cam_.groundAxes(&fx, &fz, &rx, &rz);
  const float f = float(held(GLFW_KEY_T)) - float(held(GLFW_KEY_G));
  const float r = float(held(GLFW_KEY_H)) - float(held(GLFW_KEY_F));
  const float u = float(held(GLFW_KEY_U)) - float(held(GLFW_KEY_J));
  if (f == 0 && r == 0 && u == 0) return in;
  const double dt = s.scenario.timeStep.toDouble();
  const double scale = positionMode_ ? cam_.tune.bodySpeed * dt : cam_.tune.bodyAcceleration * dt;
  BodyCommand c;
  c.body = selected_;
  c.kind = positionMode_ ? BodyCommandKind::Displace : BodyCommandKind::AddVelocity;
  c.value = {toRaw((f * fx + r * rx) * scale), toRaw(u * scale), toRaw((f * fz + r * rz) * scale)};
  in.bodies.push_back(c);
  return in;
}

void App::queueBodyCommand(BodyCommandKind kind) {
  const int64_t bodies = live_->world->counts().bodies;
  if (play_ || selected_ < 0 || selected_ >= bodies) return;
  BodyCommand c;
  c.body = selected_;
  c.kind = kind;
  if (kind == BodyCommandKind::Spawn) {
    if (bodies >= kMaxBodies) {
      status_ = "at most " + std::to_string(kMaxBodies) + " bodies";
      return;
    }
    // 3 m in front of the camera (on the ground plane), 1 m above the terrain there.
    float fx, fz, rx, rz;
    cam_.groundAxes(&fx, &fz, &rx, &rz);
    const float x = cam_.camera.x + 3 * fx, z = cam_.camera.z + 3 * fz;
    c.value = {toRaw(x), toRaw(groundHeight(world(), x, z) + 1.0), toRaw(z)};
  }
  if (kind == BodyCommandKind::MowerOn || kind == BodyCommandKind::MowerOff) {
    if (mowerOn_.size() < size_t(bodies)) mowerOn_.resize(size_t(bodies), true);
    mowerOn_[size_t(selected_)] = kind == BodyCommandKind::MowerOn;
  }
  pendingCommands_.push_back(c);
}

// ---- simulation -------------------------------------------------------------------------------

bool App::simulate(double wall, std::string* error) {
  if (play_) {
    // A/B: the whole run's divergence scan goes on a slice a frame, whatever else happens.
    if (play_->hasB() && !play_->scanDone()) play_->scanWork(scripted_ ? kScriptedSeekSeconds : kSeekSecondsPerFrame);
    // Playback: `wall` seconds are wall/dt recorded ticks at speed 1 (a scripted frame: one).
    const double dt = play_->scenario().timeStep.toDouble();
    if (play_->busy()) {
      // A pending seek or step: a slice of it per frame, so the window stays responsive and
      // Escape (or the panel's Cancel) can stop it. A failure is the one-line error, shown.
      std::string e;
      if (!play_->work(scripted_ ? kScriptedSeekSeconds : kSeekSecondsPerFrame, &e)) showError(e);
      status_ = play_->busy()
                    ? "seeking to tick " + std::to_string(play_->target()) + ": at " + std::to_string(play_->tick())
                    : "at tick " + std::to_string(play_->tick());
      return true;
    }
    if (!play_->advance(scripted_ ? 1.0 : std::min(wall, 0.25) / dt, error)) return false;
    if (!play_->mismatchText().empty() && errorText_.empty()) errorText_ = play_->mismatchText();
    return true;
  }
  const double dt = live_->scenario.timeStep.toDouble();
  int steps = 1;
  if (paused_) {
    // Paused: only the ticks asked for (. or `step N`), a frame's worth at most 8 at a time.
    steps = int(std::min<int64_t>(liveStepsPending_, scripted_ ? liveStepsPending_ : 8));
    liveStepsPending_ -= steps;
    accumulator_ = 0;
  } else if (!scripted_) {
    accumulator_ = std::min(accumulator_ + wall, 0.25);
    steps = int(accumulator_ / dt);
    accumulator_ -= steps * dt;
    steps = std::min(steps, 8);
  }
  const StageClock before = live_->clock;
  FrameTiming& frame = timing_[(timingNext_ + kTimingFrames - 1) % kTimingFrames];  // this frame's
  for (int i = 0; i < steps; ++i) {
    // The tick before the last of this frame is what display interpolation starts from.
    if (i + 1 == steps && interpolate_ && !scripted_ && !paused_) extractScene(world(), scenario(), &previous_);
    // Behind the history's end (stepped back), a paused step replays what was done there; any
    // other tick is a new input and starts a new branch from here (Session::step).
    const bool replaying = paused_ && live_->world->tick() < live_->historyEnd();
    const StepResult r = replaying ? live_->replayNext() : live_->step(tickInput());
    if (!live_->recordingError.empty()) {
      showError(live_->recordingError);
      status_ = live_->recordingError;
      live_->recordingError.clear();
      recordingFailed_ = true;
    }
    if (!r.ok) {
      *error = "the simulation faulted: " + r.error.message();
      return false;
    }
    ++clockTicks_;
    ++frame.ticks;
  }
  for (size_t st = 0; st < size_t(Stage::Count); ++st)
    frame.stageMs[st] = float(double(live_->clock.nanos[st] - before.nanos[st]) / 1e6);
  if (clockTicks_ >= 30) {
    double total = 0;
    for (size_t st = 0; st < size_t(Stage::Count); ++st) {
      stageMs_[st] = double(live_->clock.nanos[st]) / 1e6 / double(clockTicks_);
      total += stageMs_[st];
      live_->clock.nanos[st] = 0;
    }
    simMsPerTick_ = total;
    clockTicks_ = 0;
  }
  return true;
}

// ---- drawing ----------------------------------------------------------------------------------

void App::buildScenes(float alpha) {
  extractScene(world(), scenario(), &scene_);
  scene_.debug = {};
  if (render_.debug.any()) extractDebug(world(), scenario(), render_.debug, &scene_);
  // The selected body, outlined (drawn over the scene: RenderOptions::overlay).
  const bool outline = selected_ >= 0 && selected_ < world().counts().bodies;
  if (outline) appendSelectionOutline(&scene_);
  render_.overlay = outline;
  render_.heatMap = false;
  if (play_ && play_->hasB()) {
    if (abView_ == AbView::Side) {
      extractScene(play_->worldB(), play_->scenarioB(), &sceneB_);
      sceneB_.debug = {};
      if (render_.debug.any()) extractDebug(play_->worldB(), play_->scenarioB(), render_.debug, &sceneB_);
    } else if (play_->measured()) {
      applyDivergenceHeat(play_->observationA(), play_->observationB(), heatFullScale_, &scene_);
      render_.heatMap = true;
    }
  }
  const bool lerp = interpolate_ && !scripted_ && !play_ && previous_.tick + 1 == scene_.tick;
  if (lerp) interpolateScene(previous_, scene_, std::clamp(alpha, 0.0f, 1.0f), &shown_);
}

void App::renderWorld(int fbw, int fbh) {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, fbw, fbh);
  RenderOptions o = render_;
  o.alphaToCoverage = render_.alphaToCoverage && samples_ > 0;
  const bool lerp = interpolate_ && !scripted_ && !play_ && previous_.tick + 1 == scene_.tick;
  const Scene& a = lerp ? shown_ : scene_;
  if (!(play_ && play_->hasB() && abView_ == AbView::Side)) {
    renderer_->draw(a, cam_.camera, fbw, fbh, o);
    return;
  }
  // Side by side, one camera, each view abViewWidth wide (the panel column right of them): the
  // renderer draws at the viewport origin and clears the whole framebuffer, so B goes first into
  // [0, w) and is copied to [w, 2w) (the two never overlap); then A is drawn into [0, w) with the
  // scissor keeping its clear off B.
  const int w = abViewWidth(fbw);
  RenderOptions ob = o;
  ob.heatMap = false;
  renderer_->draw(sceneB_, cam_.camera, w, fbh, ob);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glBlitFramebuffer(0, 0, w, fbh, w, 0, 2 * w, fbh, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glEnable(GL_SCISSOR_TEST);
  glScissor(0, 0, w, fbh);
  renderer_->draw(a, cam_.camera, w, fbh, o);
  glDisable(GL_SCISSOR_TEST);
  glViewport(0, 0, fbw, fbh);
}

std::string App::inputNamed(const std::string& path) const {
  std::vector<std::string> inputs = {opt_.script, opt_.input, opt_.abFile, live_->scenario.sourceName};
  if (play_) inputs.push_back(play_->recording().file);
  for (const std::string& in : inputs)
    if (!in.empty() && sameFile(path, in)) return in;
  return {};
}

bool App::screenshot(const std::string& path, std::string* error) {
  if (const std::string in = inputNamed(path); !in.empty()) {
    *error = path + ": expected an output file other than the input " + in;
    return false;
  }
  int fbw = 0, fbh = 0;
  glfwGetFramebufferSize(window_, &fbw, &fbh);
  renderWorld(fbw, fbh);
  // The panels of the last frame (ImGui's draw data stays valid until the next NewFrame).
  if (imgui_ && ImGui::GetDrawData() && ImGui::GetDrawData()->Valid)
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
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

int App::run(const std::vector<ScriptCommand>* script, const std::string& startupError) {
  scripted_ = script != nullptr;
  loadSettings();
  if (scripted_) interpolate_ = false;  // frame-locked runs show exact ticks (screenshots stay exact)
  std::string error;
  if (!open(&error)) {
    close();
    std::fprintf(stderr, "simgrass-viewer: %s\n", error.c_str());
    return kExitFailure;
  }
  errorText_ = startupError;
  if (startupError.empty()) settings_.remember(opt_.input);
  extractScene(world(), scenario(), &scene_);
  cam_.camera = defaultCamera(scene_, world(), float(opt_.width) / float(opt_.height));
  cam_.eyeHeight = cam_.camera.y - groundHeight(world(), cam_.camera.x, cam_.camera.z);
  render_.alphaToCoverage = samples_ > 0 && settings_.alphaToCoverage;
  if (play_) play_->playing = !scripted_;  // interactive: starts playing; scripts start paused
  if (!opt_.record.empty() && !inputNamed(opt_.record).empty()) {
    std::fprintf(stderr, "simgrass-viewer: --record: %s: expected an output file other than the input %s\n",
                 opt_.record.c_str(), inputNamed(opt_.record).c_str());
    close();
    return kExitBadInput;
  }
  if (!opt_.record.empty() && !live_->startRecording(opt_.record, &error)) {
    std::fprintf(stderr, "simgrass-viewer: %s\n", error.c_str());
    return finish(kExitFailure);
  }

  using Clock = std::chrono::steady_clock;
  auto last = Clock::now();
  int64_t pendingFrames = 0;
  while (!glfwWindowShouldClose(window_)) {
    if (scripted_) {
      if (pendingFrames == 0) {
        const int r = runScript(*script, &pendingFrames);
        if (r != kGoOn) return finish(r);
      }
    } else if (opt_.frames >= 0 && frames_ >= opt_.frames) {
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

    // The cursor (a script's `mouse X Y` places it instead), then the frame's events in order.
    if (!scripted_) glfwGetCursorPos(window_, &cursorX_, &cursorY_);
    timing_[timingNext_++ % kTimingFrames] = FrameTiming{};  // this frame's slot of the timing graph
    handleEvents();
    handleMouse();
    const double dt = scenario().timeStep.toDouble();
    MoveKeys mk;
    mk.forward = float(held(GLFW_KEY_W)) - float(held(GLFW_KEY_S));
    mk.right = float(held(GLFW_KEY_D)) - float(held(GLFW_KEY_A));
    mk.up = float(held(GLFW_KEY_E)) - float(held(GLFW_KEY_Q));
    mk.fast = held(GLFW_KEY_LEFT_SHIFT) || held(GLFW_KEY_RIGHT_SHIFT);
    cam_.update(mk, scripted_ ? float(dt) : float(wall), ground());
    if (following_) followSelected();
    if (!simulate(wall, &error)) {
      std::fprintf(stderr, "simgrass-viewer: %s\n", error.c_str());
      return finish(kExitFailure);
    }
    input_.endFrame();  // this frame's taps have driven its ticks

    buildScenes(float(accumulator_ / dt));
    int fbw = 0, fbh = 0;
    glfwGetFramebufferSize(window_, &fbw, &fbh);
    if (fbw > 0 && fbh > 0) {
      const auto r0 = Clock::now();
      renderWorld(fbw, fbh);
      glFinish();
      const double ms = std::chrono::duration<double, std::milli>(Clock::now() - r0).count();
      renderMs_ = 0.9 * renderMs_ + 0.1 * ms;
      timing_[(timingNext_ + kTimingFrames - 1) % kTimingFrames].renderMs = float(ms);
    }
    if (imgui_) {
      if (!uiHidden_) drawPanels();
      if (play_ && play_->hasB() && abView_ == AbView::Side && fbw > 0) drawAbLabels(fbw, fbh);
      if (helpShown_) drawHelp();
      ImGui::Render();
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    }
    glfwSwapBuffers(window_);
    ++frames_;
    if (pendingFrames > 0) --pendingFrames;
  }
  return finish(kExitOk);
}

}  // namespace sg::viewer
