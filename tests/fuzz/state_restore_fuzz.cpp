// libFuzzer target for state restore (SimWorld::restoreState): any bytes restored into a fresh
// world of the fixed fuzz scenario (fx32, fx16 and double) give a StateError or a world that
// saves the very same bytes and steps without a crash; never a crash, a hang or a huge
// allocation. An accepted state that saves different bytes was silently changed on the way in.
//
// Seeds: SIMGRASS_FUZZ_WRITE_SEEDS=DIR state_restore_fuzz writes the states of each scalar at
// ticks 0 and 8 into DIR and exits (tests/fuzz/corpus/state_restore/ was made so).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <span>
#include <string>

#include "sim/world/sim_world.h"
#include "sim/world/tick_input.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

const char* const kScalars[] = {"fx32", "fx16", "double"};

std::unique_ptr<sg::SimWorld> freshWorld(int scalar) {
  sg::Scenario s = sg::fuzz::fixedScenario();
  s.scalar = *sg::parseScalarKind(kScalars[scalar]);
  return sg::makeWorld(s, 1);
}

void writeSeeds(const std::string& dir) {
  for (int k = 0; k < 3; ++k) {
    auto w = freshWorld(k);
    for (int tick = 0; tick <= 8; ++tick) {
      if (tick == 0 || tick == 8) {
        const std::vector<uint8_t> bytes = w->saveState();
        const std::string path = dir + "/" + kScalars[k] + "-tick" + std::to_string(tick) + ".state";
        FILE* f = std::fopen(path.c_str(), "wb");
        if (!f || std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size() || std::fclose(f) != 0) std::exit(1);
      }
      (void)w->step(sg::scriptedInput(sg::fuzz::fixedScenario(), w->tick()));
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* dir = std::getenv("SIMGRASS_FUZZ_WRITE_SEEDS")) {
    writeSeeds(dir);
    std::exit(0);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::span<const uint8_t> bytes(data, size);
  for (int k = 0; k < 3; ++k) {
    auto w = freshWorld(k);
    try {
      w->restoreState(bytes);
    } catch (const sg::StateError&) {
      continue;
    }
    if (w->saveState() != std::vector<uint8_t>(data, data + size)) std::abort();
    for (int t = 0; t < 2; ++t) (void)w->step(sg::scriptedInput(sg::fuzz::fixedScenario(), w->tick()));
  }
  return 0;
}
