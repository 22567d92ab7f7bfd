// libFuzzer target for input tracks: any text against the fixed fuzz scenario (three bodies) must
// give an InputTrack or a ScenarioError, never a crash, another exception, a hang or a huge
// allocation.
#include <cstddef>
#include <cstdint>
#include <string>

#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const sg::Scenario& scenario = sg::fuzz::fixedScenario();
  try {
    (void)sg::parseInputTrack(std::string(reinterpret_cast<const char*>(data), size), "fuzz-track.json", scenario);
  } catch (const sg::ScenarioError&) {
  }
  return 0;
}
