// libFuzzer target for the scenario parser: any text must give a Scenario or a ScenarioError, never
// a crash, an uncaught exception of another type, a hang or a huge allocation. A parsed scenario
// is also built into a world under a 32 MiB memory limit and stepped once (validateForScalar, the
// derived constants and the first tick see the parsed values). Every file name reads the same 4x4
// heightmap ("missing.png" is not found, to reach that error too).
#include <cstddef>
#include <cstdint>
#include <string>

#include "sim/world/sim_world.h"
#include "sim/world/tick_input.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const sg::ScenarioFileReader reader = [](const std::string& path, std::vector<uint8_t>* bytes, std::string* error) {
    if (path == "missing.png") {
      *error = "an existing file (not found)";
      return false;
    }
    *bytes = sg::fuzz::heightmapPng();
    return true;
  };
  sg::Scenario scenario;
  try {
    scenario = sg::parseScenario(text, "fuzz.json", reader);
  } catch (const sg::ScenarioError&) {
    return 0;
  }
  try {
    const auto world = sg::makeWorld(scenario, 1, uint64_t(32) << 20);
    (void)world->step(sg::scriptedInput(scenario, world->tick()));
  } catch (const sg::ScenarioError&) {
  }
  return 0;
}
