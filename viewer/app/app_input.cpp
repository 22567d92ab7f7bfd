// The viewer's input: GLFW callbacks into an event queue (input_events.h), the keys' actions in
// the order they were pressed, mouse picking and dragging, live control (pause, step, step back,
// restart), shooting, following, the scene browser, screenshots and the settings kept between
// runs. Every action that changes the simulation becomes a recorded TickInput command.
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "replay/input_file.h"
#include "viewer/app/app.h"
#include "viewer/app/text.h"

namespace sg::viewer {

// ---- events -----------------------------------------------------------------------------------

void App::onKey(GLFWwindow* window, int key, int scancode, int action, int mods) {
  auto* app = static_cast<App*>(glfwGetWindowUserPointer(window));
  InputEvent e;
  e.kind = InputEvent::Kind::Key;
  e.code = key;
  e.down = action != GLFW_RELEASE;
  e.repeat = action == GLFW_REPEAT;
  e.mods = mods;
  const bool ui =
      app->router_.route(e, ImGui::GetIO().WantTextInput || ImGui::IsAnyItemActive(), false) == InputRouter::Owner::Ui;
  if (ui) {
    if (app->uiKey_) app->uiKey_(window, key, scancode, action, mods);
  } else if (e.code >= 0) {
    app->input_.push(e);
  }
}

void App::onChar(GLFWwindow* window, unsigned int codepoint) {
  auto* app = static_cast<App*>(glfwGetWindowUserPointer(window));
  // Characters are text: only a text field ImGui is editing takes them.
  if (ImGui::GetIO().WantTextInput && app->uiChar_) app->uiChar_(window, codepoint);
}

void App::onMouseButton(GLFWwindow* window, int button, int action, int mods) {
  auto* app = static_cast<App*>(glfwGetWindowUserPointer(window));
  InputEvent e;
  e.kind = InputEvent::Kind::MouseButton;
  e.code = button;
  e.down = action == GLFW_PRESS;
  e.mods = mods;
  // Over a panel (or while one of its widgets is held) the click is ImGui's; a drag or a look
  // that started in the view keeps its button until released (the router remembers).
  if (app->router_.route(e, false, ImGui::GetIO().WantCaptureMouse) == InputRouter::Owner::Ui) {
    if (app->uiMouseButton_) app->uiMouseButton_(window, button, action, mods);
  } else {
    app->input_.push(e);
  }
}

void App::deliver(const InputEvent& e) {
  // Scripts: the same routing as the keyboard's, ImGui's side receiving nothing (a script's keys
  // and clicks are the app's, as a user's are when no panel is being edited).
  if (router_.route(e, false, false) == InputRouter::Owner::App) input_.push(e);
}

void App::handleEvents() {
  for (const InputEvent& e : input_.takeEvents()) {
    if (!e.down) {
      if (e.kind == InputEvent::Kind::MouseButton && e.code == GLFW_MOUSE_BUTTON_LEFT) dragging_ = false;
      continue;
    }
    if (e.kind == InputEvent::Kind::Key) {
      handleKeyPress(e.code, e.mods);
      continue;
    }
    if (e.code != GLFW_MOUSE_BUTTON_LEFT) continue;
    // A left click picks the body under the cursor; in a live session it also grabs it: the drag
    // pulls the grabbed point along the plane through it that faces the camera.
    int fbw = 0, fbh = 0, ww = 0, wh = 0;
    glfwGetFramebufferSize(window_, &fbw, &fbh);
    glfwGetWindowSize(window_, &ww, &wh);
    const int viewWidth = play_ && play_->hasB() && abView_ == AbView::Side ? abViewWidth(ww) : ww;
    if (cursorX_ >= viewWidth) continue;  // B's view or the panel column: nothing to pick
    Vec3f o, d;
    cursorRay(cam_.camera, viewWidth, wh, cursorX_, cursorY_, &o, &d);
    const std::vector<PickPart> parts = pickParts(scene_, world(), scenario());
    const PickHit hit = pickBody(parts, o, d);
    if (hit.body < 0) continue;
    selected_ = hit.body;
    status_ = "selected body " + std::to_string(hit.body);
    Vec3f centre;
    if (play_ || !bodyCentre(parts, hit.body, &centre)) continue;
    const auto f = cam_.camera.forward();
    dragging_ = true;
    dragBody_ = hit.body;
    dragPoint_ = hit.point;
    dragNormal_ = {f[0], f[1], f[2]};
    for (size_t a = 0; a < 3; ++a) dragOffset_[a] = centre[a] - hit.point[a];
  }
}

void App::handleMouse() {
  // Mouse look while the right button is held in the view (interactive; a script places the camera).
  const bool look = input_.mouseDown(GLFW_MOUSE_BUTTON_RIGHT);
  if (look && looking_) cam_.look(float(cursorX_ - lastCursorX_), float(cursorY_ - lastCursorY_));
  looking_ = look;
  lastCursorX_ = cursorX_;
  lastCursorY_ = cursorY_;
  updateCursorRay();
  if (!dragging_) return;
  if (play_ || dragBody_ >= world().counts().bodies) {
    dragging_ = false;
    return;
  }
  // The grabbed point follows the cursor on its plane (the plane stays where the grab put it).
  Vec3f hit;
  if (rayPlane(rayOrigin_, rayDirection_, dragPoint_, dragNormal_, &hit)) dragPoint_ = hit;
}

void App::updateCursorRay() {
  int ww = 0, wh = 0;
  glfwGetWindowSize(window_, &ww, &wh);
  const int viewWidth = play_ && play_->hasB() && abView_ == AbView::Side ? abViewWidth(ww) : ww;
  cursorRay(cam_.camera, std::max(1, viewWidth), std::max(1, wh), cursorX_, cursorY_, &rayOrigin_, &rayDirection_);
}

void App::handleKeyPress(int key, int mods) {
  std::string error;
  const bool shift = (mods & GLFW_MOD_SHIFT) != 0;
  switch (key) {
    case GLFW_KEY_F1:
      helpShown_ = !helpShown_;
      return;
    case GLFW_KEY_SLASH:  // '?' on US layouts
      if (shift) helpShown_ = !helpShown_;
      return;
    case GLFW_KEY_F2:
      uiHidden_ = !uiHidden_;
      return;
    case GLFW_KEY_F3:
      if (play_) return;  // a recording's camera track drives its window
      grassFollows_ = !grassFollows_;
      frozenCamera_ = {toRaw(cam_.camera.x), toRaw(cam_.camera.y), toRaw(cam_.camera.z)};
      status_ = grassFollows_ ? "grass follows the camera" : "simulated window frozen where it stands";
      return;
    case GLFW_KEY_F12:
      takeScreenshot();
      return;
    case GLFW_KEY_C:
      cam_.free = !cam_.free;
      return;
    case GLFW_KEY_L:
      following_ = !following_;
      if (following_) {
        Vec3f c;
        if (!bodyCentre(pickParts(scene_, world(), scenario()), selected_, &c)) {
          following_ = false;
          return;
        }
        followCentre_ = c;
      }
      return;
    case GLFW_KEY_V:
      if (play_ && play_->hasB()) abView_ = abView_ == AbView::Side ? AbView::Overlay : AbView::Side;
      return;
    case GLFW_KEY_ESCAPE:
      if (scripted_) return;
      if (play_ && play_->busy()) {  // Escape first cancels a pending seek, then quits
        play_->cancel();
        status_ = "seek cancelled at tick " + std::to_string(play_->tick());
      } else {
        glfwSetWindowShouldClose(window_, GLFW_TRUE);
      }
      return;
    case GLFW_KEY_PAGE_DOWN:
    case GLFW_KEY_PAGE_UP:
      openNeighbourScene(key == GLFW_KEY_PAGE_DOWN ? 1 : -1);
      return;
    case GLFW_KEY_SPACE:
      if (play_) {
        play_->playing = !play_->playing;
      } else {
        paused_ = !paused_;
        if (!paused_) status_.clear();  // "at tick T of N" from a step back no longer holds
      }
      return;
    case GLFW_KEY_PERIOD:
      if (play_) {
        play_->playing = false;
        if (!play_->step(1, &error)) showError(error);
      } else {
        stepLive(1);
      }
      return;
    case GLFW_KEY_COMMA:
      if (play_) {
        play_->playing = false;
        if (play_->tick() > play_->recording().header.startTick && !play_->seek(play_->tick() - 1, &error))
          showError(error);
      } else {
        stepLiveBack(1);
      }
      return;
    case GLFW_KEY_HOME:
      if (play_) {
        if (!play_->seek(0, &error)) showError(error);
      } else {
        restartLive();
      }
      return;
    default:
      break;
  }
  if (play_) {
    if (key == GLFW_KEY_TAB && world().counts().bodies > 0) selected_ = int((selected_ + 1) % world().counts().bodies);
    return;
  }
  const int64_t bodies = live_->world->counts().bodies;
  switch (key) {
    case GLFW_KEY_TAB:
      if (bodies > 0) selected_ = int((selected_ + 1) % bodies);
      break;
    case GLFW_KEY_P:
      positionMode_ = !positionMode_;
      break;
    case GLFW_KEY_M: {
      const bool on = size_t(selected_) < mowerOn_.size() ? mowerOn_[size_t(selected_)] : true;
      queueBodyCommand(on ? BodyCommandKind::MowerOff : BodyCommandKind::MowerOn);
      break;
    }
    case GLFW_KEY_BACKSPACE:
    case GLFW_KEY_Z:
      queueBodyCommand(BodyCommandKind::Reset);
      break;
    case GLFW_KEY_N:
      queueBodyCommand(BodyCommandKind::Spawn);
      break;
    case GLFW_KEY_B:
      shootBody();
      break;
    case GLFW_KEY_R:
      if (live_->recorder) {
        status_ = live_->stopRecording(&error) ? "saved " + live_->recordPath : error;
      } else {
        // The scenario's name comes from its JSON: only letters, digits, '-' and '_' of it, at
        // most 40, go into the file name (a name like "../../x" must not pick the folder).
        std::string name;
        for (char ch : live_->scenario.name)
          if (name.size() < 40 && (std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_')) name += ch;
        const std::string path =
            "simgrass-" + (name.empty() ? std::string("session") : name) + "-" +
            std::to_string(std::chrono::system_clock::now().time_since_epoch().count() / 1000000000) + ".sgr";
        status_ = live_->startRecording(path, &error) ? "" : error;
      }
      break;
    default:
      break;
  }
}

// ---- live control -----------------------------------------------------------------------------

void App::stepLive(int64_t n) {
  paused_ = true;
  liveStepsPending_ += n;
}

void App::stepLiveBack(int64_t n) {
  paused_ = true;
  liveStepsPending_ = 0;
  dragging_ = false;
  const int64_t to = std::max<int64_t>(0, live_->world->tick() - n);
  bool stopped = false;
  std::string error;
  if (!live_->seek(to, &stopped, &error)) {
    showError(error);
    return;
  }
  status_ = "at tick " + std::to_string(to) + " of " + std::to_string(live_->historyEnd()) +
            " (resume or a new input continues from here)" +
            (stopped ? "; the recording " + live_->recordPath + " was stopped at its last tick" : "");
  previous_.tick = -1;  // no display interpolation across a jump
}

void App::restartLive() {
  // The scenario's world afresh at tick 0, as a panel edit builds one (a recording is stopped).
  if (!applyScenario(live_->scenario.text, false, "restarted")) return;
  dragging_ = false;
  liveStepsPending_ = 0;
  previous_.tick = -1;
}

void App::shootBody() {
  const int64_t bodies = live_->world->counts().bodies;
  if (selected_ < 0 || selected_ >= bodies) return;
  if (bodies >= kMaxBodies) {
    status_ = "at most " + std::to_string(kMaxBodies) + " bodies";
    return;
  }
  // A copy of the selected body, 1.5 m ahead of the eye along the view, thrown at 15 m/s: two
  // recorded commands, the spawn and the new body's velocity (tickInput names its index).
  const auto f = cam_.camera.forward();
  BodyCommand spawn;
  spawn.body = selected_;
  spawn.kind = BodyCommandKind::Spawn;
  spawn.value = {toRaw(cam_.camera.x + 1.5f * f[0]), toRaw(cam_.camera.y + 1.5f * f[1]),
                 toRaw(cam_.camera.z + 1.5f * f[2])};
  BodyCommand throwIt;
  throwIt.body = kShotBody;
  throwIt.kind = BodyCommandKind::AddVelocity;
  throwIt.value = {toRaw(15.0 * f[0]), toRaw(15.0 * f[1]), toRaw(15.0 * f[2])};
  pendingCommands_.push_back(spawn);
  pendingCommands_.push_back(throwIt);
}

void App::followSelected() {
  Vec3f c;
  if (!bodyCentre(pickParts(scene_, world(), scenario()), selected_, &c)) {
    following_ = false;
    return;
  }
  // The camera keeps its offset to the body (WASD just moved the camera: that changes the
  // offset), never below the ground, and looks at the body.
  followOffset_ = {cam_.camera.x - followCentre_[0], cam_.camera.y - followCentre_[1],
                   cam_.camera.z - followCentre_[2]};
  followCentre_ = c;
  Camera next =
      Camera::lookingAt(c[0] + followOffset_[0], c[1] + followOffset_[1], c[2] + followOffset_[2], c[0], c[1], c[2]);
  const float g = groundHeight(world(), next.x, next.z) + cam_.tune.minEyeHeight;
  if (next.y < g) next = Camera::lookingAt(next.x, g, next.z, c[0], c[1], c[2]);
  next.fovYDegrees = cam_.camera.fovYDegrees;
  cam_.camera = next;
  cam_.eyeHeight = cam_.camera.y - groundHeight(world(), cam_.camera.x, cam_.camera.z);
}

// ---- scenes, screenshots, settings -------------------------------------------------------------

std::vector<std::string> App::sceneList() const {
  // The scenario files beside the current one (or in ./scenarios for the built-in meadow).
  namespace fs = std::filesystem;
  const std::string dir = !live_->scenarioDir.empty() ? live_->scenarioDir : std::string("scenarios");
  std::vector<std::string> files;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().extension() == ".json" && it->is_regular_file(ec)) files.push_back(it->path().string());
    if (files.size() >= 1000) break;  // a folder of thousands is not a scene list
  }
  std::sort(files.begin(), files.end());
  return files;
}

void App::openNeighbourScene(int direction) {
  const std::vector<std::string> files = sceneList();
  if (files.empty()) {
    status_ = "no scenario files next to this one";
    return;
  }
  const std::string current = live_->scenario.sourceName;
  auto at = std::find_if(files.begin(), files.end(), [&](const std::string& f) { return sameFile(f, current); });
  size_t next = 0;
  if (at != files.end())
    next = (size_t(at - files.begin()) + files.size() + size_t(direction > 0 ? 1 : files.size() - 1)) % files.size();
  openFile(files[next]);
}

void App::takeScreenshot() {
  std::string name;
  for (char ch : scenario().name)
    if (name.size() < 40 && (std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_')) name += ch;
  // Appended piece by piece (GCC 12's -Wrestrict misfires on one long concatenation, bug 105329).
  std::string path = "simgrass-";
  path.append(name.empty() ? std::string("scene") : name).append("-").append(std::to_string(world().tick()));
  if (screenshots_ > 0) path.append("-").append(std::to_string(screenshots_));
  path.append(".png");
  ++screenshots_;
  std::string error;
  status_ = screenshot(path, &error) ? "saved " + path : error;
  if (!error.empty()) showError(error);
}

void App::loadSettings() {
  // Scripted runs (tests) keep no settings unless --config-dir names a folder.
  configDir_ = !opt_.configDir.empty() ? opt_.configDir : scripted_ ? std::string() : defaultConfigDir();
  if (configDir_.empty()) return;
  std::string warning;
  settings_ = viewer::loadSettings(configDir_, &warning);
  if (!warning.empty()) std::fprintf(stderr, "simgrass-viewer: warning: %s\n", warning.c_str());
  imguiIni_ = (std::filesystem::path(configDir_) / "imgui.ini").string();
  cam_.tune.walkSpeed = settings_.walkSpeed;
  cam_.free = settings_.freeCamera;
  render_.ssao = settings_.ssao;
  render_.rockBlend = settings_.rockBlend;
  interpolate_ = settings_.interpolate;
  uiHidden_ = settings_.uiHidden;
}

void App::saveSettings() {
  if (configDir_.empty()) return;
  settings_.walkSpeed = cam_.tune.walkSpeed;
  settings_.freeCamera = cam_.free;
  settings_.ssao = render_.ssao;
  settings_.rockBlend = render_.rockBlend;
  if (samples_ > 0) settings_.alphaToCoverage = render_.alphaToCoverage;
  if (!scripted_) settings_.interpolate = interpolate_;
  settings_.uiHidden = uiHidden_;
  std::string error;
  if (!viewer::saveSettings(configDir_, settings_, &error))
    std::fprintf(stderr, "simgrass-viewer: warning: settings not saved: %s\n", error.c_str());
  if (imgui_ && !imguiIni_.empty()) ImGui::SaveIniSettingsToDisk(imguiIni_.c_str());
}

// ---- the selected body's outline --------------------------------------------------------------

void App::appendSelectionOutline(Scene* scene) const {
  // A yellow box around each part of the selected body (a cube around a sphere): drawn over the
  // scene by the renderer's overlay, whatever the debug layers.
  for (const PickPart& p : pickParts(*scene, world(), scenario())) {
    if (p.body != selected_) continue;
    Vec3f corner[8];
    for (int k = 0; k < 8; ++k) {
      const float s[3] = {k & 1 ? 1.05f : -1.05f, k & 2 ? 1.05f : -1.05f, k & 4 ? 1.05f : -1.05f};
      for (size_t a = 0; a < 3; ++a)
        corner[k][a] = p.model[12 + a] + p.model[a] * s[0] + p.model[4 + a] * s[1] + p.model[8 + a] * s[2];
    }
    static constexpr int kEdges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                          {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    for (const auto& e : kEdges) {
      DebugScene::Line l{};
      for (size_t a = 0; a < 3; ++a) {
        l.a[a] = corner[e[0]][a];
        l.b[a] = corner[e[1]][a];
      }
      l.colour[0] = 1.0f;
      l.colour[1] = 0.85f;
      l.colour[2] = 0.1f;
      scene->debug.lines.push_back(l);
    }
  }
}

}  // namespace sg::viewer
