// libFuzzer target for viewer scripts (parseScript): any text gives commands or one error line
// "fuzz.script:LINE: ..."; never a crash, a hang or a huge allocation. Built only with
// SIMGRASS_BUILD_VIEWER (the parser maps key names to GLFW codes).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "viewer/app/script.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<sg::viewer::ScriptCommand> commands;
  std::string error;
  if (!sg::viewer::parseScript(std::string(reinterpret_cast<const char*>(data), size), "fuzz.script", &commands,
                               &error)) {
    if (error.rfind("fuzz.script:", 0) != 0 || error.find('\n') != std::string::npos) std::abort();
  }
  return 0;
}
