// Script commands (--script, docs/viewer.md): each one does what a key or a panel does, so tests
// drive the same code paths; `print` is the line tests compare with the CLI.
#include <cinttypes>
#include <cstdio>

#include "replay/input_file.h"
#include "viewer/app/app.h"
#include "viewer/app/text.h"

namespace sg::viewer {

/// The `print` line: what tests compare with the CLI (state hash at a tick, counts, A/B numbers).
void App::printState() const {
  const WorldCounts c = world().counts();
  std::printf("state      tick %" PRId64 ", hash %s, patches %" PRId64 "x%" PRId64 ", bodies %" PRId64, world().tick(),
              hex(world().stateHash()).c_str(), c.patchesX, c.patchesZ, c.bodies);
  if (play_) {
    std::printf(", playback %" PRId64 "/%" PRId64 ", hashes ok %" PRId64 ", mismatch %" PRId64, play_->tick(),
                play_->lastTick(), play_->hashesOk(), play_->firstMismatchTick());
    if (play_->hasB())
      std::printf(", ab tick %" PRId64 ", tipMax %.9g m, tipRms %.9g m, first divergent tick %" PRId64, play_->tickB(),
                  play_->measured() ? play_->divergence().tipMax : -1.0,
                  play_->measured() ? play_->divergence().tipRms : -1.0, play_->firstDivergentTick());
  }
  std::printf("\n");
  std::fflush(stdout);
}

/// The `status` lines: the status line and the error window's text, as the window shows them
/// (tests check that a bad file or edit reaches the UI, not only stderr).
void App::printStatus() const {
  std::printf("status     %s\n", status_.empty() ? "-" : status_.c_str());
  std::printf("error      %s\n", errorText_.empty() ? "-" : errorText_.c_str());
  const Camera& c = cam_.camera;
  std::printf("camera     %.4f %.4f %.4f %.3f %.3f\n", c.x, c.y, c.z, c.yawDegrees, c.pitchDegrees);
  const WorldCounts counts = world().counts();
  if (counts.lodWindow)
    std::printf("window     %" PRId64 " %" PRId64 "\n", counts.windowOriginI, counts.windowOriginJ);
  else
    std::printf("window     off\n");
  std::printf("view       panels %s, help %s, %s, selected %d%s, grass %s\n", uiHidden_ ? "hidden" : "shown",
              helpShown_ ? "shown" : "hidden", paused_ ? "paused" : "running", selected_,
              following_ ? " (followed)" : "", grassFollows_ ? "follows the camera" : "frozen");
  std::fflush(stdout);
}

// ---- script -----------------------------------------------------------------------------------

int App::runCommand(const ScriptCommand& c) {
  const std::string& where = scriptWhere_;
  std::string error;
  auto failWith = [&](int code, const std::string& what) {
    std::fprintf(stderr, "simgrass-viewer: %s%s\n", where.c_str(), what.c_str());
    return code;
  };
  auto bad = [&](const std::string& what) { return failWith(kExitBadInput, what); };
  auto needPlayback = [&](const char* cmd) {
    return bad(std::string(cmd) + ": expected a recording to play back (open a .sgr), the viewer runs a live session");
  };
  using K = ScriptCommand::Kind;
  switch (c.kind) {
    case K::Frames:
      return kGoOn;  // handled by the caller
    case K::Key:     // through the event queue, as the keyboard's callback does
      deliver(InputEvent{InputEvent::Kind::Key, c.key, c.down, false, 0});
      return kGoOn;
    case K::Tap:  // down and up before the next frame: the tap must still act (and drive a frame)
      deliver(InputEvent{InputEvent::Kind::Key, c.key, true, false, 0});
      deliver(InputEvent{InputEvent::Kind::Key, c.key, false, false, 0});
      return kGoOn;
    case K::Mouse:
      cursorX_ = c.camera[0];
      cursorY_ = c.camera[1];
      return kGoOn;
    case K::Button:
      deliver(InputEvent{InputEvent::Kind::MouseButton, c.key, c.down, false, 0});
      return kGoOn;
    case K::Back:
      if (play_) {
        play_->playing = false;
        if (!play_->seek(std::max<int64_t>(play_->recording().header.startTick, play_->tick() - c.count), &error))
          showError(error);
      } else {
        stepLiveBack(c.count);
      }
      return kGoOn;
    case K::Restart:
      if (play_) return bad("restart: expected a live session (a playback goes back with 'seek 0')");
      restartLive();
      return kGoOn;
    case K::Physics: {
      const PhysicsPath path = PhysicsPath(c.count);
      if (const std::string why = play_ ? play_->setPhysics(path) : live_->setPhysics(path); !why.empty())
        showError(std::string("physics ") + physicsPathName(path) + ": " + why);  // as the panel: the session goes on
      else
        status_ =
            std::string("grass stages on ") + physicsPathName(path) + " from tick " + std::to_string(world().tick());
      return kGoOn;
    }
    case K::Camera:
      cam_.place(c.camera[0], c.camera[1], c.camera[2], c.camera[3], c.camera[4], ground());
      return kGoOn;
    case K::Select:
      if (c.count >= world().counts().bodies)
        return bad("select " + std::to_string(c.count) + ": the scenario has " +
                   std::to_string(world().counts().bodies) + " bodies");
      selected_ = int(c.count);
      return kGoOn;
    case K::RecordStart:
      if (play_) return bad("record start: a playback is not recorded again");
      if (live_->recorder) return bad("record start: expected no recording running, got one to " + live_->recordPath);
      if (const std::string in = inputNamed(c.path); !in.empty())
        return bad(c.path + ": expected an output file other than the input " + in);
      if (!live_->startRecording(c.path, &error)) return failWith(kExitFailure, error);
      return kGoOn;
    case K::RecordStop:
      if (!live_->recorder) return bad("record stop: expected a recording running, got none");
      if (!live_->stopRecording(&error)) return failWith(kExitFailure, error);
      return kGoOn;
    case K::Screenshot:
      if (const std::string in = inputNamed(c.path); !in.empty())
        return bad(c.path + ": expected an output file other than the input " + in);
      if (!screenshot(c.path, &error)) return failWith(kExitFailure, error);
      return kGoOn;
    case K::Quit:
      return kExitOk;
    case K::Play:
    case K::Pause:
      if (!play_) {  // live: resume / pause the session
        paused_ = c.kind == K::Pause;
        if (!paused_) status_.clear();
        return kGoOn;
      }
      play_->playing = c.kind == K::Play;
      return kGoOn;
    case K::Step:
      if (!play_) {  // live: the next `frames` run these ticks, then stay paused
        stepLive(c.count);
        return kGoOn;
      }
      play_->playing = false;
      if (!play_->step(c.count, &error)) showError(error);
      return kGoOn;
    case K::Seek:
      if (!play_) return needPlayback("seek");
      if (c.count > play_->lastTick())
        return bad("seek " + std::to_string(c.count) + ": expected a tick from 0 to " +
                   std::to_string(play_->lastTick()));
      if (!play_->seek(c.count, &error)) showError(error);
      return kGoOn;
    case K::Speed:
      if (!play_) return needPlayback("speed");
      play_->speed = c.number;
      return kGoOn;
    case K::AbView:
      if (!play_ || !play_->hasB()) return bad("ab: expected A/B mode (--ab B.sgr or --ab-variant SETTINGS)");
      abView_ = c.count ? AbView::Overlay : AbView::Side;
      return kGoOn;
    case K::Open:
      openFile(c.path);
      return kGoOn;  // a bad file: the error shown, the session goes on
    case K::Set:
      try {
        // Staged like a panel edit: the next `regenerate` builds the world from it. Staged as
        // parsed JSON, so a script of many `set` lines costs one parse and one dump.
        if (!stagedJson_) stagedJson_ = parseScenarioJsonForEdit(live_->scenario.text, live_->scenario.sourceName);
        editScenarioJson(&*stagedJson_, live_->scenario.sourceName, c.path, c.value);
      } catch (const std::exception& e) {
        return bad(e.what());
      }
      return kGoOn;
    case K::Regenerate: {
      std::string text = live_->scenario.text;
      if (stagedJson_) text = stagedJson_->dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
      stagedJson_.reset();
      if (text.size() > InputLimits::kScenarioBytes) {  // what a scenario file may hold
        showError(live_->scenario.sourceName + ": $: expected an edited scenario of at most " +
                  std::to_string(InputLimits::kScenarioBytes) + " bytes, got " + std::to_string(text.size()));
        return kGoOn;
      }
      applyScenario(text, false, "regenerated");  // a bad edit: the error shown, the session goes on
      return kGoOn;
    }
    case K::Lod: {
      std::string text;
      try {
        text = editScenarioText(live_->scenario.text, live_->scenario.sourceName, "lod.mode",
                                c.count ? "\"window\"" : "\"off\"");
      } catch (const std::exception& e) {
        return bad(e.what());
      }
      applyScenario(text, true, c.count ? "level of detail on" : "level of detail off");
      return kGoOn;
    }
    case K::Print:
      printState();
      return kGoOn;
    case K::Status:
      printStatus();
      return kGoOn;
  }
  return kGoOn;
}

int App::runScript(const std::vector<ScriptCommand>& script, int64_t* frames) {
  while (true) {
    // A seek or step under way runs frame by frame (App::simulate); the script waits for it, so
    // the next command sees the tick it asked for.
    if (play_ && play_->busy()) {
      *frames = 0;
      return kGoOn;
    }
    // `print` in A/B mode reports the whole run's first divergent tick: it waits for the scan.
    if (scriptNext_ < script.size() && script[scriptNext_].kind == ScriptCommand::Kind::Print && play_ &&
        play_->hasB() && !play_->scanDone()) {
      *frames = 0;
      return kGoOn;
    }
    if (scriptNext_ >= script.size()) return kExitOk;  // the end of the script quits
    const ScriptCommand& c = script[scriptNext_++];
    scriptWhere_ = opt_.script + ":" + std::to_string(c.line) + ": ";
    if (c.kind == ScriptCommand::Kind::Frames) {
      *frames = c.count;
      if (c.count > 0) return kGoOn;
      continue;
    }
    const int code = runCommand(c);
    if (code != kGoOn) return code;
  }
}

}  // namespace sg::viewer
