// What the outside world feeds into one tick. Everything here is recorded by record/replay, so
// it is stored in a canonical, scalar-independent quantisation: Q32.32 raw integers.
#pragma once

#include <cstdint>

namespace sg {

/// A position or vector in Q32.32 (raw = value * 2^32); each scalar rounds it on use.
struct InputVec3 {
  int64_t x = 0, y = 0, z = 0;
  friend bool operator==(const InputVec3&, const InputVec3&) = default;
};

struct TickInput {
  /// Camera position for the level-of-detail window (the LOD issue); ignored until then.
  bool hasCamera = false;
  InputVec3 camera;
  // Body commands (moves, impulses, teleports) arrive with the rigid-body issue.
  friend bool operator==(const TickInput&, const TickInput&) = default;
};

}  // namespace sg
