// Loading scenarios from files: the scenario JSON and the heightmap it names (relative to the
// scenario's folder). Errors are ScenarioError lines naming the file and JSON path.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "replay/format/sgr_format.h"
#include "sim/scenario/scenario.h"
#include "sim/world/sim_world.h"

namespace sg {

/// Reads and parses a scenario file; an empty path gives the embedded thesis meadow. When
/// `files` is given, it receives every file the scenario named (for embedding in recordings).
Scenario loadScenarioFile(const std::string& path, std::vector<sgr::EmbeddedFile>* files = nullptr);

/// Every file a scenario loaded from `scenarioFile` reads, as paths to open: the files it
/// embedded (`files`, from loadScenarioFile: the heightmap) and the OBJ meshes its bodies name for
/// looks, each resolved against `folder` (the scenario's folder; for a recording, the recording's).
/// What no command may write over.
std::vector<std::string> filesNamedBy(const Scenario& scenario, const std::vector<sgr::EmbeddedFile>& files,
                                      const std::string& folder);

/// Memory this process may use in bytes (the default memory budget for a world): the machine's
/// physical memory, or the address-space limit (ulimit -v) when that is lower.
uint64_t physicalMemoryBytes();

/// makeWorld under physicalMemoryBytes(), with an allocation that fails anyway (the estimate is
/// a lower bound) turned into the ScenarioError `run` prints:
/// "file: $.field: expected a field that fits in memory (allocation failed)".
std::unique_ptr<SimWorld> makeWorldWithinMemory(const Scenario& scenario, int threads);

}  // namespace sg
