// Records the built-in meadow for 10 ticks through the installed replay component, verifies the
// recording, and prints the final state hash (run.sh compares it with the simgrass CLI's).
//   consumer OUT.sgr
#include <cstdio>
#include <string>

#include "replay/recording.h"
#include "sim/scenario/scenario.h"
#include "sim/world/tick_input.h"

// The consumer's include path holds the installed SimGrass headers and the system's, not Eigen's
// (/usr/include/eigen3): everything above compiled without it.
#if __has_include(<Eigen/Core>)
#error "Eigen is on the consumer's include path: the check proves nothing"
#endif

#include "sim/world/sim_world.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer OUT.sgr\n");
    return 2;
  }
  const std::string path = argv[1];
  const sg::Scenario scenario = sg::parseScenario(sg::defaultScenarioText(), "<built-in>", {});
  sg::RecordingSession session = sg::RecordingSession::fromScenario(scenario, path);
  if (!session.stepScripted(10)) {
    std::fprintf(stderr, "consumer: %s\n", session.error().c_str());
    return 1;
  }
  const sg::RecordingSummary summary = session.finish();

  const sg::RecordingInfo info = sg::readRecordingInfo(path);
  const sg::VerifyResult verified = sg::verifyRecording(path);
  if (!info.complete || info.lastTick != 10 || !verified.ok || verified.finalHash != summary.finalHash) {
    std::fprintf(stderr, "consumer: %s does not verify (complete %d, last tick %lld, verified %d)\n", path.c_str(),
                 int(info.complete), (long long)info.lastTick, int(verified.ok));
    return 1;
  }
  // The core alone, stepped directly: the same state as the recorded session; saved, restored
  // into a fresh world and exported as plain numbers.
  auto world = sg::makeWorld(scenario, 1);
  for (int64_t t = 0; t < 10; ++t)
    if (!world->step(sg::scriptedInput(scenario, t)).ok) return 1;
  if (world->stateHash() != summary.finalHash) {
    std::fprintf(stderr, "consumer: SimWorld and the recorded session differ\n");
    return 1;
  }
  auto fresh = sg::makeWorld(scenario, 2);
  fresh->restoreState(world->saveState());
  sg::StateExport exported;
  fresh->exportState(exported);
  if (fresh->stateHash() != summary.finalHash || exported.tick != 10 ||
      exported.particlePosition.size() != size_t(3 * world->counts().particles())) {
    std::fprintf(stderr, "consumer: save/restore/export through the public API failed\n");
    return 1;
  }
  std::printf("tick %lld hash %016llx\n", (long long)summary.ticks, (unsigned long long)summary.finalHash);
  return 0;
}
