#include "sim/world/tick_input.h"

#include <algorithm>
#include <limits>

namespace sg {

int64_t toInputRaw(const Rational& value) {
  const auto raw = value.toScaledInteger(32);
  if (!raw) return value.isNegative() ? std::numeric_limits<int64_t>::min() : std::numeric_limits<int64_t>::max();
  if (*raw > Int128(std::numeric_limits<int64_t>::max())) return std::numeric_limits<int64_t>::max();
  if (*raw < Int128(std::numeric_limits<int64_t>::min())) return std::numeric_limits<int64_t>::min();
  return int64_t(*raw);
}

namespace {
InputVec3 toInputVec3(const Rational3& v) { return InputVec3{toInputRaw(v[0]), toInputRaw(v[1]), toInputRaw(v[2])}; }

void addCommands(const std::vector<ScriptedCommand>& script, int64_t tick, TickInput& input) {
  // The script is sorted by tick: binary search for this tick's commands.
  auto first = std::lower_bound(script.begin(), script.end(), tick,
                                [](const ScriptedCommand& c, int64_t t) { return c.tick < t; });
  for (auto it = first; it != script.end() && it->tick == tick; ++it)
    input.bodies.push_back(BodyCommand{it->body, it->kind, toInputVec3(it->value)});
}
void setCamera(const std::vector<CameraKey>& keys, int64_t tick, TickInput& input) {
  auto key = std::upper_bound(keys.begin(), keys.end(), tick, [](int64_t t, const CameraKey& k) { return t < k.tick; });
  if (key == keys.begin()) return;
  input.hasCamera = true;
  input.camera = toInputVec3((key - 1)->position);
}
}  // namespace

TickInput scriptedInput(const Scenario& scenario, int64_t tick) {
  TickInput input;
  setCamera(scenario.camera, tick, input);
  addCommands(scenario.script, tick, input);
  return input;
}

TickInput trackInput(const InputTrack& track, int64_t tick) {
  TickInput input;
  setCamera(track.camera, tick, input);
  addCommands(track.commands, tick, input);
  return input;
}

}  // namespace sg
