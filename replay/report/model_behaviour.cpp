#include "replay/report/model_behaviour.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

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
constexpr double kErrorBodySeconds = 10;   // s of each body passing in the model-error run
/// A ball passing the tuft, in rod lengths L (and L per second), off to one side of the root so
/// the push is not in a plane. The first skims the tips (its bottom 0.7 L up: bodies rolling over
/// a meadow of tips, the thesis' case); the second goes through the blade's middle (bottom 0.1 L
/// up), which a model that only has a tip particle cannot feel until the ball reaches the tip.
struct PassingBall {
  double radius, height, beside, start, speed;
};
constexpr PassingBall kBalls[2] = {{0.5, 1.2, 0.2, -2, 1}, {0.5, 0.6, 0.2, -2, 1}};
constexpr int64_t kBallMassRatio = 1000;  // the ball's mass over the particle's: it pushes a tip 1000/1001 of its depth
constexpr int64_t kBallGrid =
    int64_t(1) << 20;  // L rounded to 2^-20 m (~1 µm) for the ball: exact fractions that stay small
constexpr double kPressAngle = 70 * 3.14159265358979323846 / 180;

/// The tuft pressed to kPressAngle, at rest.
void press(World<double>& w) {
  auto& p = w.mutableParticles();
  const double L = w.particleConstants().rodLength;
  p.px[0] = p.anchorX[0] + L * std::sin(kPressAngle);
  p.py[0] = p.anchorY[0] + L * std::cos(kPressAngle);
  p.pz[0] = p.anchorZ[0];
  p.vx[0] = p.vy[0] = p.vz[0] = 0;
}

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
  press(w);
  auto& p = w.mutableParticles();
  const double L = w.particleConstants().rodLength;
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

/// The scenario's one tuft at time step dt, validated (throws ScenarioError).
Scenario errorTuft(const Scenario& scenario, const Rational& dt) {
  Scenario tuft = oneTuft(scenario);
  tuft.timeStep = dt;
  validateForScalar(tuft, ScalarKind::Double, 0);
  return tuft;
}

int64_t windTicks(double dt) { return std::llround(kErrorWindSeconds / dt); }
int64_t pressTicks(double dt) { return std::llround(kErrorPressSeconds / dt); }
int64_t bodyTicks(double dt) { return std::llround(kErrorBodySeconds / dt); }

/// The rod length the balls scale with: L rounded to kBallGrid (a long decimal L, 0.1234567890123 m,
/// made the ball's exact volume overflow), the same in the world and the reference.
Rational ballScale(const Scenario& tuft) {
  const double L = tuft.particles.constraintLength.toDouble();
  if (!(L * double(kBallGrid) >= 1) || !(L < 1e9))
    throw ScenarioError(tuft.sourceName, "$.particles.constraintLength",
                        "a rod length from 1 µm to 1e9 m for the model error's passing balls");
  return Rational::make(std::llround(L * double(kBallGrid)), kBallGrid).value();
}

/// The tuft in still air with a passing ball (runs 3 and 4), untrampled, without grass drag (the
/// ball keeps its speed): validated (throws ScenarioError).
Scenario passingBall(const Scenario& tuft, const PassingBall& b) {
  Scenario s = tuft;
  s.wind.schedule.clear();
  s.particles.blade.trampleSeconds = Rational{0, 1};
  s.bodies.gravity = {Rational{0, 1}, Rational{0, 1}, Rational{0, 1}};
  s.bodies.grassDrag = Rational{0, 1};
  const Rational L = ballScale(tuft);
  auto times = [&](double k) {  // k L, exactly (k in tenths; L a multiple of 2^-20 below 1e9: no overflow)
    return mul(L, Rational{int64_t(std::llround(k * 10)), 10}).value();
  };
  BodySpec ball;
  ball.name = "passing ball";
  ShapeSpec sphere;
  sphere.type = ShapeType::Sphere;
  sphere.radius = times(b.radius);
  ball.parts = {sphere};
  const std::optional<Rational> mass = mul(s.particles.mass, Rational::integer(kBallMassRatio));
  if (!mass) throw ScenarioError(s.sourceName, "$.particles.mass", "a particle mass the passing ball can scale with");
  ball.mass = *mass;
  ball.position = {times(b.start), times(b.height), times(b.beside)};  // oneTuft: ground at 0
  ball.velocity = {times(b.speed), Rational{0, 1}, Rational{0, 1}};
  ball.canSleep = false;
  s.bodies.list = {ball};
  validateForScalar(s, ScalarKind::Double, 0);
  return s;
}

/// The reference ball over tick t (1-based: the world's ball is at start + v t dt after step t),
/// relative to the root.
ReferenceBall referenceBall(const PassingBall& p, double L, double dt, int64_t t) {
  ReferenceBall b;
  b.radius = p.radius * L;
  b.from = {L * (p.start + p.speed * dt * double(t - 1)), p.height * L, p.beside * L};
  b.to = {L * (p.start + p.speed * dt * double(t)), p.height * L, p.beside * L};
  return b;
}

/// The two ball runs' scenarios, or none, with `why` (one line), when they do not validate: the
/// model error is then the wind and the press alone.
std::optional<std::array<Scenario, 2>> passingBalls(const Scenario& tuft, std::string* why) {
  try {
    return std::array<Scenario, 2>{passingBall(tuft, kBalls[0]), passingBall(tuft, kBalls[1])};
  } catch (const ScenarioError& e) {
    *why = e.what();
    return std::nullopt;
  }
}

}  // namespace

std::vector<std::array<double, 3>> referenceTips(const Scenario& scenario, const Rational& dt) {
  const Scenario tuft = errorTuft(scenario, dt);
  const double h = dt.toDouble();
  std::vector<std::array<double, 3>> tips;
  // The scenario's wind at the tuft, tick by tick, exactly as the world's schedule has it.
  const WindSchedule schedule = WindSchedule::build(tuft, deriveConstants(tuft));
  ReferenceBlade ref = referenceFor(tuft);
  for (int64_t t = 0, ticks = windTicks(h); t < ticks; ++t) {
    std::array<double, 3> force{0, 0, 0};
    for (size_t g = 0; g < schedule.gusts.size(); ++g) {
      const bool on = schedule.gusts[g].swept ? schedule.activeAt(g, 0, 0, t) : schedule.active(g, 0, t);
      if (!on) continue;
      for (size_t c = 0; c < 3; ++c) force[c] += tuft.wind.schedule[g].force[c].toDouble();
    }
    ref.advance(h, force);
    tips.push_back(ref.tip());
  }
  // The press: the blade straight at 70 degrees, at rest, let go in still air.
  ref.bendTo(kPressAngle);
  for (int64_t t = 0, ticks = pressTicks(h); t < ticks; ++t) {
    ref.advance(h, {0, 0, 0});
    tips.push_back(ref.tip());
  }
  // The bodies passing: the blade upright at rest, a ball moving through it (where the ball's
  // scenario validates: passingBalls).
  std::string why;
  if (!passingBalls(tuft, &why)) return tips;
  const double L = ballScale(tuft).toDouble();
  for (const PassingBall& pass : kBalls) {
    ref.bendTo(0);
    for (int64_t t = 1, ticks = bodyTicks(h); t <= ticks; ++t) {
      const ReferenceBall ball = referenceBall(pass, L, h, t);
      ref.advance(h, {0, 0, 0}, &ball);
      tips.push_back(ref.tip());
    }
  }
  return tips;
}

ModelError measureModelError(const Scenario& scenario, const Rational& dt,
                             const std::vector<std::array<double, 3>>* reference) {
  const Scenario tuft = errorTuft(scenario, dt);
  const double h = dt.toDouble();
  std::vector<std::array<double, 3>> own;
  if (!reference) reference = &(own = referenceTips(scenario, dt));
  std::string why;
  const std::optional<std::array<Scenario, 2>> passes = passingBalls(tuft, &why);
  const int64_t wind = windTicks(h), pressed = wind + pressTicks(h), passTicks = passes ? bodyTicks(h) : 0;
  const int64_t total = pressed + 2 * passTicks;
  if (int64_t(reference->size()) != total)
    throw std::invalid_argument("measureModelError: the reference tips are not of this scenario and dt");
  ModelError out;
  if (!passes) {
    out.bodyRms = out.bodyMax = out.passRms[0] = out.passRms[1] = NAN;
    out.bodyError = why;
  }
  double sumSq = 0, bodySumSq = 0, passSumSq[2] = {0, 0};
  int64_t compared = 0;
  const auto failed = [&] {
    return ModelError{INFINITY, INFINITY, double(compared) * h, INFINITY, INFINITY, {INFINITY, INFINITY}, why};
  };
  auto compare = [&](const World<double>& w) {
    const auto& p = w.particles();
    const auto& t = (*reference)[size_t(compared)];
    const double ex = p.px[0] - p.anchorX[0] - t[0], ey = p.py[0] - p.anchorY[0] - t[1],
                 ez = p.pz[0] - p.anchorZ[0] - t[2];
    const double e = std::sqrt(ex * ex + ey * ey + ez * ez);
    sumSq += e * e;
    out.tipMax = std::max(out.tipMax, e);
    if (compared >= pressed) {
      passSumSq[(compared - pressed) / passTicks] += e * e;
      bodySumSq += e * e;
      out.bodyMax = std::max(out.bodyMax, e);
    }
    ++compared;
  };
  {
    World<double> w(tuft, 1);
    for (int64_t t = 0; t < wind; ++t) {
      if (!w.step(TickInput{}).ok) return failed();
      compare(w);
    }
  }
  {
    Scenario calm = tuft;
    calm.wind.schedule.clear();
    World<double> w(calm, 1);
    press(w);
    while (compared < pressed) {
      if (!w.step(TickInput{}).ok) return failed();
      compare(w);
    }
  }
  for (size_t k = 0; passes && k < 2; ++k) {
    World<double> w((*passes)[k], 1);
    for (int64_t t = 0; t < passTicks; ++t) {
      if (!w.step(TickInput{}).ok) return failed();
      compare(w);
    }
  }
  out.tipRms = compared > 0 ? std::sqrt(sumSq / double(compared)) : 0;
  if (passes && passTicks > 0) {
    out.bodyRms = std::sqrt(bodySumSq / double(2 * passTicks));
    for (size_t k = 0; k < 2; ++k) out.passRms[k] = std::sqrt(passSumSq[k] / double(passTicks));
  }
  out.seconds = double(compared) * h;
  return out;
}

}  // namespace sg
