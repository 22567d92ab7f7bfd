// Shared pieces of the benchmark suites: a per-stage wall-clock timer (outside the core: the core
// never reads a clock) and the three bodies the collision benchmarks roll through the meadow.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <vector>

#include "sim/world/world.h"

namespace sg::bench {

/// Sums each stage's wall-clock time over the ticks it observes, ns.
class StageTimer final : public StageObserver {
 public:
  void stageBegin(Stage) override { start_ = std::chrono::steady_clock::now(); }
  void stageEnd(Stage s) override {
    nanos[size_t(s)] += std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start_).count();
  }
  std::array<double, size_t(Stage::Count)> nanos{};

 private:
  std::chrono::steady_clock::time_point start_;
};

/// The q-quantile (0..1) of v, by the nearest rank (0 for no values).
inline double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[std::min(v.size() - 1, size_t(q * double(v.size())))];
}

/// The thesis meadow (tufts 0.1 m apart, the built-in scenario's wind) at side x side patches.
inline Scenario plainMeadow(int64_t side, int k, ScalarKind scalar) {
  Scenario s = parseScenario(defaultScenarioText(), "<built-in>", {});
  s.field.patchesX = s.field.patchesZ = side;
  s.field.spacing = Rational{1, 10};
  s.particles.interpolation = k;
  s.scalar = scalar;
  return s;
}

/// A sphere of radius radiusCm cm resting on the ground at (x, z) m, rolling at (2, 0, 1) m/s.
inline BodySpec rollingSphere(const char* name, int64_t radiusCm, int64_t x, int64_t z) {
  BodySpec b;
  b.name = name;
  ShapeSpec p;
  p.type = ShapeType::Sphere;
  p.radius = Rational{radiusCm, 100};
  b.parts = {p};
  b.position = {Rational{x, 1}, Rational{radiusCm, 100}, Rational{z, 1}};
  b.velocity = {Rational{2, 1}, Rational{0, 1}, Rational{1, 1}};
  return b;
}

/// The thesis' three bodies: a football, a bunny-sized sphere and a 0.7 m box, rolling.
inline std::vector<BodySpec> threeRollingBodies() {
  std::vector<BodySpec> list = {rollingSphere("football", 30, -5, -3), rollingSphere("bunny", 40, -3, 3)};
  BodySpec box = rollingSphere("box", 35, 4, 0);
  box.parts[0].type = ShapeType::Box;
  box.parts[0].halfExtents = {Rational{35, 100}, Rational{35, 100}, Rational{35, 100}};
  list.push_back(box);
  return list;
}

}  // namespace sg::bench
