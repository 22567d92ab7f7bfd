#include "replay/player.h"

#include <algorithm>
#include <cmath>

#include "replay/physics_devices.h"
#include "replay/scenario_files.h"
#include "sim/scenario/json_bounds.h"

namespace sg {

Scenario recordedScenario(const sgr::Recording& rec, const VariantSettings& override) {
  const sgr::Header& h = rec.header;
  // Files the scenario names come from the recording, never from the disk: a recording is
  // self-contained and replays the same wherever it is moved.
  auto embedded = [&h](const std::string& name, std::vector<uint8_t>* out, std::string* why) {
    for (const sgr::EmbeddedFile& f : h.files)
      if (f.name == name) {
        *out = f.bytes;
        return true;
      }
    *why = "'" + name + "' embedded in the recording (it is not)";
    return false;
  };
  Scenario s;
  const std::string where = rec.file + " (scenario '" + h.scenarioSource + "' in HEAD)";
  try {
    s = parseScenario(h.scenarioText, where, embedded);
  } catch (const ScenarioError& e) {
    throw sgr::RecordingError(rec.file, sgr::kPreambleBytes, std::string("a scenario that loads: ") + e.what());
  }
  VariantSettings recorded;
  try {
    recorded = VariantSettings::parse(h.variant);
  } catch (const std::invalid_argument& e) {
    throw sgr::RecordingError(rec.file, sgr::kPreambleBytes, std::string("valid variant settings: ") + e.what());
  }
  if (recorded.scalar && *recorded.scalar != h.scalar)
    throw sgr::RecordingError(rec.file, sgr::kPreambleBytes + sgr::kChunkHeaderBytes,
                              "the header's scalar type to match its variant settings");
  override.over(recorded).applyTo(s);
  return s;
}

namespace {
/// An upper bound of the binary state's size (docs/state-format.md) of any world this recording's
/// field can give, whatever variant replays it (the snapshots hold the recorded scalar, level of
/// detail and interpolation): 8-byte scalars, a particle per lattice corner, every body it could
/// spawn (kMaxBodies), every patch mown and a generous warm-start cache (64 entries per pair of
/// bodies, the terrain counted as a body).
uint64_t largestState(const WorldCounts& c) {
  const uint64_t s = 8;
  const uint64_t bodies = uint64_t(std::max<int64_t>(c.bodies, kMaxBodies));
  const uint64_t pairs = (bodies + 1) * (bodies + 2) / 2;
  const uint64_t patches = uint64_t(std::max<int64_t>(c.patches(), 0));
  const uint64_t corners =
      uint64_t(std::max<int64_t>(c.patchesX, 0) + 1) * uint64_t(std::max<int64_t>(c.patchesZ, 0) + 1);
  const uint64_t particles = std::max(corners, uint64_t(std::max<int64_t>(c.particles(), 0)));
  return 8 + 7 * 12 + 40 + 6 * s * particles + bodies * (13 * s + 8) + 4 + bodies * 32 + 8 + pairs * 64 * (6 * s + 16) +
         8 + patches * 16 + 16;
}
}  // namespace

Player::Player(const sgr::Recording& recording, int threads, const VariantSettings& variant)
    : recording_(recording), threads_(variant.threads.value_or(threads)), physics_(variant.physics) {
  scenario_ = recordedScenario(recording, variant);
  // Settings compared once resolved (a recording's variant string may omit keys it left at the
  // scenario's value, e.g. recordings made before `lod` existed).
  const VariantSettings recorded = VariantSettings::resolvedFrom(recordedScenario(recording));
  sameSettings_ = variant.mustBeIdenticalTo(recorded);
  exactSettings_ = VariantSettings::resolvedFrom(scenario_).describe() == recorded.describe();
  try {
    // The machine's memory is the budget (as for `simgrass record`): a recording whose scenario
    // asks for more is an error here, not a failed allocation later.
    buildWorld();
  } catch (const ScenarioError& e) {
    throw sgr::RecordingError(recording.file, sgr::kPreambleBytes,
                              std::string("a scenario this build can run: ") + e.what());
  }
  largestStateBytes_ = largestState(world_->counts());
  // Spawn commands add bodies up to kMaxBodies: commands may name those indices too.
  const int64_t bodies = bodyIndexLimit(size_t(world_->counts().bodies));
  // Camera positions and command values within the scalar's coordinate range, as a track's are
  // (validateInputTrack): a forged camera at 2^30 m wrapped the level-of-detail window, and
  // `replay --to` exported the diverged state with exit 0 (an independent pass, 2026-11-29).
  const double limit = dispatchScalar(scenario_.scalar, []<class S>() { return ScalarTraits<S>::maxCoordinate; });
  const auto within = [&](const InputVec3& v) {
    for (const int64_t raw : {v.x, v.y, v.z})
      if (!(std::fabs(double(raw) / 4294967296.0) <= limit)) return false;
    return true;
  };
  const std::string rangeText = std::string(" within the ") + scalarName(scenario_.scalar) +
                                " range (|value| <= " + std::to_string(int64_t(std::min(limit, 2147483647.0))) + " m)";
  for (const sgr::InputRecord& in : recording.inputs) {
    if (in.input.hasCamera && !within(in.input.camera))
      throw sgr::RecordingError(recording.file, in.offset,
                                "camera coordinates" + rangeText + " at tick " + std::to_string(in.tick));
    for (const BodyCommand& c : in.input.bodies)
      if (!within(c.value))
        throw sgr::RecordingError(recording.file, in.offset,
                                  "command values" + rangeText + " at tick " + std::to_string(in.tick));
  }
  for (const sgr::InputRecord& in : recording.inputs)
    for (const BodyCommand& c : in.input.bodies)
      if (c.body >= bodies)
        throw sgr::RecordingError(recording.file, in.offset,
                                  "commands for at most " + std::to_string(bodies) + " bodies, got body " +
                                      std::to_string(c.body) + " at tick " + std::to_string(in.tick));
  if (sameSettings_ && world_->stateHash() != recording.header.initialStateHash && recording.header.startTick == 0)
    throw sgr::RecordingError(recording.file, sgr::kPreambleBytes,
                              "an initial state this build reproduces (the scenario builds a different world: "
                              "the physics or the scenario format changed since it was recorded)");
}

void Player::restart() { buildWorld(); }

std::string Player::setPhysics(PhysicsPath path) {
  if (path != PhysicsPath::Cpu && scenario_.scalar == ScalarKind::Float && sameSettings_)
    return "a float recording's hashes promise bits the device's float does not keep: it plays on the CPU";
  if (std::string why = applyPhysicsPath(*world_, path); !why.empty()) return why;
  physics_ = path;
  return "";
}

void Player::buildWorld() {
  world_ = makeWorldWithinMemory(scenario_, threads_);
  if (physics_ && *physics_ != PhysicsPath::Cpu)
    if (const std::string why = applyPhysicsPath(*world_, *physics_); !why.empty())
      throw std::invalid_argument(std::string("physics=") + physicsPathName(*physics_) + ": " + why);
}

StepResult Player::stepForward(StageObserver* observer) {
  return world_->step(recording_.inputAt(world_->tick()), observer);
}

StepResult Player::seek(int64_t target, const std::function<void(int64_t)>& progress) {
  if (target < 0) target = 0;
  // Nearest snapshot at or before the target (only when the settings match the recording's:
  // a snapshot is a state of the recorded world).
  const sgr::SnapshotInfo* snap = sameSettings_ ? recording_.snapshotAtOrBefore(target) : nullptr;
  const int64_t from = world_->tick();
  const bool forwardIsShorter = from <= target && (!snap || snap->tick <= from);
  if (!forwardIsShorter) {
    if (snap) {
      const std::vector<uint8_t> state = recording_.snapshotState(*snap, largestStateBytes_);
      try {
        world_->restoreState(state);
      } catch (const StateError& e) {
        throw sgr::RecordingError(recording_.file, snap->offset,
                                  // e.what() is "byte N: expected ..." (it said "state byte N: expected byte N: ...").
                                  std::string("a snapshot of this scenario's state (state ") + e.what() + ")");
      }
      if (world_->stateHash() != snap->hash)
        throw sgr::RecordingError(recording_.file, snap->offset, "a snapshot whose state matches its hash");
    } else {
      restart();
    }
  }
  const int64_t start = world_->tick();
  while (world_->tick() < target) {
    StepResult r = stepForward();
    if (!r.ok) return r;
    if (progress) progress(world_->tick() - start);
  }
  return {};
}

VerifyReport Player::verify(const std::function<void(int64_t)>& progress) {
  VerifyReport report;
  if (world_->tick() != recording_.header.startTick) restart();
  const bool recordedFault = recording_.end && recording_.end->faulted;
  // A recording that stopped on a fault: replay the faulting step too, it must fault the same way.
  const int64_t last = recordedFault ? recording_.end->tick + 1 : recording_.lastTick();
  // Expected hashes by tick: CHCK, SNAP and END (merged, each checked once per tick).
  std::vector<sgr::Check> expected = recording_.checks;
  for (const sgr::SnapshotInfo& s : recording_.snapshots) expected.push_back({s.tick, s.hash});
  if (recording_.end && !recording_.end->faulted) expected.push_back({recording_.end->tick, recording_.end->hash});
  std::stable_sort(expected.begin(), expected.end(),
                   [](const sgr::Check& a, const sgr::Check& b) { return a.tick < b.tick; });
  size_t next = 0;
  // The start state's hash was compared when this Player was made (same settings, tick 0).
  if (exactSettings_ && recording_.header.startTick == 0 && world_->tick() == 0) report.checksVerified = 1;
  // Snapshots are what seeking restores, and their hash (checked above) says nothing about their
  // bytes: each must decompress (a damaged frame throws RecordingError) and, when this world runs
  // with exactly the recorded settings, hold the state replayed at its tick.
  const bool exactSettings = exactSettings_;
  size_t nextSnapshot = 0;
  while (world_->tick() < last) {
    // A tick with an expected hash: the particle pass takes the row groups' digests (state_hash.h).
    while (next < expected.size() && expected[next].tick <= world_->tick()) ++next;
    if (next < expected.size() && expected[next].tick == world_->tick() + 1) world_->requestStateHash();
    StepResult r = stepForward();
    if (!r.ok) {
      if (!(recordedFault && recording_.end->tick == world_->tick())) {
        report.ok = false;
        report.fault = r.error;
        report.firstMismatchTick = world_->tick() + 1;
      }
      break;
    }
    ++report.ticks;
    while (next < expected.size() && expected[next].tick < world_->tick()) ++next;
    bool hashed = false;
    uint64_t hash = 0;
    for (; next < expected.size() && expected[next].tick == world_->tick(); ++next) {
      if (!hashed) hash = world_->stateHash(), hashed = true;
      if (hash != expected[next].hash) {
        report.ok = false;
        report.firstMismatchTick = world_->tick();
        report.expectedHash = expected[next].hash;
        report.actualHash = hash;
        return report;
      }
    }
    if (hashed) ++report.checksVerified;  // a tick with CHCK, SNAP and END counts once
    const std::vector<sgr::SnapshotInfo>& snapshots = recording_.snapshots;
    while (nextSnapshot < snapshots.size() && snapshots[nextSnapshot].tick < world_->tick()) ++nextSnapshot;
    if (nextSnapshot < snapshots.size() && snapshots[nextSnapshot].tick == world_->tick()) {
      const sgr::SnapshotInfo& snap = snapshots[nextSnapshot];
      const std::vector<uint8_t> state = recording_.snapshotState(snap, largestStateBytes_);
      if (exactSettings && state != world_->saveState())
        throw sgr::RecordingError(recording_.file, snap.offset,
                                  "a snapshot holding the state replayed at tick " + std::to_string(snap.tick));
    }
    if (progress) progress(report.ticks);
  }
  if (recordedFault && report.ok && world_->tick() > recording_.end->tick) {
    report.ok = false;  // the recording faulted at end->tick, the replay stepped past it
    report.firstMismatchTick = recording_.end->tick + 1;
    report.recordedFaultMissing = true;
  }
  return report;
}

std::string describeRecordedFaultMissing(const sgr::EndInfo& end) {
  return "the recording says the step from tick " + std::to_string(end.tick) + " faulted" +
         (end.message.empty() ? std::string() : " (" + echoText(end.message) + ")") +
         "; the replay stepped it without a fault";
}

}  // namespace sg
