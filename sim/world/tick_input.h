// What the outside world feeds into one tick. Everything here is recorded by record/replay, so
// it is stored in a canonical, scalar-independent quantisation: Q32.32 raw integers.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim/scenario/scenario.h"

namespace sg {

/// A position or vector in Q32.32 (raw = value * 2^32); each scalar rounds it on use.
struct InputVec3 {
  int64_t x = 0, y = 0, z = 0;
  friend bool operator==(const InputVec3&, const InputVec3&) = default;
};

/// One command to one body, applied at the start of the tick (thesis keys T/F/G/H/U/J map to
/// Displace or AddVelocity along the camera's axes; the viewer issue does that mapping). Bodies
/// are numbered scenario bodies first, then spawned ones in spawn order; a command to a body that
/// does not exist when it runs is ignored.
struct BodyCommand {
  int32_t body = 0;
  BodyCommandKind kind = BodyCommandKind::AddVelocity;
  InputVec3 value;  ///< m, m/s or N s depending on the kind (Spawn, DragTo: m; ignored by Reset, MowerOn,
                    ///< MowerOff)
  friend bool operator==(const BodyCommand&, const BodyCommand&) = default;
};

struct TickInput {
  /// Camera position: the level-of-detail window follows it (ignored with the level of detail off).
  bool hasCamera = false;
  InputVec3 camera;
  std::vector<BodyCommand> bodies;  ///< applied in order
  friend bool operator==(const TickInput&, const TickInput&) = default;
};

/// The scenario's scripted input for one tick: its camera track and its script (empty when it has none).
TickInput scriptedInput(const Scenario& scenario, int64_t tick);

/// An input track's input for one tick: the latest camera key at or before it, that tick's commands.
TickInput trackInput(const InputTrack& track, int64_t tick);

/// Q32.32 raw of an exact value (saturating; scenario validation keeps values in range).
int64_t toInputRaw(const Rational& value);

/// SimError::body of a fault the body stages raised without knowing which body: fixed-point fault
/// bits are per thread, not per body (an independent pass saw "body 0" named for body 1's overflow).
inline constexpr int32_t kSomeBody = -2;

/// Which input a simulation fault of `body` at `tick` most likely came from, for the one-line
/// error: the commands of the latest tick at or before it (at most four), by file and JSON path
/// ("last input: track.json: $.commands[4] (teleport to body 2 at tick 50)"),
/// else the scenario's bodies ("no input before it; the bodies as given in scene.json:
/// $.bodies.list", or $.bodies.list[0] when there is one body). Commands
/// come from `track` when given, else the scenario's script. Empty when body is -1 (a particle
/// fault: the scenario as a whole); kSomeBody is a body fault whose body is not known. Control
/// characters in the file name are escaped.
std::string describeInputCause(const Scenario& scenario, const InputTrack* track, int64_t tick, int32_t body);

}  // namespace sg
