// The window and the frame loop of simgrass-viewer (docs/viewer.md): a GLFW window (OpenGL 3.3
// core, GLEW), the shared Renderer, Dear ImGui panels (panels.cpp), and one of two sources of
// worlds: a live Session (keys and camera become recorded TickInputs) or a Playback of a `.sgr`
// (optionally A/B against a second run).
//
// The simulation never reads a clock: the loop decides how many ticks to run (a fixed-step
// accumulator at the scenario's dt, or exactly one per frame with --script) and hands each one a
// TickInput, which is all a recording needs to reproduce the session.
#pragma once

#include <GL/glew.h>
// GLEW's header first; GLFW must not pull in another GL header.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <array>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "viewer/app/camera_controller.h"
#include "viewer/app/input_events.h"
#include "viewer/app/options.h"
#include "viewer/app/picking.h"
#include "viewer/app/playback.h"
#include "viewer/app/script.h"
#include "viewer/app/session.h"
#include "viewer/app/settings.h"
#include "viewer/render/renderer.h"
#include "viewer/render/scene.h"

namespace sg::viewer {

/// App::runScript / runCommand: go on (any other value is an exit code).
inline constexpr int kGoOn = -1;

/// A pending AddVelocity of a shot (B) names the body its Spawn will make: resolved in tickInput.
inline constexpr int32_t kShotBody = -2;

/// Wall time a pending seek or step may take per frame (interactive; scripted runs wait for it
/// with bigger slices). A seek's length is bounded by the recording's last tick.
inline constexpr double kSeekSecondsPerFrame = 0.03, kScriptedSeekSeconds = 0.25;

/// Panel edit buffers (what the Physics, Grass, Meadow and Terrain panels show before Apply).
struct ScenarioEdits {
  float gustScale = 1, gustPeriodScale = 1;  ///< factors on the wind schedule's forces / durations
  float damping = 0.97f, upAcceleration = 1, constraintLength = 1;
  float gravityY = -9.81f;
  float scaleY = 1, scaleXZ = 0.5f;
  int patchesX = 151, patchesZ = 151, interpolation = 1;
  float spacing = 0.25f;
  char heightmap[512] = "";
  float cellSize = 1, maxHeight = 5;
  int model = 0;  ///< GrassModel: 0 thesis, 1 pbd, 2 blade
  float bladeFrequency = 0.5f, bladeDampingRatio = 0.3f, trampleSeconds = 10;
};

class App {
 public:
  /// Starts with a live session, or with a playback when `playback` is given (then `live` is the
  /// built-in meadow, kept for the Open panel's errors to fall back on).
  App(Options o, std::unique_ptr<Session> live, std::unique_ptr<Playback> playback);
  /// `startupError`: shown in the error window from the first frame (--keep-open-on-error).
  int run(const std::vector<ScriptCommand>* script, const std::string& startupError = "");

 private:
  enum class AbView { Side, Overlay };

  // ---- app.cpp: window, loop ----
  bool open(std::string* error);
  void close();
  int finish(int code);
  // ---- app_input.cpp: events, keys, mouse, live control ----
  /// GLFW callbacks (installed after ImGui's, which they forward to): each event is routed once.
  static void onKey(GLFWwindow* window, int key, int scancode, int action, int mods);
  static void onChar(GLFWwindow* window, unsigned int codepoint);
  static void onMouseButton(GLFWwindow* window, int button, int action, int mods);
  /// Routes an event to ImGui (through its saved callback) or to the app's queue (InputRouter).
  void deliver(const InputEvent& e);
  /// A drive or movement key: held at any time during this frame (keyboard or script).
  bool held(int k) const { return input_.heldThisFrame(k); }
  /// The frame's key presses and mouse clicks, in order: toggles, live control, picking.
  void handleEvents();
  void handleKeyPress(int key, int mods);
  void handleMouse();
  void updateCursorRay();
  /// Live control: pause, step forward, step back, restart (docs/viewer.md "Live control").
  void stepLive(int64_t n);
  void stepLiveBack(int64_t n);
  void restartLive();
  void shootBody();
  void openNeighbourScene(int direction);
  std::vector<std::string> sceneList() const;
  void takeScreenshot();
  void followSelected();
  void appendSelectionOutline(Scene* scene) const;
  // ---- app_script.cpp ----
  /// Runs script commands until one asks for frames (*frames = N); returns an exit code to stop
  /// with, or -1 to render those frames.
  int runScript(const std::vector<ScriptCommand>& script, int64_t* frames);
  int runCommand(const ScriptCommand& c);
  /// Advances the simulation for `wall` seconds of wall time (scripted: one tick). False: fault.
  bool simulate(double wall, std::string* error);
  TickInput tickInput();
  void queueBodyCommand(BodyCommandKind kind);
  void buildScenes(float alpha);
  void renderWorld(int fbw, int fbh);
  /// A/B side by side: the two views' width (each), leaving the panel column on the right.
  int abViewWidth(int fbw) const;
  void drawAbLabels(int fbw, int fbh);
  void drawHelp();
  void panelTiming();
  void panelLive();
  void panelScenes();
  void loadSettings();
  void saveSettings();
  bool screenshot(const std::string& path, std::string* error);
  /// The input of this session (script, scenario, recording, A/B file) that `path` names (same
  /// file), or "": outputs never replace an input.
  std::string inputNamed(const std::string& path) const;
  void printState() const;
  void printStatus() const;
  std::function<float(float, float)> ground();

  // ---- files and sessions (app_files.cpp) ----
  /// Opens a scenario or a recording in place of the current one. On failure keeps the current
  /// session, prints the one-line error (the CLI's text) and shows it in the error window.
  bool openFile(const std::string& path);
  /// Applies scenario JSON edits by building a new Session (see docs/viewer.md: from tick 0, or
  /// replaying the inputs so far when `replayHistory`). On failure the old session keeps running.
  bool applyScenario(const std::string& text, bool replayHistory, const std::string& what);
  /// Puts the (new) live session on `path`, the one the session it replaced ran on; an error
  /// leaves it on the CPU and says so.
  void keepPhysics(PhysicsPath path);
  void showError(const std::string& message);
  void resetEdits();
  std::string editedScenarioText() const;

  // ---- panels.cpp ----
  void drawPanels();
  void panelStats();
  void panelPlayback();
  void panelAb();
  void panelOpen();
  void panelCamera();
  void panelPhysics();
  void panelVisuals();
  void panelLod();
  void panelMeadow();
  void panelTerrain();
  void panelBodies();
  void panelRecording();
  void errorWindow();

  SimWorld& world() { return play_ ? play_->world() : *live_->world; }
  const SimWorld& world() const { return play_ ? play_->world() : *live_->world; }
  const Scenario& scenario() const { return play_ ? play_->scenario() : live_->scenario; }

  Options opt_;
  // The stats panel's hash on the resident GPU path: computed on request (it copies the state
  // back), kept for the world and tick it was taken at.
  const SimWorld* hashedWorld_ = nullptr;
  int64_t hashedTick_ = -1;
  uint64_t hashedValue_ = 0;
  std::unique_ptr<Session> live_;
  std::unique_ptr<Playback> play_;
  CameraController cam_;
  GLFWwindow* window_ = nullptr;
  bool imgui_ = false;
  std::unique_ptr<Renderer> renderer_;
  Scene scene_, sceneB_, previous_, shown_;
  bool scripted_ = false;
  int samples_ = 0;
  // Input: the app's events and held keys, where each press went, ImGui's own callbacks.
  InputState input_;
  InputRouter router_;
  GLFWkeyfun uiKey_ = nullptr;
  GLFWcharfun uiChar_ = nullptr;
  GLFWmousebuttonfun uiMouseButton_ = nullptr;
  double cursorX_ = 0, cursorY_ = 0;  ///< window pixels (a script's `mouse X Y` sets them)
  double lastCursorX_ = 0, lastCursorY_ = 0;
  bool looking_ = false;
  Vec3f rayOrigin_{}, rayDirection_{};  ///< the ray under the cursor, this frame
  double accumulator_ = 0;              ///< s of wall time not yet simulated (live, interactive)
  // Live control.
  bool paused_ = false;
  int64_t liveStepsPending_ = 0;  ///< ticks the next frame runs while paused (. key, `step N`)
  bool grassFollows_ = true;      ///< F3 off: the simulated window's camera input stays frozen
  InputVec3 frozenCamera_{};
  // Mouse drag (a DragTo command every tick while held).
  bool dragging_ = false;
  int dragBody_ = -1;
  Vec3f dragOffset_{};  ///< centre of mass minus the grabbed point (m)
  Vec3f dragPoint_{};   ///< the grabbed point's target: on the plane facing the camera
  Vec3f dragNormal_{};
  // Camera following the selected body (L).
  bool following_ = false;
  Vec3f followOffset_{}, followCentre_{};
  // UI.
  bool uiHidden_ = false, helpShown_ = false;
  ViewerSettings settings_;
  std::string configDir_;  ///< where settings live ("" : nowhere, as in scripted runs)
  std::string imguiIni_;   ///< ImGui's layout file (kept alive for io.IniFilename)
  int64_t screenshots_ = 0;
  // Bodies.
  int selected_ = 0;
  bool positionMode_ = false;
  std::vector<bool> mowerOn_;                 ///< per body; mowers start cutting
  std::vector<BodyCommand> pendingCommands_;  ///< one-shot commands (reset, spawn, mower) for the next tick
  // Visuals.
  RenderOptions render_;
  bool interpolate_ = true;      ///< display interpolation (off in scripted runs)
  float heatFullScale_ = 0.05f;  ///< m of tip difference shown at full heat
  AbView abView_ = AbView::Side;
  // Panels.
  ScenarioEdits edits_;
  char openPath_[512] = "";
  bool scrubbing_ = false;  ///< the timeline slider is held
  int64_t scrubTick_ = 0;   ///< where it is held
  std::string errorText_;   ///< the error window's line ("" when closed)
  std::string status_;
  bool recordingFailed_ = false;  ///< a recording stopped on a write error (exit code 1 at the end)
  // Stats: averages, and per-frame stage times for the timing graph (a ring of kTimingFrames).
  static constexpr size_t kTimingFrames = 240;
  struct FrameTiming {
    std::array<float, size_t(Stage::Count)> stageMs{};  ///< summed over the frame's ticks
    float renderMs = 0;
    int ticks = 0;
  };
  std::array<FrameTiming, kTimingFrames> timing_{};
  size_t timingNext_ = 0;
  double renderMs_ = 0, frameMs_ = 0;
  std::array<double, size_t(Stage::Count)> stageMs_{};
  double simMsPerTick_ = 0;
  int64_t clockTicks_ = 0;
  int64_t frames_ = 0;
  std::string scriptWhere_;                   ///< "FILE:LINE: " of the running script command
  size_t scriptNext_ = 0;                     ///< next script command
  std::optional<nlohmann::json> stagedJson_;  ///< scenario edited by `set`, applied by `regenerate`
};

}  // namespace sg::viewer
