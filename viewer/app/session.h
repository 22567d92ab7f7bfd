// The live simulated session: the world, every tick's input since tick 0, the recorder. Panel
// edits never touch a running world: they edit the scenario's JSON text and build a new Session
// from it (the text is what a recording embeds, so an edited session still records and verifies).
#pragma once

#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "replay/recorder.h"
#include "replay/stage_clock.h"
#include "sim/world/world.h"
#include "viewer/app/input_history.h"

namespace sg::viewer {

class Session {
 public:
  Scenario scenario;
  std::vector<sgr::EmbeddedFile> files;
  std::string scenarioDir;  ///< folder the scenario's relative file names resolve against
  std::unique_ptr<SimWorld> world;
  InputHistory history;  ///< history[t]: the input of tick t (runs of equal inputs)
  std::unique_ptr<Recorder> recorder;
  std::string recordPath;
  int threads = 1;
  StageClock clock;
  /// Where the grass stages of this session's worlds run (docs/gpu-physics.md): the live world
  /// and every world the session makes later (a seek from tick 0, a recording's catch-up).
  PhysicsPath physics = PhysicsPath::Cpu;

  /// Moves the live world, and every later one, to `path`: "" on success, else why not (one
  /// line; the session unchanged). The GPU paths need the process's provider (the viewer
  /// registers its window's context once GL is up).
  std::string setPhysics(PhysicsPath path);

  /// Loads a scenario file (empty: the built-in meadow) and builds its world. Throws ScenarioError.
  static std::unique_ptr<Session> load(const std::string& path, int threads);

  /// A new session from edited scenario JSON text (same source name and folder), at tick 0; with
  /// `replayHistory` it then steps through this session's inputs so far (how the level-of-detail
  /// toggle keeps the session going). Throws ScenarioError; a fault while replaying becomes a
  /// ScenarioError naming the tick.
  std::unique_ptr<Session> rebuilt(const std::string& text, bool replayHistory) const;

  /// One tick with a new input (recorded when recording). Behind the history's end (after a step
  /// back or a seek), the inputs after this tick are dropped first: the session takes a new
  /// branch. A recording write that fails stops the recording, sets recordingError (one line)
  /// and the session goes on.
  StepResult step(const TickInput& input);

  // ---- the live timeline: pause, step back, scrub (docs/viewer.md "Live control") ----
  /// The ticks the session has inputs for: the world can be anywhere in 0 .. historyEnd().
  int64_t historyEnd() const { return int64_t(history.size()); }
  /// One tick forward along the history (the input that was given at this tick), not recorded:
  /// stepping forward again after stepping back. Requires world->tick() < historyEnd().
  StepResult replayNext();
  /// Moves the world to tick t (0 .. historyEnd()) from the nearest kept state at or before it
  /// and the recorded inputs. A running recording is stopped first (its file ends at the ticks it
  /// holds: going back would contradict it); *stopped says so. False with *error on a fault.
  bool seek(int64_t t, bool* stopped, std::string* error);
  /// States kept for seeking: one every snapshotEvery() ticks, at most kLiveSnapshotBytes in all
  /// (the spacing doubles when they would exceed it, so a long session keeps ~64 of them).
  int64_t snapshotEvery() const { return snapshotEvery_; }
  size_t snapshotCount() const { return snapshots_.size(); }
  static constexpr uint64_t kLiveSnapshotBytes = uint64_t(256) << 20;
  std::string recordingError;  ///< set by step() when the recording stopped on a write error
  /// A world of the scenario at tick 0 on the session's physics path. Throws std::runtime_error
  /// when the device refuses it.
  std::unique_ptr<SimWorld> makeSessionWorld() const;

  /// Records the whole session, from tick 0, to `path`: a fresh world replays the inputs so far
  /// under a Recorder (a recording must start from a state a replay can build), must reach the
  /// live world's hash, and then takes its place.
  bool startRecording(const std::string& path, std::string* error);
  /// Writes END and prints "recorded   N ticks to PATH (hash H)".
  bool stopRecording(std::string* error);

 private:
  void keepSnapshot();
  std::vector<std::pair<int64_t, std::vector<uint8_t>>> snapshots_;  ///< (tick, state), increasing ticks
  int64_t snapshotEvery_ = 60;
};

/// The scenario text with one value replaced: `dotted` is a path such as "field.patchesX" or
/// "bodies.gravity" (a list takes an index up to its size; the size appends), `value` any JSON
/// value. Throws ScenarioError (file, "$.dotted", expected) when the text is not an object, the
/// path or value breaks EditLimits (text.h) or the value is not JSON; echoed text is truncated.
std::string editScenarioText(const std::string& text, const std::string& sourceName, const std::string& dotted,
                             const std::string& valueJson);

/// The same edit on an already parsed scenario (what repeated `set` lines stage, parsed once).
void editScenarioJson(nlohmann::json* doc, const std::string& sourceName, const std::string& dotted,
                      const std::string& valueJson);
/// Parses scenario text for editing (depth bounded first). Throws ScenarioError unless an object.
nlohmann::json parseScenarioJsonForEdit(const std::string& text, const std::string& sourceName);

}  // namespace sg::viewer
