#include "replay/lockstep.h"

#include <algorithm>
#include <stdexcept>

namespace sg {

std::optional<TimeRatio> lineUp(const Rational& dtA, const Rational& dtB) {
  if (dtA.isZero() || dtB.isZero()) return std::nullopt;
  const std::optional<Rational> aOverB = div(dtA, dtB);
  if (aOverB && aOverB->isInteger() && aOverB->num >= 1 && aOverB->num <= (int64_t(1) << 30))
    return TimeRatio{1, int64_t(aOverB->num)};  // A's step is bSteps of B's
  const std::optional<Rational> bOverA = div(dtB, dtA);
  if (bOverA && bOverA->isInteger() && bOverA->num >= 1 && bOverA->num <= (int64_t(1) << 30))
    return TimeRatio{int64_t(bOverA->num), 1};
  return std::nullopt;
}

Rational recordedTimeStep(const sgr::Recording& recording) {
  VariantSettings recorded;
  try {
    recorded = VariantSettings::parse(recording.header.variant);
  } catch (const std::invalid_argument&) {
    // recordedScenario reports it, with the offset
  }
  return recorded.timeStep ? *recorded.timeStep : recordedScenario(recording).timeStep;
}

RecordedHashes::RecordedHashes(const sgr::Recording& r) {
  byTick_.push_back({r.header.startTick, r.header.initialStateHash});
  byTick_.insert(byTick_.end(), r.checks.begin(), r.checks.end());
  for (const sgr::SnapshotInfo& s : r.snapshots) byTick_.push_back({s.tick, s.hash});
  if (r.end && !r.end->faulted) byTick_.push_back({r.end->tick, r.end->hash});
  std::stable_sort(byTick_.begin(), byTick_.end(),
                   [](const sgr::Check& a, const sgr::Check& b) { return a.tick < b.tick; });
}

std::optional<uint64_t> RecordedHashes::at(int64_t tick) const {
  auto it =
      std::lower_bound(byTick_.begin(), byTick_.end(), tick, [](const sgr::Check& c, int64_t t) { return c.tick < t; });
  if (it == byTick_.end() || it->tick != tick) return std::nullopt;
  return it->hash;
}

TimeRatio lockStepRatio(const Rational& recordedDt, const Rational& runDt) {
  const std::optional<TimeRatio> r = lineUp(recordedDt, runDt);
  if (!r)
    throw std::invalid_argument("dt=" + runDt.toString() +
                                ": expected a time step that is a whole multiple or a whole " +
                                "fraction of the recording's dt=" + recordedDt.toString());
  return *r;
}

namespace {
TimeRatio ratioFor(const sgr::Recording& recording, const VariantSettings& variant) {
  const Rational recorded = recordedTimeStep(recording);
  return lockStepRatio(recorded, variant.timeStep.value_or(recorded));
}
}  // namespace

LockStepReplay::LockStepReplay(const sgr::Recording& recording, int threads, const VariantSettings& variant)
    : recording_(recording), ratio_(ratioFor(recording, variant)), player_(recording, threads, variant) {}

TickInput LockStepReplay::mergedInput(const sgr::Recording& recording, int64_t first, int64_t count) {
  TickInput merged = recording.inputAt(first);
  for (int64_t t = first + 1; t < first + count; ++t) {
    TickInput in = recording.inputAt(t);
    merged.bodies.insert(merged.bodies.end(), in.bodies.begin(), in.bodies.end());
    merged.hasCamera = in.hasCamera;
    merged.camera = in.camera;
  }
  return merged;
}

StepResult LockStepReplay::advanceTo(int64_t target) {
  SimWorld& w = player_.world();
  const int64_t r = ratio_.bSteps, m = ratio_.aSteps;
  while (recordedTick() < target) {
    const int64_t tick = recordedTick();
    TickInput input = m > 1 ? mergedInput(recording_, tick, m) : recording_.inputAt(tick);
    for (int64_t s = 0; s < r; ++s) {
      if (s == 1) input.bodies.clear();  // later substeps: the camera alone
      StepResult result = w.step(input);
      if (!result.ok) return result;
    }
  }
  return {};
}

}  // namespace sg
