#include "replay/recording.h"

#include <stdexcept>
#include <utility>

#include "replay/format/sgr_reader.h"
#include "replay/input_file.h"
#include "replay/player.h"
#include "replay/recorder.h"
#include "replay/scenario_files.h"
#include "sim/world/world.h"

namespace sg {

struct RecordingSession::Impl {
  /// What `simgrass record` does between loading the scenario and its first step: the world
  /// under the machine's memory budget, the default hash interval for its size, then HEAD.
  Impl(Scenario s, std::vector<sgr::EmbeddedFile> files, const std::string& output, const RecordingSettings& settings)
      : scenario(std::move(s)), world(makeWorldWithinMemory(scenario, settings.threads)) {
    RecordSettings record;
    record.checkEvery = settings.checkEvery ? *settings.checkEvery : defaultCheckEvery(world->counts().patches());
    record.snapshotEvery = settings.snapshotEvery;
    recorder = std::make_unique<Recorder>(output, scenario, std::move(files), *world, record);
  }

  Scenario scenario;
  std::unique_ptr<SimWorld> world;  // declared before the recorder, which holds a reference to it
  std::unique_ptr<Recorder> recorder;
  StepResult last;
  std::string error;  ///< last.error.message() once a step faulted
  bool finished = false;
  RecordingSummary summary;
};

RecordingSession::RecordingSession(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RecordingSession::RecordingSession(RecordingSession&&) noexcept = default;
RecordingSession& RecordingSession::operator=(RecordingSession&&) noexcept = default;
RecordingSession::~RecordingSession() = default;

RecordingSession RecordingSession::fromScenarioFile(const std::string& scenarioFile, const std::string& output,
                                                    const RecordingSettings& settings) {
  // The recording must not replace the scenario it is made from.
  if (!scenarioFile.empty() && sameFile(scenarioFile, output))
    throw std::runtime_error(output + ": expected a recording file other than the scenario " + scenarioFile);
  std::vector<sgr::EmbeddedFile> files;
  Scenario scenario = loadScenarioFile(scenarioFile, &files);
  return RecordingSession(std::make_unique<Impl>(std::move(scenario), std::move(files), output, settings));
}

RecordingSession RecordingSession::fromScenario(const Scenario& scenario, const std::string& output,
                                                const RecordingSettings& settings) {
  // The player reads a named file from the recording only; without its bytes the recording
  // would be written fine and fail to load at replay time, far from the cause.
  if (!scenario.terrain.heightmapPath.empty())
    throw ScenarioError(scenario.sourceName, "$.terrain.file",
                        "no file in a scenario recorded from memory (RecordingSession::fromScenarioFile embeds it)");
  return RecordingSession(std::make_unique<Impl>(scenario, std::vector<sgr::EmbeddedFile>{}, output, settings));
}

bool RecordingSession::step(const TickInput& input) {
  if (impl_->finished) throw std::logic_error("RecordingSession::step after finish()");
  if (!impl_->last.ok) return false;
  impl_->last = impl_->recorder->step(input);
  if (!impl_->last.ok) impl_->error = impl_->last.error.message();
  return impl_->last.ok;
}

bool RecordingSession::stepScripted(int64_t ticks) {
  for (int64_t t = 0; t < ticks; ++t)
    if (!step(scriptedInput(impl_->scenario, impl_->world->tick()))) return false;
  return impl_->last.ok;
}

RecordingSummary RecordingSession::finish() {
  if (!impl_->finished) {
    impl_->recorder->finish(impl_->last);
    impl_->finished = true;
    impl_->summary.ticks = impl_->world->tick();
    impl_->summary.finalHash = impl_->world->stateHash();
    impl_->summary.bytes = impl_->recorder->bytesWritten();
    impl_->summary.error = impl_->error;
  }
  return impl_->summary;
}

const Scenario& RecordingSession::scenario() const { return impl_->scenario; }
int64_t RecordingSession::tick() const { return impl_->world->tick(); }
uint64_t RecordingSession::stateHash() const { return impl_->world->stateHash(); }
const SimWorld& RecordingSession::world() const { return *impl_->world; }

const std::string& RecordingSession::error() const { return impl_->error; }

RecordingInfo readRecordingInfo(const std::string& path) {
  const sgr::Recording rec = sgr::readRecording(path);
  RecordingInfo info;
  info.scenarioSource = rec.header.scenarioSource;
  info.scenarioText = rec.header.scenarioText;
  info.variant = rec.header.variant;
  info.buildId = rec.header.buildId;
  info.startTick = rec.header.startTick;
  info.lastTick = rec.lastTick();
  info.checkEvery = rec.header.checkEvery;
  info.snapshotEvery = rec.header.snapshotEvery;
  info.inputs = int64_t(rec.inputs.size());
  info.checks = int64_t(rec.checks.size());
  info.snapshots = int64_t(rec.snapshots.size());
  info.hashedTicks = rec.hashedTicks();
  info.complete = rec.end.has_value();
  if (rec.end && rec.end->faulted) info.fault = rec.end->message;
  if (rec.end && !rec.end->faulted) info.finalHash = rec.end->hash;
  return info;
}

VerifyResult verifyRecording(const std::string& path, int threads) {
  const sgr::Recording rec = sgr::readRecording(path);
  Player player(rec, threads);  // holds a reference to rec: both live to the end of this call
  const VerifyReport report = player.verify();
  VerifyResult result;
  result.ok = report.ok;
  result.ticks = report.ticks;
  result.hashesChecked = report.checksVerified;
  result.firstMismatchTick = report.firstMismatchTick;
  result.expectedHash = report.expectedHash;
  result.actualHash = report.actualHash;
  if (report.fault) result.error = report.fault->message();
  result.recordedFaultMissing = report.recordedFaultMissing;
  if (report.recordedFaultMissing) result.error = describeRecordedFaultMissing(*rec.end);
  result.finalHash = player.world().stateHash();
  return result;
}

}  // namespace sg
