// The scenario fingerprint: a hash of everything that shapes a world (not its name or
// description), stored in every saved state so that a state is only restored into a world built
// from an equivalent scenario. Canonical little-endian bytes: the same on every machine.
#pragma once

#include <cstdint>

#include "sim/scenario/scenario.h"

namespace sg {

uint64_t scenarioFingerprint(const Scenario& scenario);

}  // namespace sg
