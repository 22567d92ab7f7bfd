// The replay component's public interface (installed; find_package(SimGrass COMPONENTS replay)):
// record a session to a `.sgr` file, read what a recording holds, verify one by replaying it.
//
// A small facade over the recorder, the player and the format (replay/recorder.h, player.h,
// format/), which stay internal: their headers reach World<S> and Eigen, this one includes only
// the public sim headers (scenario, tick input) and the standard library, so a program using it
// needs neither Eigen nor zstd on its include path. Recordings made here are the recordings of
// `simgrass record` (same chunks, same defaults); `simgrass replay --verify` accepts them and
// verifyRecording() accepts theirs.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "sim/scenario/scenario.h"
#include "sim/world/tick_input.h"

namespace sg {

class SimWorld;  // sim/world/sim_world.h: include it to read a session's world

/// How a new recording is written (the defaults are `simgrass record`'s).
struct RecordingSettings {
  int threads = 1;  ///< worker threads; the recording is the same for any count
  std::optional<uint32_t>
      checkEvery;                ///< ticks between state hashes (0: none); unset: 1 up to ~130,000 patches, then fewer
  uint32_t snapshotEvery = 300;  ///< ticks between compressed state snapshots (0: none)
  // With both intervals 0, step() throws once 65,536 ticks would pass without an input naming a
  // tick (the reader's tick-span limit, docs/replay-format.md "Limits a reader enforces").
};

/// Where a session or a recording ended.
struct RecordingSummary {
  int64_t ticks = 0;       ///< the world's tick at the end
  uint64_t finalHash = 0;  ///< its state hash there
  uint64_t bytes = 0;      ///< size of the file written
  std::string error;       ///< the simulation fault that stopped it; empty when none
};

/// A live session being recorded. Owns its world; each step() records the input, steps the world
/// and writes the hashes and snapshots that fall due, so the file on disk is always readable up to
/// the last tick. finish() closes it with END; a session destroyed without finish() leaves a file
/// that reads as cut off (everything in it still verifies).
class RecordingSession {
 public:
  /// Loads a scenario file (empty path: the built-in thesis meadow) and embeds the heightmap it
  /// names, so the recording replays anywhere. Throws ScenarioError for a bad
  /// scenario, std::runtime_error ("path: why") when `output` cannot be written or is the scenario.
  static RecordingSession fromScenarioFile(const std::string& scenarioFile, const std::string& output,
                                           const RecordingSettings& settings = {});
  /// A scenario already parsed (parseScenario). It must name no heightmap file: a recording embeds
  /// the file's bytes, which a parsed Scenario no longer holds (use fromScenarioFile for those).
  /// Throws ScenarioError when it names one, std::runtime_error when `output` cannot be written.
  static RecordingSession fromScenario(const Scenario& scenario, const std::string& output,
                                       const RecordingSettings& settings = {});

  RecordingSession(RecordingSession&&) noexcept;
  RecordingSession& operator=(RecordingSession&&) noexcept;
  ~RecordingSession();

  /// Records `input` and advances one tick. Returns false once the simulation has faulted (then
  /// error() says where, and finish() records the fault); later calls do nothing and return false.
  /// Throws std::runtime_error when the file cannot be written, std::logic_error after finish().
  bool step(const TickInput& input);
  /// `ticks` steps with the scenario's own scripted input (its camera track and script).
  bool stepScripted(int64_t ticks);
  /// Writes END and closes the file. Further calls return the same summary.
  RecordingSummary finish();

  const Scenario& scenario() const;
  int64_t tick() const;
  uint64_t stateHash() const;
  const std::string& error() const;  ///< empty until a fault
  /// The world being recorded, read-only: stepping it directly would bypass the recording.
  const SimWorld& world() const;

 private:
  struct Impl;
  explicit RecordingSession(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// What a recording holds, read without simulating (`simgrass replay --info`).
struct RecordingInfo {
  std::string scenarioSource;  ///< the scenario file it was recorded from
  std::string scenarioText;    ///< the scenario JSON, verbatim
  std::string variant;         ///< resolved settings, "scalar=fx32 interp=1 ..."
  std::string buildId;         ///< the build that recorded it (informational)
  int64_t startTick = 0, lastTick = 0;
  uint32_t checkEvery = 0, snapshotEvery = 0;
  int64_t inputs = 0, checks = 0, snapshots = 0;  ///< chunks of each kind
  int64_t hashedTicks = 0;                        ///< ticks with a recorded hash (start, CHCK, SNAP, END), each once
  bool complete = false;                          ///< ends with END
  std::optional<uint64_t> finalHash;              ///< END's state hash, when it ended without a fault
  std::string fault;                              ///< the fault the recording stopped on; empty when none
};

/// Reads a recording's chunks (every checksum and field checked). Throws std::runtime_error
/// (sgr::RecordingError: the file, the byte offset and what was expected there) for a file that
/// cannot be read or is damaged. A file cut off mid-chunk reads up to its last complete chunk,
/// with complete = false.
RecordingInfo readRecordingInfo(const std::string& path);

/// The outcome of replaying a recording against every hash it holds.
struct VerifyResult {
  bool ok = true;             ///< every recorded hash matched (and a recorded fault recurred)
  int64_t ticks = 0;          ///< ticks replayed
  int64_t hashesChecked = 0;  ///< hashed ticks that matched (RecordingInfo::hashedTicks when all did)
  int64_t firstMismatchTick = -1;
  uint64_t expectedHash = 0, actualHash = 0;  ///< at firstMismatchTick, for a hash mismatch
  std::string error;  ///< the replay faulted where the recording did not, or the reverse (below)
  /// The recording says its last step faulted and the replay stepped it without a fault (no hash
  /// was compared there: expectedHash and actualHash stay 0).
  bool recordedFaultMissing = false;
  uint64_t finalHash = 0;  ///< the replayed state's hash where the replay stopped
};

/// Rebuilds the recorded world and replays it from start to end (`simgrass replay --verify`).
/// Throws std::runtime_error (sgr::RecordingError) for an unreadable or damaged recording,
/// including a snapshot that does not hold the replayed state.
VerifyResult verifyRecording(const std::string& path, int threads = 1);

}  // namespace sg
