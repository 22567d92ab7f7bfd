// The documented JSON form of a world's state (docs/state-format.md, "JSON export"): what
// `simgrass replay --to T --export-state s.json` writes, readable without the library.
#pragma once

#include <nlohmann/json.hpp>

#include "sim/world/sim_world.h"

namespace sg {

/// format "simgrass-state/2": tick, scalar, particles, patch tips, bodies, cuts.
nlohmann::json stateExportJson(const StateExport& state);

}  // namespace sg
