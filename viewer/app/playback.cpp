#include "viewer/app/playback.h"

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "replay/format/sgr_reader.h"
#include "replay/input_file.h"
#include "viewer/app/text.h"

namespace sg::viewer {

bool looksLikeRecording(const std::string& path) {
  // A `.sgr` name is a recording (its reader names what is wrong with it); otherwise the magic
  // decides, probed without blocking (sgr::hasRecordingMagic).
  if (path.size() >= 4 && path.compare(path.size() - 4, 4, ".sgr") == 0) return true;
  return sgr::hasRecordingMagic(path);
}

std::unique_ptr<Playback> Playback::open(const std::string& path, int threads) {
  std::unique_ptr<Playback> p(new Playback());
  p->threads_ = threads;
  p->rec_ = std::make_unique<sgr::Recording>(sgr::readRecording(path));
  if (p->rec_->truncated)  // the CLI's warning: what is there still plays
    std::fprintf(stderr,
                 "simgrass-viewer: warning: %s: byte %" PRIu64 ": expected %s; playing the %" PRId64
                 " ticks before it\n",
                 path.c_str(), p->rec_->truncatedAt, p->rec_->truncatedExpected.c_str(), p->rec_->lastTick());
  p->player_ = std::make_unique<Player>(*p->rec_, threads);
  p->hashesOwned_ = std::make_unique<RecordedHashes>(*p->rec_);
  p->hashes_ = p->hashesOwned_.get();
  p->checkHash();
  return p;
}

void Playback::attachRecording(const std::string& path) {
  recB_ = std::make_unique<sgr::Recording>(sgr::readRecording(path));
  const Rational dtA = recordedTimeStep(*rec_), dtB = recordedTimeStep(*recB_);
  if (!(dtA == dtB))
    throw std::invalid_argument(path + ": expected a recording with A's time step " + dtA.toString() + ", got " +
                                dtB.toString());
  variantB_ = {};
  labelB_ = path;
  buildB();
}

void Playback::attachVariant(const std::string& variant) {
  variantB_ = VariantSettings::parse(variant);
  recB_.reset();
  labelB_ = "variant " + variantB_.describe();
  buildB();
}

/// (Re)builds B at tick 0 and checks that its observations compare with A's.
void Playback::buildB() {
  b_ = std::make_unique<LockStepReplay>(recB_ ? *recB_ : *rec_, threads_, variantB_);
  player_->world().observe(obsA_);
  b_->world().observe(obsB_);
  const std::string why = observationMismatch(obsA_, obsB_);
  if (!why.empty()) {
    b_.reset();
    throw std::invalid_argument(labelB_ + ": expected the same meadow and bodies as A, got " + why);
  }
  measured_ = false;
  // The scan: its own A (the recording at its settings, as compare's reference) and its own B.
  scanA_ = std::make_unique<LockStepReplay>(*rec_, threads_);
  scanB_ = std::make_unique<LockStepReplay>(recB_ ? *recB_ : *rec_, threads_, variantB_);
  scanTo_ = scanFirst_ = -1;
  scanDone_ = false;
  scanByHash_ = VariantSettings::resolvedFrom(scanB_->player().scenario())
                    .mustBeIdenticalTo(VariantSettings::resolvedFrom(scanA_->player().scenario()));
  syncB();
}

void Playback::scanWork(double seconds) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const int64_t m = scanB_ ? scanB_->mergedTicks() : 1;
  const int64_t last = std::min(rec_->lastTick(), recB_ ? recB_->lastTick() : rec_->lastTick()) / m * m;
  while (scanB_ && !scanDone_) {
    const int64_t target = scanTo_ < 0 ? 0 : scanTo_ + m;
    if (target > last) {
      scanDone_ = true;
      break;
    }
    if (!scanA_->advanceTo(target).ok || !scanB_->advanceTo(target).ok) {  // a fault: the scan ends there
      scanDone_ = true;
      break;
    }
    scanA_->world().observe(scanObsA_);
    scanB_->world().observe(scanObsB_);
    const TickDivergence d =
        measureDivergence(scanObsA_, scanObsB_, scanA_->world().stateHash() == scanB_->world().stateHash());
    scanTo_ = target;
    if (scanByHash_ ? !d.identical : d.observedDifference()) {
      scanFirst_ = target;
      scanDone_ = true;
    }
    if (std::chrono::duration<double>(Clock::now() - start).count() >= seconds) break;
  }
  if (scanDone_) scanA_.reset(), scanB_.reset();  // the worlds' memory back
}

/// B's target for A's tick: the last common tick at or before it (B may end earlier).
int64_t Playback::commonTickB() const {
  const int64_t m = b_->mergedTicks();
  return std::min(tick() / m * m, (recB_ ? recB_->lastTick() : rec_->lastTick()) / m * m);
}

/// Moves B back when it is past `target`: to its nearest snapshot (or its start) at or before
/// it, restoring only (the steps from there are syncB's or work()'s). False, B unmeasured, when
/// B's snapshot is damaged or the restore fails.
bool Playback::rewindB(int64_t target, std::string* why) {
  if (target >= b_->recordedTick()) return true;
  try {
    if (b_->mergedTicks() == 1 && b_->substeps() == 1) {
      const sgr::Recording& r = recB_ ? *recB_ : *rec_;
      const sgr::SnapshotInfo* snap = b_->player().sameSettingsAsRecorded() ? r.snapshotAtOrBefore(target) : nullptr;
      const StepResult step = b_->player().seek(snap ? snap->tick : r.header.startTick);
      if (!step.ok && why) *why = labelB_ + ": " + step.error.message();
      return step.ok;
    }
    b_ = std::make_unique<LockStepReplay>(recB_ ? *recB_ : *rec_, threads_, variantB_);
    return true;
  } catch (const std::exception& e) {  // sgr::RecordingError: a damaged snapshot of B
    if (why) *why = e.what();
    return false;
  }
}

/// Measures A against B (B at A's tick; else B stays unmeasured).
void Playback::measureB() {
  const int64_t t = tick();
  if (b_->recordedTick() != t) {
    measured_ = false;
    return;
  }
  player_->world().observe(obsA_);
  b_->world().observe(obsB_);
  last_ = measureDivergence(obsA_, obsB_, player_->world().stateHash() == b_->world().stateHash());
  measured_ = true;
}

/// Brings B to A's tick (or the last common tick before it) and measures the divergence there,
/// at once: for single steps, where B is at most one step behind.
void Playback::syncB() {
  if (!b_) return;
  const int64_t target = commonTickB();
  measured_ = false;
  if (!rewindB(target, nullptr) || !b_->advanceTo(target).ok) return;
  measureB();
}

/// After a seek of A: B rewinds now and catches up in work()'s slices (a variant B has no
/// snapshots and replays from its start). False with *why when B cannot rewind (B unmeasured).
bool Playback::beginCatchUpB(std::string* why) {
  measured_ = false;
  catchingUpB_ = b_ && rewindB(commonTickB(), why);
  return !b_ || catchingUpB_;
}

void Playback::checkHash() {
  if (!player_->sameSettingsAsRecorded()) return;
  const int64_t t = tick();
  const std::optional<uint64_t> want =
      t == rec_->header.startTick ? std::optional<uint64_t>(rec_->header.initialStateHash) : hashes_->at(t);
  if (!want) return;
  const uint64_t got = player_->world().stateHash();
  if (*want == got) {
    okTicks_.insert(t);
    return;
  }
  if (firstMismatch_ >= 0 && firstMismatch_ <= t) return;
  firstMismatch_ = t;
  mismatchText_ = rec_->file + ": hash mismatch at tick " + std::to_string(t) + ": recorded " + hex(*want) +
                  ", replayed " + hex(got);
  std::fprintf(stderr, "simgrass-viewer: %s\n", mismatchText_.c_str());
}

bool Playback::step(int64_t n, std::string* error) {
  if (n <= 0 || tick() >= lastTick()) return true;
  target_ = tick() + std::min(n, lastTick() - tick());
  checkEachTick_ = true;
  return work(0, error);  // one tick now (a single step is immediate), the rest frame by frame
}

bool Playback::advance(double wallTicks, std::string* error) {
  if (!playing || busy()) return true;
  accumulator_ += wallTicks * speed;
  const int64_t n = int64_t(std::floor(accumulator_));
  accumulator_ -= double(n);
  bool ok = true;
  for (int64_t i = 0; ok && i < n && tick() < lastTick(); ++i) {
    target_ = tick() + 1;
    checkEachTick_ = true;
    ok = work(0, error);
  }
  if (!ok) playing = false;
  if (tick() >= lastTick()) {
    playing = false;
    accumulator_ = 0;
  }
  return ok;
}

bool Playback::seek(int64_t t, std::string* error) {
  t = std::clamp<int64_t>(t, rec_->header.startTick, lastTick());
  accumulator_ = 0;
  cancel();
  // The jump now (what Player::seek does first): the nearest snapshot at or before t, or the
  // start, unless stepping on from here is shorter. Player::seek to that tick restores it and
  // steps nothing; the steps from there to t are work()'s.
  const sgr::SnapshotInfo* snap = hashesComparable() ? rec_->snapshotAtOrBefore(t) : nullptr;
  const int64_t from = tick();
  const bool forwardIsShorter = from <= t && (!snap || snap->tick <= from);
  try {
    if (!forwardIsShorter) {
      const StepResult r = player_->seek(snap ? snap->tick : rec_->header.startTick);
      if (!r.ok) {
        *error = r.error.message();
        return false;
      }
    }
  } catch (const sgr::RecordingError& e) {
    *error = e.what();
    return false;
  }
  if (tick() == t) {
    checkHash();
    return beginCatchUpB(error) && work(0, error);
  }
  target_ = t;
  checkEachTick_ = false;
  return work(0, error);
}

bool Playback::work(double seconds, std::string* error) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  while (busy()) {
    if (target_ >= 0 && tick() < target_) {
      StepResult r;
      std::string why;
      try {
        r = player_->stepForward();
      } catch (const sgr::RecordingError& e) {
        r.ok = false;
        why = e.what();
      }
      if (!r.ok) {
        *error = why.empty() ? r.error.message() : why;
        cancel();
        playing = false;
        return false;
      }
      if (checkEachTick_) {
        checkHash();
        syncB();
      }
    }
    if (target_ >= 0 && tick() >= target_) {
      target_ = -1;
      if (!checkEachTick_) {
        checkHash();
        if (!beginCatchUpB(error)) return false;
      }
    } else if (target_ < 0 && catchingUpB_) {
      // B, one of its steps at a time (m recorded ticks), up to A's tick.
      const int64_t bt = commonTickB();
      if (b_->recordedTick() < bt && !b_->advanceTo(b_->recordedTick() + b_->mergedTicks()).ok) catchingUpB_ = false;
      if (catchingUpB_ && b_->recordedTick() >= bt) {
        catchingUpB_ = false;
        measureB();
      }
    }
    if (std::chrono::duration<double>(Clock::now() - start).count() >= seconds) break;
  }
  return true;
}

}  // namespace sg::viewer
