// Every exact constant a world derives from its scenario, computed once with checked 128-bit
// fraction arithmetic. A combination that does not fit (possible only with very long decimals)
// is a ScenarioError naming the JSON path of the value that caused it - never a crash. Both the
// validation and World<S> use this one function, so what validates is what runs.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "sim/scenario/scenario.h"

namespace sg {

struct ScenarioConstants {
  Rational invDt;           ///< 1/s
  Rational dampingPerTick;  ///< damping^dt (deterministicPow)
  // model blade only (zero otherwise)
  Rational bladeStiffness;              ///< 1/s^2: (2 pi f)^2 - acceleration.y / L
  Rational bladeDampingRate;            ///< 1/s: 4 pi dampingRatio f
  Rational bladeStiffnessDt;            ///< 1/s: stiffness * dt, the recovery's velocity change per metre of offset
  Rational bladeDampingPerTick;         ///< damping^dt exp(-dampingRate dt): both dampings, one factor
  Rational trampleDecayPerTick;         ///< dt / trampleSeconds (0: no trampling)
  Rational invRodLength;                ///< 1/L (1/m), model blade
  Rational halfRod;                     ///< L/2 (m)
  Rational invMass;                     ///< 1/kg
  Rational jitterAmplitude;             ///< m
  Rational fieldOriginX, fieldOriginZ;  ///< m, un-jittered position of patch (0, 0)
  int64_t particlesX = 0, particlesZ = 0;
  Rational invParticleSpacing;                            ///< 1 / (k spacing)
  std::vector<Rational> interpolationWeights;             ///< t/k for t = 0..k-1
  std::vector<std::array<Rational, 3>> gustForcePerMass;  ///< N/kg
  std::vector<int64_t> gustTicks;                         ///< each gust's duration in ticks (>= 1)
  std::vector<int64_t> rowDelayTicks;                     ///< round(r * rowSpacing / (speed * dt)), r = 0..particlesZ-1
  Rational ticksPerParticleSpacing;                       ///< rowSpacing / (speed * dt): a front's ticks per particle
  // heightmap terrain only
  Rational terrainInvCellSize;
  Rational terrainOriginX, terrainOriginZ;            ///< m, position of sample (0, 0)
  std::array<Rational, 256> terrainHeightOfSample{};  ///< m, maxHeight * v / 255
};

/// Throws ScenarioError (file, JSON path, what was expected) when a constant cannot be derived.
ScenarioConstants deriveConstants(const Scenario& scenario);

}  // namespace sg
