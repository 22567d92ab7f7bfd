// The stages of one tick, in the thesis order (runPhysics, thesis §9.2), and a hook to time them
// from outside (the core itself never reads a clock).
#pragma once

#include <cstdint>

namespace sg {

enum class Stage : uint8_t {
  Window = 0,   ///< level-of-detail window follows the camera           (sim/lod)
  Input,        ///< recorded body commands applied                      (sim/bodies)
  Wind,         ///< per-row wind force and particle acceleration        (sim/wind)
  Collision,    ///< body-body and body-terrain contacts                 (sim/collision)
  Response,     ///< gravity, contact impulses, projection, grass push   (sim/collision)
  Integrate,    ///< p += v dt; v += a dt; v *= damping^dt              (sim/particles)
                ///< fused per row with Constraints (particle_row.h): its time is timed here
  Constraints,  ///< rod projection back to length L; names a projection fault (never timed)
  PatchState,   ///< interpolation, tip offsets, tilt levels             (sim/patches)
  Count
};

inline const char* stageName(Stage s) {
  switch (s) {
    case Stage::Window:
      return "window";
    case Stage::Input:
      return "input";
    case Stage::Wind:
      return "wind";
    case Stage::Collision:
      return "collision";
    case Stage::Response:
      return "response";
    case Stage::Integrate:
      return "integrate";
    case Stage::Constraints:
      return "constraints";
    case Stage::PatchState:
      return "patch-state";
    case Stage::Count:
      break;
  }
  return "?";
}

/// Whether a StageObserver sees the stage begin and end. The rod projection runs fused with the
/// integration, row by row (sim/particles/particle_row.h), so Constraints is never timed on its
/// own: timing tables leave it out rather than show a zero.
inline bool stageIsTimed(Stage s) { return s != Stage::Constraints && s != Stage::Count; }

/// The name a timing table gives a timed stage: Integrate's time includes the rod projection.
inline const char* timedStageName(Stage s) { return s == Stage::Integrate ? "integrate+constraints" : stageName(s); }

/// Receives stage boundaries; implemented by tools that measure time (replay/).
class StageObserver {
 public:
  virtual ~StageObserver() = default;
  virtual void stageBegin(Stage stage) = 0;
  virtual void stageEnd(Stage stage) = 0;
};

}  // namespace sg
