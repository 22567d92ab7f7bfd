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

std::string describeInputCause(const Scenario& scenario, const InputTrack* track, int64_t tick, int32_t body) {
  if (body < 0 && body != kSomeBody) return "";
  static constexpr const char* kCommandNames[] = {"displace", "addVelocity", "impulse",  "teleport", "reset",
                                                  "spawn",    "mowerOn",     "mowerOff", "dragTo"};
  const std::vector<ScriptedCommand>& commands = track ? track->commands : scenario.script;
  const std::string& file = track ? track->sourceName : scenario.sourceName;
  const char* array = track ? "$.commands" : "$.script";
  // Fixed-point fault bits are per thread, not per body, so the body a fault names is not always
  // the one that overflowed: name every command of the latest tick at or before the fault (the
  // script is sorted by tick), at most four.
  auto latest = std::upper_bound(commands.begin(), commands.end(), tick,
                                 [](int64_t t, const ScriptedCommand& c) { return t < c.tick; });
  std::string where;
  if (latest != commands.begin()) {
    const int64_t at = (latest - 1)->tick;
    auto first =
        std::lower_bound(commands.begin(), latest, at, [](const ScriptedCommand& c, int64_t t) { return c.tick < t; });
    where = "last input: " + file + ":";
    int listed = 0;
    for (auto it = first; it != latest; ++it, ++listed) {
      if (listed == 4) {
        where += " and " + std::to_string(latest - it) + " more";
        break;
      }
      where += std::string(listed ? ", " : " ") + array + "[" + std::to_string(it->source) + "] (" +
               kCommandNames[size_t(it->kind)] + " to body " + std::to_string(it->body) + " at tick " +
               std::to_string(it->tick) + ")";
    }
  } else if (scenario.bodies.list.size() == 1 && (body == 0 || body == kSomeBody)) {
    where = "no input before it; the body as given in " + scenario.sourceName + ": $.bodies.list[0]";
  } else if (body == kSomeBody ? !scenario.bodies.list.empty() : size_t(body) < scenario.bodies.list.size()) {
    // Not [body]: the fault bits do not say which of the bodies overflowed.
    where = "no input before it; the bodies as given in " + scenario.sourceName + ": $.bodies.list";
  } else {
    return "";
  }
  std::string out;  // one line: control characters in a file name are escaped
  for (unsigned char ch : where) {
    if (ch < 0x20 || ch == 0x7f) {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[ch >> 4];
      out += kHex[ch & 15];
    } else {
      out += char(ch);
    }
  }
  return out;
}

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
