// How a grass model behaves, measured on one tuft of a scenario (issue 16's behaviour metrics, the
// sweep prints them per scenario and model): stationarity (the same gust at the start and ten
// minutes in), how fast a tuft settles after a gust and after a body lets it go, and how long a
// pressed tuft stays down. docs/grass-models.md.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "sim/scenario/scenario.h"

namespace sg {

struct ModelBehaviour {
  double swayStart = 0;          ///< m: largest tip offset under the gust when it comes at t = 0
  double swayLate = 0;           ///< m: the same gust coming 600 s into the run
  double settleAfterGust = -1;   ///< s after the gust ends until the tip stays within 5 cm (-1: not in 200 s)
  double settleAfterPress = -1;  ///< s after a tip pressed to 70 degrees is let go until it stays within 5 cm
  double downAfterPress = 0;     ///< s the pressed tip stays below half its rod's height (trampling)
};

/// One tuft of `scenario` (its particles, grass model and time step, starting at rest; flat ground,
/// no bodies, the scenario's strongest gust alone), in double. A press sets the tip to 70 degrees at rest, and
/// trampled when the model tramples. Throws ScenarioError when the scenario does not validate.
ModelBehaviour measureModelBehaviour(const Scenario& scenario);

/// A grass model's error against the truth (reference_blade.h: a blade of 8 segments with the
/// scenario's length, mass, blade frequency and damping ratio, under gravity, in double at a
/// small step): one tuft (as above) in four runs, each from rest in still air but the first:
///   1. the scenario's own wind for its first 30 s;
///   2. the tip pressed to 70 degrees and let go, 10 s;
///   3. a body passing over the tips: a ball of radius 0.5 L, its centre 1.2 L up and 0.2 L beside
///      the root, moving along +x at L per second from 2 L before the root, 10 s (in the model's
///      world a ball of 1000 particle masses, without gravity or grass drag: it keeps its speed;
///      kinematic in the reference; L rounded to 2^-20 m for the ball in both);
///   4. the same ball through the blade's middle, its centre 0.6 L up, 10 s.
/// Where the balls' scenario does not validate (an L beyond 1 µm..1e9 m, a particle mass whose
/// thousandfold the bodies do not take), runs 3 and 4 are left out: the body figures are NaN and
/// bodyError says why.
/// No trampling in any run (the truth has none). The tip offsets from the root are compared every
/// tick.
struct ModelError {
  double tipRms = 0;                    ///< m: RMS over the compared ticks of |tip - reference tip|
  double tipMax = 0;                    ///< m: the largest
  double seconds = 0;                   ///< simulated s compared (all runs)
  double bodyRms = 0;                   ///< m: the same over runs 3 and 4 (the bodies passing)
  double bodyMax = 0;                   ///< m
  std::array<double, 2> passRms{0, 0};  ///< m: RMS over run 3 (over the tips) and run 4 (through the middle)
  std::string bodyError;                ///< why runs 3 and 4 were left out (empty: they ran)
};

/// The reference blade's tip offset at every tick of those four runs, for `scenario` at `dt`. The
/// same for every grass model (it reads the tuft's length, mass, blade frequency and damping
/// ratio and the wind only): the sweep computes it once per scenario file and dt.
std::vector<std::array<double, 3>> referenceTips(const Scenario& scenario, const Rational& dt);

/// `scenario`'s grass model at time step `dt`, in double, against `reference` (referenceTips of
/// the same scenario and dt; null: computed here). Throws ScenarioError when the scenario does
/// not validate at that step.
ModelError measureModelError(const Scenario& scenario, const Rational& dt,
                             const std::vector<std::array<double, 3>>* reference = nullptr);

}  // namespace sg
