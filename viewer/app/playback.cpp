#include "viewer/app/playback.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "viewer/app/text.h"

namespace sg::viewer {

bool looksLikeRecording(const std::string& path) {
  if (path.size() >= 4 && path.compare(path.size() - 4, 4, ".sgr") == 0) return true;
  std::ifstream in(path, std::ios::binary);
  char magic[sizeof sgr::kMagic] = {};
  return in.read(magic, sizeof magic) && std::memcmp(magic, sgr::kMagic, sizeof magic) == 0;
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
  for (int64_t i = 0; i < n && tick() < lastTick(); ++i) {
    const StepResult r = player_->stepForward();
    if (!r.ok) {
      *error = r.error.message();
      playing = false;
      return false;
    }
    checkHash();
    syncB();
  }
  return true;
}

bool Playback::advance(double wallTicks, std::string* error) {
  if (!playing) return true;
  accumulator_ += wallTicks * speed;
  const int64_t n = int64_t(std::floor(accumulator_));
  accumulator_ -= double(n);
  const bool ok = step(n, error);
  if (tick() >= lastTick()) {
    playing = false;
    accumulator_ = 0;
  }
  return ok;
}

bool Playback::seek(int64_t t, std::string* error) {
  t = std::clamp<int64_t>(t, rec_->header.startTick, lastTick());
  accumulator_ = 0;
  try {
    const StepResult r = player_->seek(t);
    if (!r.ok) {
      *error = r.error.message();
      return false;
    }
  } catch (const sgr::RecordingError& e) {
    *error = e.what();
    return false;
  }
  checkHash();
  syncB();
  return true;
}

}  // namespace sg::viewer
