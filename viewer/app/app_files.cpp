// Opening files and applying panel edits: a scenario or recording replaces what runs, or the
// edited scenario text becomes a new Session. Failures keep the old session and show the CLI's
// one-line error (stderr and the Error window).
#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "viewer/app/app.h"

namespace sg::viewer {

// ---- files and sessions ---------------------------------------------------------------------

bool App::openFile(const std::string& path) {
  try {
    if (looksLikeRecording(path)) {
      std::unique_ptr<Playback> p = Playback::open(path, opt_.threads);
      play_ = std::move(p);
      if (live_->physics != PhysicsPath::Cpu)  // the path the live session ran on
        if (const std::string why = play_->setPhysics(live_->physics); !why.empty())
          showError(std::string("physics ") + physicsPathName(live_->physics) + ": " + why + " (playing on the CPU)");
      play_->playing = !scripted_;  // interactive: starts playing; scripts start paused (exact ticks)
      status_ = "playing " + path;
    } else {
      std::unique_ptr<Session> s = Session::load(path, opt_.threads);
      if (live_->recorder) {
        std::string e;
        if (!live_->stopRecording(&e)) showError(e);
      }
      const PhysicsPath physics = live_->physics;
      live_ = std::move(s);
      keepPhysics(physics);
      play_.reset();
      if (renderer_ && !live_->scenarioDir.empty()) renderer_->setAssetDirectory(live_->scenarioDir);
      status_ = "opened " + path;
    }
  } catch (const std::exception& e) {  // RecordingError, ScenarioError: the CLI's one line
    showError(e.what());
    return false;
  }
  settings_.remember(path);
  selected_ = 0;
  mowerOn_.clear();
  pendingCommands_.clear();
  accumulator_ = 0;
  paused_ = false;
  liveStepsPending_ = 0;
  dragging_ = following_ = false;
  previous_.tick = -1;
  errorText_.clear();
  stagedJson_.reset();  // `set` edits staged for the previous scenario
  resetEdits();
  extractScene(world(), scenario(), &scene_);
  cam_.camera = defaultCamera(scene_, world(), float(opt_.width) / float(opt_.height));
  cam_.eyeHeight = cam_.camera.y - groundHeight(world(), cam_.camera.x, cam_.camera.z);
  return true;
}

void App::resetEdits() {
  const Scenario& s = live_->scenario;
  ScenarioEdits e;
  e.damping = float(s.particles.damping.toDouble());
  e.upAcceleration = float(s.particles.acceleration[1].toDouble());
  e.constraintLength = float(s.particles.constraintLength.toDouble());
  e.gravityY = float(s.bodies.gravity[1].toDouble());
  e.scaleY = float(s.field.scaleY.toDouble());
  e.scaleXZ = float(s.field.scaleXZ.toDouble());
  e.patchesX = int(s.field.patchesX);
  e.patchesZ = int(s.field.patchesZ);
  e.interpolation = s.particles.interpolation;
  e.spacing = float(s.field.spacing.toDouble());
  e.cellSize = float(s.terrain.cellSize.toDouble());
  e.maxHeight = float(s.terrain.maxHeight.toDouble());
  e.model = int(s.particles.model);
  e.bladeFrequency = float(s.particles.blade.frequency.toDouble());
  e.bladeDampingRatio = float(s.particles.blade.dampingRatio.toDouble());
  e.trampleSeconds = float(s.particles.blade.trampleSeconds.toDouble());
  std::snprintf(e.heightmap, sizeof e.heightmap, "%s", s.terrain.heightmapPath.c_str());
  edits_ = e;
}

/// The live scenario's JSON with the panels' values written in. Numbers go in as decimal text
/// rounded to 6 significant digits, which the scenario parser reads exactly (Rational).
std::string App::editedScenarioText() const {
  nlohmann::json j = nlohmann::json::parse(live_->scenario.text, nullptr, false);
  if (!j.is_object()) j = nlohmann::json::object();
  auto round6 = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return nlohmann::json::parse(buf);
  };
  const Scenario& s = live_->scenario;
  j["particles"]["damping"] = round6(edits_.damping);
  j["particles"]["acceleration"] = {round6(s.particles.acceleration[0].toDouble()), round6(edits_.upAcceleration),
                                    round6(s.particles.acceleration[2].toDouble())};
  j["particles"]["constraintLength"] = round6(edits_.constraintLength);
  j["particles"]["interpolation"] = edits_.interpolation;
  // The grass model (docs/grass-models.md) under its new name; another model than the text's
  // starts from that model's initial velocity (the panel set its damping and acceleration).
  const int model = std::clamp(edits_.model, 0, 2);
  j["particles"].erase("constraintMode");
  j["particles"]["model"] = grassModelName(GrassModel(model));
  if (model != int(s.particles.writtenModel))
    j["particles"]["initialVelocity"] =
        model == int(GrassModel::Blade) ? nlohmann::json{0, 0, 0} : nlohmann::json{0.2, 0.2, 0.2};
  if (model == int(GrassModel::Blade))
    j["particles"]["blade"] = {{"frequency", round6(edits_.bladeFrequency)},
                               {"dampingRatio", round6(edits_.bladeDampingRatio)},
                               {"trampleSeconds", round6(edits_.trampleSeconds)}};
  else
    j["particles"].erase("blade");
  j["bodies"]["gravity"] = {round6(s.bodies.gravity[0].toDouble()), round6(edits_.gravityY),
                            round6(s.bodies.gravity[2].toDouble())};
  j["field"]["scaleY"] = round6(edits_.scaleY);
  j["field"]["scaleXZ"] = round6(edits_.scaleXZ);
  j["field"]["patchesX"] = edits_.patchesX;
  j["field"]["patchesZ"] = edits_.patchesZ;
  j["field"]["spacing"] = round6(edits_.spacing);
  if (edits_.gustScale != 1 || edits_.gustPeriodScale != 1) {
    nlohmann::json schedule = nlohmann::json::array();
    for (const WindGust& g : s.wind.schedule)
      schedule.push_back(
          {{"force",
            {round6(g.force[0].toDouble() * edits_.gustScale), round6(g.force[1].toDouble() * edits_.gustScale),
             round6(g.force[2].toDouble() * edits_.gustScale)}},
           {"duration", round6(g.duration.toDouble() * edits_.gustPeriodScale)}});
    j["wind"]["schedule"] = schedule;
  }
  if (edits_.heightmap[0] && edits_.heightmap != s.terrain.heightmapPath)
    j["terrain"] = {{"type", "heightmap"},
                    {"file", std::string(edits_.heightmap)},
                    {"cellSize", round6(edits_.cellSize)},
                    {"maxHeight", round6(edits_.maxHeight)}};
  // A heightmap name typed in the panel that is not UTF-8 becomes U+FFFD (a file-not-found line
  // later), never an exception out of the frame loop.
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
}

bool App::applyScenario(const std::string& text, bool replayHistory, const std::string& what) {
  std::unique_ptr<Session> next;
  try {
    next = live_->rebuilt(text, replayHistory);
  } catch (const std::exception& e) {
    showError(e.what());
    return false;
  }
  std::string note;
  if (live_->recorder) {
    // The recording's scenario text no longer describes the session: end it where it stands.
    std::string e;
    if (live_->stopRecording(&e))
      note = "; the recording " + live_->recordPath + " was stopped";
    else
      showError(e);
  }
  play_.reset();
  const PhysicsPath physics = live_->physics;
  live_ = std::move(next);
  keepPhysics(physics);
  status_ = what + (replayHistory ? " (inputs so far replayed)" : " (new world from tick 0)") + note;
  std::printf("%s\n", status_.c_str());
  std::fflush(stdout);
  errorText_.clear();
  mowerOn_.clear();
  pendingCommands_.clear();
  if (selected_ >= live_->world->counts().bodies) selected_ = 0;
  resetEdits();
  return true;
}

void App::keepPhysics(PhysicsPath path) {
  if (path == PhysicsPath::Cpu) return;
  if (const std::string why = live_->setPhysics(path); !why.empty())
    showError(std::string("physics ") + physicsPathName(path) + ": " + why + " (the new world runs on the CPU)");
}

}  // namespace sg::viewer
