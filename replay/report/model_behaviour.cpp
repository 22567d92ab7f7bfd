#include "replay/report/model_behaviour.h"

#include <algorithm>
#include <cmath>

#include "sim/world/world.h"

namespace sg {
namespace {

constexpr double kWithin = 0.05;     // m: "back within 5 cm"
constexpr double kHorizon = 200;     // s looked at after the gust or the press
constexpr int64_t kLateStart = 600;  // s: "ten minutes in"

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
  const double L = w.particleConstants().rodLength, angle = 70 * 3.14159265358979323846 / 180;
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

}  // namespace sg
