#include "replay/report/model_behaviour.h"

#include <algorithm>
#include <cmath>

#include "replay/report/reference_blade.h"
#include "sim/scenario/derived.h"
#include "sim/wind/wind.h"
#include "sim/world/world.h"

namespace sg {
namespace {

constexpr double kWithin = 0.05;           // m: "back within 5 cm"
constexpr double kHorizon = 200;           // s looked at after the gust or the press
constexpr int64_t kLateStart = 600;        // s: "ten minutes in"
constexpr double kErrorWindSeconds = 30;   // s of the scenario's wind in the model-error run
constexpr double kErrorPressSeconds = 10;  // s after the press in the model-error run
constexpr double kPressAngle = 70 * 3.14159265358979323846 / 180;

/// The scenario reduced to one tuft at the origin on flat ground, no bodies, no script.
Scenario oneTuft(const Scenario& s) {
  Scenario t = s;
  t.scalar = ScalarKind::Double;
  t.field.patchesX = t.field.patchesZ = 1;
  t.field.jitter = Rational{0, 1};
  t.field.centerX = t.field.centerZ = Rational{0, 1};
  t.particles.interpolation = 1;
  t.particles.initialVelocity = {Rational{0, 1}, Rational{0, 1}, Rational{0, 1}};  // the gust's sway alone
  t.terrain = Scenario::Terrain{};
  t.bodies.list.clear();
  t.script.clear();
  t.camera.clear();
  t.lod = Scenario::Lod{};
  t.markings.enabled = false;
  return t;
}

/// The gust with the largest horizontal force (none: an empty schedule).
std::vector<WindGust> strongestGust(const Scenario& s) {
  const WindGust* best = nullptr;
  double strongest = 0;
  for (const WindGust& g : s.wind.schedule) {
    const double h = std::hypot(g.force[0].toDouble(), g.force[2].toDouble());
    if (h > strongest) strongest = h, best = &g;
  }
  if (!best) return {};
  WindGust gust = *best;
  gust.front.reset();
  return {gust};
}

double tipOffset(const World<double>& w) {
  const auto& p = w.particles();
  return std::hypot(p.px[0] - p.anchorX[0], p.pz[0] - p.anchorZ[0]);
}

/// Runs the gust starting `startSeconds` in: the largest sway from then on, and the settling time
/// after the gust ends.
void runGust(const Scenario& tuft, const std::vector<WindGust>& gust, int64_t startSeconds, double* sway,
             double* settle) {
  Scenario s = tuft;
  s.wind.schedule.clear();
  if (!gust.empty()) {
    if (startSeconds > 0)
      s.wind.schedule.push_back({{Rational{0, 1}, Rational{0, 1}, Rational{0, 1}}, Rational::integer(startSeconds)});
    s.wind.schedule.push_back(gust[0]);
    s.wind.schedule.push_back({{Rational{0, 1}, Rational{0, 1}, Rational{0, 1}}, Rational{100000, 1}});
  }
  validateForScalar(s, ScalarKind::Double, 0);
  World<double> w(s, 1);
  const double dt = s.timeStep.toDouble();
  const int64_t start = std::llround(double(startSeconds) / dt);
  const int64_t gustEnd = start + (gust.empty() ? 0 : std::llround(gust[0].duration.toDouble() / dt));
  const int64_t end = gustEnd + std::llround(kHorizon / dt);
  int64_t lastOut = -1;
  *sway = 0;
  for (int64_t t = 0; t < end; ++t) {
    if (!w.step(TickInput{}).ok) {
      *settle = -1;
      return;
    }
    const double offset = tipOffset(w);
    if (t >= start) *sway = std::max(*sway, offset);
    if (offset > kWithin) lastOut = t;
  }
  *settle = lastOut < end - std::llround(10 / dt) ? double(std::max<int64_t>(0, lastOut + 1 - gustEnd)) * dt : -1;
}

}  // namespace

ModelBehaviour measureModelBehaviour(const Scenario& scenario) {
  const Scenario tuft = oneTuft(scenario);
  const std::vector<WindGust> gust = strongestGust(scenario);
  ModelBehaviour b;
  double unused = 0;
  runGust(tuft, gust, 0, &b.swayStart, &b.settleAfterGust);
  runGust(tuft, gust, kLateStart, &b.swayLate, &unused);

  // A press: the tip at 70 degrees, at rest, trampled where the model tramples; no wind.
  Scenario calm = tuft;
  calm.wind.schedule.clear();
  validateForScalar(calm, ScalarKind::Double, 0);
  World<double> w(calm, 1);
  auto& p = w.mutableParticles();
  const double L = w.particleConstants().rodLength, angle = kPressAngle;
  p.px[0] = p.anchorX[0] + L * std::sin(angle);
  p.py[0] = p.anchorY[0] + L * std::cos(angle);
  p.vx[0] = p.vy[0] = p.vz[0] = 0;
  if (!p.trample.empty()) p.trample[0] = 1;
  const double dt = calm.timeStep.toDouble();
  const int64_t end = std::llround(kHorizon / dt);
  int64_t lastOut = -1, lastDown = -1;
  for (int64_t t = 0; t < end; ++t) {
    if (!w.step(TickInput{}).ok) return b;
    if (tipOffset(w) > kWithin) lastOut = t;
    if (p.py[0] - p.anchorY[0] < L / 2) lastDown = t;
  }
  b.settleAfterPress = lastOut < end - std::llround(10 / dt) ? double(lastOut + 1) * dt : -1;
  b.downAfterPress = double(lastDown + 1) * dt;
  return b;
}

namespace {

/// The truth for `s`'s tuft: its length and mass, its blade frequency and damping ratio.
ReferenceBlade referenceFor(const Scenario& s) {
  ReferenceBladeParams p;
  p.length = s.particles.constraintLength.toDouble();
  p.mass = s.particles.mass.toDouble();
  p.frequency = s.particles.blade.frequency.toDouble();
  p.dampingRatio = s.particles.blade.dampingRatio.toDouble();
  return ReferenceBlade(p);
}

/// |model tip offset - reference tip| of this tick, added to the sums.
void compareTips(const World<double>& w, const ReferenceBlade& ref, double* sumSq, double* worst) {
  const auto& p = w.particles();
  const auto t = ref.tip();
  const double e = std::sqrt(std::pow(p.px[0] - p.anchorX[0] - t[0], 2) + std::pow(p.py[0] - p.anchorY[0] - t[1], 2) +
                             std::pow(p.pz[0] - p.anchorZ[0] - t[2], 2));
  *sumSq += e * e;
  *worst = std::max(*worst, e);
}

}  // namespace

ModelError measureModelError(const Scenario& scenario, const Rational& dt) {
  Scenario tuft = oneTuft(scenario);
  tuft.timeStep = dt;
  validateForScalar(tuft, ScalarKind::Double, 0);
  const double h = dt.toDouble();
  ModelError out;
  double sumSq = 0;
  int64_t compared = 0;

  // The scenario's wind at the tuft, tick by tick, exactly as the world's schedule has it.
  const ScenarioConstants constants = deriveConstants(tuft);
  const WindSchedule schedule = WindSchedule::build(tuft, constants);
  {
    World<double> w(tuft, 1);
    ReferenceBlade ref = referenceFor(tuft);
    const int64_t ticks = std::llround(kErrorWindSeconds / h);
    for (int64_t t = 0; t < ticks; ++t) {
      std::array<double, 3> force{0, 0, 0};
      for (size_t g = 0; g < schedule.gusts.size(); ++g) {
        const bool on = schedule.gusts[g].swept ? schedule.activeAt(g, 0, 0, t) : schedule.active(g, 0, t);
        if (!on) continue;
        for (int c = 0; c < 3; ++c) force[size_t(c)] += tuft.wind.schedule[g].force[size_t(c)].toDouble();
      }
      if (!w.step(TickInput{}).ok) return {INFINITY, INFINITY, double(compared) * h};
      ref.advance(h, force);
      compareTips(w, ref, &sumSq, &out.tipMax);
      ++compared;
    }
  }
  // The press: the tip (and the reference blade, straight) at 70 degrees, at rest, let go.
  {
    Scenario calm = tuft;
    calm.wind.schedule.clear();
    World<double> w(calm, 1);
    auto& p = w.mutableParticles();
    const double L = w.particleConstants().rodLength;
    p.px[0] = p.anchorX[0] + L * std::sin(kPressAngle);
    p.py[0] = p.anchorY[0] + L * std::cos(kPressAngle);
    p.pz[0] = p.anchorZ[0];
    p.vx[0] = p.vy[0] = p.vz[0] = 0;
    ReferenceBlade ref = referenceFor(calm);
    ref.bendTo(kPressAngle);
    const int64_t ticks = std::llround(kErrorPressSeconds / h);
    for (int64_t t = 0; t < ticks; ++t) {
      if (!w.step(TickInput{}).ok) return {INFINITY, INFINITY, double(compared) * h};
      ref.advance(h, {0, 0, 0});
      compareTips(w, ref, &sumSq, &out.tipMax);
      ++compared;
    }
  }
  out.tipRms = compared > 0 ? std::sqrt(sumSq / double(compared)) : 0;
  out.seconds = double(compared) * h;
  return out;
}

}  // namespace sg
