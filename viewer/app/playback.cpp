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
  if (path.size() >= 4 && path.compare(path.size() - 4, 4, ".sgr") == 0) return true;
  // The bounded reader: a FIFO, a directory or a device is no recording (and opening it never
  // blocks); the scenario loader then names what it is.
  InputFile in;
  std::string expected;
  uint8_t magic[sizeof sgr::kMagic] = {};
  return in.open(path, InputLimits::kRecordingBytes, &expected) && in.size() >= sizeof magic &&
         in.readAt(0, magic, &expected) && std::memcmp(magic, sgr::kMagic, sizeof magic) == 0;
}

sgr::Recording readRecordingFile(const std::string& path) {
  std::vector<uint8_t> bytes;
  std::string expected;
  if (!readInputFile(path, InputLimits::kRecordingBytes, &bytes, &expected))
    throw sgr::RecordingError(path, 0, expected);
  return sgr::parseRecording(std::move(bytes), path);
}

std::unique_ptr<Playback> Playback::open(const std::string& path, int threads) {
  std::unique_ptr<Playback> p(new Playback());
  p->threads_ = threads;
  p->rec_ = std::make_unique<sgr::Recording>(readRecordingFile(path));
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
  recB_ = std::make_unique<sgr::Recording>(readRecordingFile(path));
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
  firstDivergent_ = -1;
  syncB();
}

/// Brings B to A's tick (or the last common tick before it) and measures the divergence there.
void Playback::syncB() {
  if (!b_) return;
  const int64_t t = tick();
  const int64_t m = b_->mergedTicks();
  int64_t target = t / m * m;
  target = std::min(target, (recB_ ? recB_->lastTick() : rec_->lastTick()) / m * m);
  if (target < b_->recordedTick()) {
    if (m == 1 && b_->substeps() == 1) {
      const StepResult r = b_->player().seek(target);
      if (!r.ok) return;
    } else {
      b_ = std::make_unique<LockStepReplay>(recB_ ? *recB_ : *rec_, threads_, variantB_);
    }
  }
  if (!b_->advanceTo(target).ok || b_->recordedTick() != t) {
    measured_ = false;
    return;
  }
  player_->world().observe(obsA_);
  b_->world().observe(obsB_);
  last_ = measureDivergence(obsA_, obsB_, player_->world().stateHash() == b_->world().stateHash());
  measured_ = true;
  if (last_.observedDifference() && (firstDivergent_ < 0 || t < firstDivergent_)) firstDivergent_ = t;
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
  target_ = -1;
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
    syncB();
    return true;
  }
  target_ = t;
  checkEachTick_ = false;
  return work(0, error);
}

bool Playback::work(double seconds, std::string* error) {
  if (!busy()) return true;
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  do {
    if (tick() >= target_) break;
    StepResult r;
    try {
      r = player_->stepForward();
    } catch (const sgr::RecordingError& e) {
      target_ = -1;
      playing = false;
      *error = e.what();
      return false;
    }
    if (!r.ok) {
      target_ = -1;
      playing = false;
      *error = r.error.message();
      return false;
    }
    if (checkEachTick_ || tick() >= target_) {
      checkHash();
      syncB();
    }
  } while (std::chrono::duration<double>(Clock::now() - start).count() < seconds);
  if (tick() >= target_) target_ = -1;
  return true;
}

}  // namespace sg::viewer
