// Playing a recording back: rebuilds the world from the embedded scenario (optionally under a
// variant), then steps it with the recorded inputs, seeks through snapshots and verifies hashes.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "replay/format/sgr_reader.h"
#include "replay/variant.h"
#include "sim/world/world.h"

namespace sg {

/// The scenario stored in a recording, parsed with its embedded files and the recorded variant
/// (then `override` on top). Throws sgr::RecordingError (offset of HEAD) when it no longer loads.
Scenario recordedScenario(const sgr::Recording& recording, const VariantSettings& override = {});

struct VerifyReport {
  bool ok = true;
  int64_t ticks = 0;  ///< ticks replayed
  /// Ticks whose recorded hashes (the header's initial hash, CHCK, SNAP, END) matched, each tick
  /// once: a complete verify of a recording with the same settings reaches
  /// Recording::hashedTicks().
  int64_t checksVerified = 0;
  int64_t firstMismatchTick = -1;
  uint64_t expectedHash = 0, actualHash = 0;
  std::optional<SimError> fault;  ///< the replay faulted where the recording did not
  /// The recording's END says the step from its last tick faulted, and the replay stepped it
  /// without a fault (firstMismatchTick is the tick after; no hash was compared there).
  bool recordedFaultMissing = false;
};

/// What a verify says when VerifyReport::recordedFaultMissing: the step from `end.tick` that the
/// recording says faulted (with its message, if it has one, echoed bounded) stepped cleanly.
std::string describeRecordedFaultMissing(const sgr::EndInfo& end);

class Player {
 public:
  /// Builds the world. With a non-empty `variant`, the recorded inputs drive a different setup
  /// (then CHCK hashes are not expected to match unless the variant must be bit-identical).
  /// Throws std::invalid_argument ("physics=gpu: ...") when the variant's physics path cannot run
  /// this scenario.
  explicit Player(const sgr::Recording& recording, int threads = 1, const VariantSettings& variant = {});

  const sgr::Recording& recording() const { return recording_; }
  const Scenario& scenario() const { return scenario_; }
  SimWorld& world() { return *world_; }
  int64_t tick() const { return world_->tick(); }
  /// True when the world runs with the recorded settings (hashes are comparable).
  bool sameSettingsAsRecorded() const { return sameSettings_; }
  /// The largest binary state this scenario can have: a snapshot declaring more is refused
  /// before it is decompressed.
  uint64_t largestStateBytes() const { return largestStateBytes_; }

  /// Steps once with the recorded input for the current tick.
  StepResult stepForward(StageObserver* observer = nullptr);
  /// Moves to `tick` (0 ≤ tick ≤ recording().lastTick()): restores the latest snapshot at or
  /// before it (or restarts from the start) unless stepping on from the current tick is shorter.
  /// Returns the fault when a step fails. Throws sgr::RecordingError for a damaged snapshot.
  StepResult seek(int64_t tick, const std::function<void(int64_t)>& progress = {});
  /// Replays from the start to the end, comparing every CHCK, SNAP and END hash; each snapshot is
  /// also decompressed (and, under the recorded settings, compared byte for byte with the replayed
  /// state). Throws sgr::RecordingError for a damaged snapshot.
  VerifyReport verify(const std::function<void(int64_t)>& progress = {});
  /// Moves the world, and every world this player builds later, to `path`: "" on success, else
  /// why not (one line; the player unchanged). A float recording stays on the CPU: its hashes are
  /// a promise about bits the device's float does not keep (docs/gpu-physics.md).
  std::string setPhysics(PhysicsPath path);

 private:
  void restart();
  void buildWorld();
  const sgr::Recording& recording_;
  Scenario scenario_;
  int threads_;
  std::optional<PhysicsPath> physics_;  ///< the variant's, put on every world this player builds
  bool sameSettings_ = true;
  bool exactSettings_ = true;  ///< every setting as recorded (threads aside): snapshots compare byte for byte
  uint64_t largestStateBytes_ = 0;
  std::unique_ptr<SimWorld> world_;
};

}  // namespace sg
