// Playing a recording in the window: play/pause, single steps, seeking through snapshots
// (Player::seek), a speed factor, the recorded hashes checked as the ticks go by, and an optional
// B side for A/B comparison (a second recording, or the same one re-simulated under a variant via
// LockStepReplay) measured against A on every common tick.
#pragma once

#include <cstdint>
#include <memory>
#include <set>
#include <string>

#include "replay/divergence.h"
#include "replay/lockstep.h"
#include "replay/player.h"

namespace sg::viewer {

/// True for a path ending in ".sgr" or a file starting with the recording magic.
bool looksLikeRecording(const std::string& path);

class Playback {
 public:
  /// Reads and opens a recording. Throws sgr::RecordingError, whose message is the line the CLI
  /// prints (`simgrass replay FILE` shows the same text after its "simgrass replay: ").
  static std::unique_ptr<Playback> open(const std::string& path, int threads);

  /// A/B: B is a second recording (same time step as A) ...
  void attachRecording(const std::string& path);
  /// ... or A's recording re-simulated under `variant` ("interp=2", "dt=1/120"). Both throw
  /// sgr::RecordingError or std::invalid_argument with a one-line message.
  void attachVariant(const std::string& variant);

  const sgr::Recording& recording() const { return *rec_; }
  SimWorld& world() { return player_->world(); }
  /// Where the played world's grass stages run (Player::setPhysics): "" or why not.
  std::string setPhysics(PhysicsPath path) { return player_->setPhysics(path); }
  const Scenario& scenario() const { return player_->scenario(); }
  int64_t tick() const { return player_->tick(); }
  int64_t lastTick() const { return rec_->lastTick(); }

  bool playing = false;
  double speed = 1;  ///< recorded ticks per tick of wall-clock time (0.25 ... 8)

  /// Plays for `wallTicks` ticks' worth of wall-clock time (1 in a scripted frame) at `speed`;
  /// pauses at the end. Does nothing while a seek or step is pending (work() runs it). Returns
  /// false with *error on a fault or a damaged snapshot.
  bool advance(double wallTicks, std::string* error);
  /// Starts stepping n ticks (stops at the end), each one's hash checked: the steps run in work(),
  /// a frame's budget at a time (a step of 100000000 ticks never freezes the window).
  bool step(int64_t n, std::string* error);
  /// Starts moving to tick t (clamped to the recording, so never past lastTick()): the nearest
  /// snapshot is restored at once, the ticks from there to t run in work().
  bool seek(int64_t t, std::string* error);
  /// A seek or step is under way, or B catching up with A after a seek (target() is where A goes).
  bool busy() const { return target_ >= 0 || catchingUpB_; }
  int64_t target() const { return target_ >= 0 ? target_ : tick(); }
  /// Stops a pending seek or step where it stands (a consistent state: a whole tick); B stays
  /// unmeasured until the next step or seek.
  void cancel() {
    target_ = -1;
    if (catchingUpB_) measured_ = false;
    catchingUpB_ = false;
  }
  /// Runs a pending seek or step for about `seconds` of wall time (at least one tick). Returns
  /// false with *error (one line) on a fault or a damaged snapshot; the pending move then stops.
  bool work(double seconds, std::string* error);

  // ---- the recorded hashes ----
  int64_t hashesOk() const { return int64_t(okTicks_.size()); }
  int64_t firstMismatchTick() const { return firstMismatch_; }
  const std::string& mismatchText() const { return mismatchText_; }
  /// False under a variant that changes the state (A is always recorded settings).
  bool hashesComparable() const { return player_->sameSettingsAsRecorded(); }

  // ---- A/B ----
  bool hasB() const { return b_ != nullptr; }
  SimWorld& worldB() { return b_->world(); }
  const Scenario& scenarioB() { return b_->player().scenario(); }
  const std::string& labelB() const { return labelB_; }
  /// B's tick in A's time base (B lags by up to mergedTicks()-1 when its step is coarser).
  int64_t tickB() const { return b_->recordedTick(); }
  /// The divergence at the last common tick (valid when measured()).
  bool measured() const { return measured_; }
  const TickDivergence& divergence() const { return last_; }
  /// The first divergent tick of the whole run, found as `simgrass diff` and `compare` find it:
  /// a scan of every common tick from the start (two worlds of its own, beside A and B, so seeks
  /// never change it), by hash when the two runs promise the same states, else by observation.
  /// -1 while the scan has found none (scanDone() says whether it has finished).
  int64_t firstDivergentTick() const { return scanFirst_; }
  bool scanDone() const { return !b_ || scanDone_; }
  int64_t scannedTo() const { return scanTo_; }
  const char* divergenceBy() const { return scanByHash_ ? "hash" : "observation"; }
  /// Runs the scan for about `seconds` of wall time (at least one common tick).
  void scanWork(double seconds);
  const Observation& observationA() const { return obsA_; }
  const Observation& observationB() const { return obsB_; }

 private:
  Playback() = default;
  void checkHash();
  void buildB();
  void syncB();
  int64_t commonTickB() const;
  bool rewindB(int64_t target, std::string* why);
  void measureB();
  bool beginCatchUpB(std::string* why);
  std::unique_ptr<sgr::Recording> rec_, recB_;
  std::unique_ptr<Player> player_;
  RecordedHashes* hashes_ = nullptr;
  std::unique_ptr<RecordedHashes> hashesOwned_;
  int threads_ = 1;
  double accumulator_ = 0;      ///< recorded ticks not yet run
  int64_t target_ = -1;         ///< where a pending seek or step goes (-1: none)
  bool catchingUpB_ = false;    ///< after a seek: B steps towards A's tick in work()'s slices
  bool checkEachTick_ = false;  ///< step: every tick's hash checked and B synced; seek: only the last
  std::set<int64_t> okTicks_;
  int64_t firstMismatch_ = -1;
  std::string mismatchText_;
  // B side.
  std::unique_ptr<LockStepReplay> b_;
  VariantSettings variantB_;
  std::string labelB_;
  bool measured_ = false;
  TickDivergence last_;
  Observation obsA_, obsB_;
  // The divergence scan.
  std::unique_ptr<LockStepReplay> scanA_, scanB_;
  Observation scanObsA_, scanObsB_;
  int64_t scanTo_ = -1, scanFirst_ = -1;
  bool scanDone_ = false, scanByHash_ = false;
};

}  // namespace sg::viewer
