// Variant settings: what a run may change without changing the scenario text (scalar type,
// interpolation, broad phases, time step, level of detail, grass model, threads). Written "key=value" (comma or space
// separated); the resolved, complete form is stored in every recording's header.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "sim/math/rational.h"
#include "sim/particles/particle_kernel.h"
#include "sim/scenario/scenario.h"

namespace sg {

struct VariantSettings {
  std::optional<ScalarKind> scalar;
  std::optional<int> interpolation;              ///< k, 1..4
  std::optional<ParticleBroadphase> broadphase;  ///< particles vs bodies
  std::optional<BodyBroadphase> bodyBroadphase;  ///< bodies vs bodies
  std::optional<Rational> timeStep;              ///< s per tick
  std::optional<int> threads;                    ///< not part of the state: must be bit-identical
  std::optional<LodMode> lod;                    ///< off: the whole field; window: around the camera
  /// thesis, pbd or blade. Switching to or from blade also takes the new model's defaults for the
  /// particles' acceleration, initial velocity and damping (the thesis' 1 m/s^2 lift is not a blade's
  /// gravity); everything else stays.
  std::optional<GrassModel> model;
  /// Where the grass stages run (cpu, gpu, gpu-readback): not part of the state, so for fx32 and
  /// fx16 it must be bit-identical, like threads; float on the device is a comparison variant
  /// without that promise (docs/gpu-physics.md).
  std::optional<PhysicsPath> physics;

  /// Parses "interp=2", "scalar=fx16,dt=1/120", ...; later keys override earlier ones.
  /// Throws std::invalid_argument with "key=value: expected ..." on a bad setting.
  static VariantSettings parse(const std::string& text);
  /// This on top of `base` (keys set here win).
  VariantSettings over(const VariantSettings& base) const;
  void applyTo(Scenario& scenario) const;
  /// Every setting of a scenario with this variant applied (threads omitted; the model only when
  /// it is not thesis or not the one the scenario text gives, so recordings made before the key
  /// existed keep their resolved text and a thesis variant of a blade scenario replays as thesis).
  static VariantSettings resolvedFrom(const Scenario& scenario);
  /// "scalar=fx32 interp=1 broadphase=grid body-broadphase=brute dt=1/60" (set keys only).
  std::string describe() const;
  /// True when the variant cannot change the state (only broad phases, threads and, for fx32 and
  /// fx16, the physics path differ from `reference`): the run must be bit-identical to it.
  bool mustBeIdenticalTo(const VariantSettings& reference) const;
};

}  // namespace sg
