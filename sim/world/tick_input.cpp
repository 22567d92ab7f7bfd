#include "sim/world/tick_input.h"

#include <algorithm>
#include <limits>

namespace sg {

int64_t toInputRaw(const Rational& value) {
  const auto raw = value.toScaledInteger(32);
  if (!raw) return value.isNegative() ? std::numeric_limits<int64_t>::min() : std::numeric_limits<int64_t>::max();
  if (*raw > __int128(std::numeric_limits<int64_t>::max())) return std::numeric_limits<int64_t>::max();
  if (*raw < __int128(std::numeric_limits<int64_t>::min())) return std::numeric_limits<int64_t>::min();
  return int64_t(*raw);
}

TickInput scriptedInput(const Scenario& scenario, int64_t tick) {
  TickInput input;
  // The script is sorted by tick: binary search for this tick's commands.
  auto first = std::lower_bound(scenario.script.begin(), scenario.script.end(), tick,
                                [](const ScriptedCommand& c, int64_t t) { return c.tick < t; });
  for (auto it = first; it != scenario.script.end() && it->tick == tick; ++it)
    input.bodies.push_back(BodyCommand{it->body, it->kind,
                                       InputVec3{toInputRaw(it->value[0]), toInputRaw(it->value[1]), toInputRaw(it->value[2])}});
  return input;
}

}  // namespace sg
