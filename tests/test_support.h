// Shared helpers for the test suites.
#pragma once

/// SIMGRASS_TEST_ASAN: defined under AddressSanitizer (GCC or Clang), whose shadow memory does
/// not mix with an address-space limit (ulimit -v): tests that set one skip themselves. A
/// sanitizer build defines it for the test files (tests/CMakeLists.txt), which are compiled
/// without the sanitizers themselves; the checks below catch a test file built by hand with them.
#if defined(SIMGRASS_TEST_ASAN)
#elif defined(__SANITIZE_ADDRESS__)
#define SIMGRASS_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SIMGRASS_TEST_ASAN 1
#endif
#endif

#include <cstdlib>
#include <string>

#include <xxhash.h>

#include "replay/scenario_files.h"
#include "sim/scenario/scenario.h"
#include "sim/world/world.h"
#include "tests/printers.h"

namespace sg::test {

inline std::string sourcePath(const std::string& rel) { return std::string(SIMGRASS_SOURCE_DIR) + "/" + rel; }

/// True in slow builds (Debug + sanitizers): long-running tests shorten themselves there.
inline bool slowBuild() { return std::getenv("SIMGRASS_SLOW_BUILD") != nullptr; }

/// The built-in thesis meadow, parsed.
inline Scenario thesisMeadow() { return parseScenario(defaultScenarioText(), "<built-in>", {}); }

/// A scenario with one tuft (1 x 1 patches), no wind, given constraint mode.
inline Scenario singleTuft(GrassModel mode) {
  Scenario s = thesisMeadow();
  s.field.patchesX = s.field.patchesZ = 1;
  s.field.jitter = Rational{0, 1};
  s.particles.model = mode;
  s.particles.initialVelocity = {Rational{0, 1}, Rational{0, 1}, Rational{0, 1}};
  s.wind.schedule.clear();
  return s;
}

/// A World<S> for a scenario, validated for S first (tests that need typed access).
template <class S>
std::unique_ptr<World<S>> makeTyped(Scenario s, int threads = 1) {
  s.scalar = ScalarTraits<S>::kind;
  validateForScalar(s, s.scalar, 0);
  return std::make_unique<World<S>>(s, threads);
}

/// (x, y, z) / den as exact fractions.
inline Rational3 r3(int64_t x, int64_t y, int64_t z, int64_t den = 1) {
  return {*Rational::make(x, den), *Rational::make(y, den), *Rational::make(z, den)};
}

/// A tiny meadow far from the bodies (bodies are what the body tests look at).
inline Scenario emptyWorld() {
  Scenario s = thesisMeadow();
  s.field.patchesX = s.field.patchesZ = 2;
  s.field.centerX = Rational{-500, 1};
  s.wind.schedule.clear();
  return s;
}

/// A sphere body of the given radius at a position (defaults for everything else).
inline BodySpec sphere(const char* name, Rational radius, Rational3 position) {
  BodySpec b;
  b.name = name;
  ShapeSpec p;
  p.type = ShapeType::Sphere;
  p.radius = radius;
  b.parts = {p};
  b.position = position;
  return b;
}

/// A box body of the given half extents at a position (defaults for everything else).
inline BodySpec box(const char* name, Rational3 halfExtents, Rational3 position) {
  BodySpec b;
  b.name = name;
  ShapeSpec p;
  p.type = ShapeType::Box;
  p.halfExtents = halfExtents;
  b.parts = {p};
  b.position = position;
  return b;
}

/// An exact plane rising along +x with slope 1/4: samples 15 x (x = 0..16, 1 m apart, the map
/// centred at 0) and maxHeight 17/4 m give h = (x + 8) / 4 exactly, i.e. h(0) = 2.
inline Scenario slope() {
  Scenario s = emptyWorld();
  s.terrain.flat = false;
  s.terrain.cellSize = Rational{1, 1};
  s.terrain.maxHeight = Rational{17, 4};
  s.terrain.heightmap.width = 17;
  s.terrain.heightmap.height = 3;
  for (int z = 0; z < 3; ++z)
    for (int x = 0; x < 17; ++x) s.terrain.heightmap.samples.push_back(uint8_t(15 * x));
  return s;
}

}  // namespace sg::test
