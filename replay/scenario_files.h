// Loading scenarios from files: the scenario JSON and the heightmap it names (relative to the
// scenario's folder). Errors are ScenarioError lines naming the file and JSON path.
#pragma once

#include <cstdint>
#include <string>

#include "sim/scenario/scenario.h"

namespace sg {

/// Reads and parses a scenario file; an empty path gives the embedded thesis meadow.
Scenario loadScenarioFile(const std::string& path);

/// Physical memory of this machine in bytes (the default memory budget for a world).
uint64_t physicalMemoryBytes();

}  // namespace sg
