// Scalar-specific checks: does this scenario fit the chosen number format and the memory?
#include <algorithm>
#include <cmath>
#include <sstream>

#include "sim/bodies/rigid_body.h"
#include "sim/scenario/derived.h"

namespace sg {
namespace {
double d(const Rational& r) { return r.toDouble(); }

std::string metres(double v) {
  std::ostringstream o;
  o.precision(6);
  o << v << " m";
  return o.str();
}

template <class S>
void checkResolution(const Scenario& s) {
  using T = ScalarTraits<S>;
  auto nonZero = [&](const Rational& r, const char* path, const char* what) {
    auto v = T::fromRational(r);
    if (!v || *v == S(0))
      throw ScenarioError(
          s.sourceName, path,
          std::string(what) + " that does not round to zero in " + scalarName(T::kind) + ", got " + r.toString());
  };
  nonZero(s.timeStep, "$.timeStep", "a time step");
  nonZero(s.field.spacing, "$.field.spacing", "a spacing");
  nonZero(s.particles.constraintLength, "$.particles.constraintLength", "a constraint length");
  nonZero(s.wind.travelSpeed, "$.wind.travelSpeed", "a travel speed");
  auto perTick = deterministicPow(s.particles.damping, s.timeStep);
  nonZero(perTick, "$.particles.damping", "a damping whose per-tick factor damping^dt stays a value");
}
}  // namespace

uint64_t estimateWorldBytes(const Scenario& s, ScalarKind scalar) {
  const uint64_t sz = scalar == ScalarKind::Fx16 || scalar == ScalarKind::Float ? 4 : 8;
  const uint64_t k = uint64_t(s.particles.interpolation);
  uint64_t nx = uint64_t(s.field.patchesX), nz = uint64_t(s.field.patchesZ);
  uint64_t px = (nx - 1 + k - 1) / k + 1, pz = (nz - 1 + k - 1) / k + 1;
  uint64_t ring = 0;
  if (s.lod.mode == LodMode::Window) {  // only the window is held (and the edge ring)
    px = std::min<uint64_t>(uint64_t(s.lod.windowX), (nx - 1) / k + 1);
    pz = std::min<uint64_t>(uint64_t(s.lod.windowZ), (nz - 1) / k + 1);
    nx = (px - 1) * k + 1;
    nz = (pz - 1) * k + 1;
    const uint64_t m = uint64_t(s.lod.edgeSpacing), r = uint64_t(s.lod.edgeRows);
    ring = (nx / m + 2 + 2 * r) * (nz / m + 2 + 2 * r) * (3 * sz + 4);
  }
  const uint64_t perPatch = 3 * sz + 3 + 3 * sz + 1;  // root, rotation+variant, derived
  const uint64_t perParticle = 9 * sz + 3 * sz;       // p, v, anchor, displacement
  return nx * nz * perPatch + px * pz * perParticle + ring;
}

void validateForScalar(const Scenario& s, ScalarKind scalar, uint64_t memoryLimitBytes) {
  // Memory first: a field that cannot be allocated is the clearest message.
  const uint64_t bytes = estimateWorldBytes(s, scalar);
  if (memoryLimitBytes != 0 && bytes > memoryLimitBytes) {
    std::ostringstream o;
    o.precision(3);
    o << "a field that fits in memory: " << s.field.patchesX << " x " << s.field.patchesZ << " patches need "
      << double(bytes) / (1 << 30) << " GiB, the limit is " << double(memoryLimitBytes) / (1 << 30) << " GiB";
    throw ScenarioError(s.sourceName, "$.field", o.str());
  }
  // Every exact constant the world will use (throws with a path if one cannot be formed).
  const ScenarioConstants derived = deriveConstants(s);
  // Coordinates: every position the world can produce must fit the scalar's safe range.
  dispatchScalar(scalar, [&]<class S>() {
    const double limit = ScalarTraits<S>::maxCoordinate;
    const double k = s.particles.interpolation;
    const double sp = d(s.field.spacing);
    const double reachX = std::fabs(d(s.field.centerX)) + sp * (double(s.field.patchesX) + 2 * k) / 2;
    const double reachZ = std::fabs(d(s.field.centerZ)) + sp * (double(s.field.patchesZ) + 2 * k) / 2;
    const double tall = d(s.particles.constraintLength) + d(s.field.scaleY);
    const double ground = s.terrain.flat ? std::fabs(d(s.terrain.flatHeight)) : d(s.terrain.maxHeight);
    auto check = [&](double reach, const char* path, const char* what) {
      if (!(reach <= limit)) {
        throw ScenarioError(s.sourceName, path,
                            std::string(what) + " within the " + scalarName(ScalarTraits<S>::kind) +
                                " coordinate range (|coordinate| <= " + metres(limit) + "), this one reaches " +
                                metres(reach));
      }
    };
    check(reachX, "$.field.patchesX", "a field");
    check(reachZ, "$.field.patchesZ", "a field");
    check(ground + tall, s.terrain.flat ? "$.terrain.height" : "$.terrain.maxHeight", "a terrain height");
    if (!s.terrain.flat) {
      const double cs = d(s.terrain.cellSize);
      check(std::fabs(d(s.terrain.centerX)) + cs * s.terrain.heightmap.width / 2, "$.terrain.cellSize", "a heightmap");
      check(std::fabs(d(s.terrain.centerZ)) + cs * s.terrain.heightmap.height / 2, "$.terrain.cellSize", "a heightmap");
    }
    for (size_t i = 0; i < s.wind.schedule.size(); ++i)
      for (int c = 0; c < 3; ++c)
        check(std::fabs(d(s.wind.schedule[i].force[c])),
              ("$.wind.schedule[" + std::to_string(i) + "].force[" + std::to_string(c) + "]").c_str(), "a force");
    // Every other number the world converts must fit too (velocities, accelerations, ...).
    auto fits = [&](const Rational& r, const std::string& path) {
      if (!ScalarTraits<S>::fromRational(r) || !(std::fabs(r.toDouble()) <= limit))
        throw ScenarioError(s.sourceName, path,
                            "a value within the " + std::string(scalarName(ScalarTraits<S>::kind)) +
                                " range (|value| <= " + metres(limit).substr(0, metres(limit).size() - 2) + "), got " +
                                r.toString());
    };
    const auto& pa = s.particles;
    for (int c = 0; c < 3; ++c) {
      const std::string i = "[" + std::to_string(c) + "]";
      fits(pa.initialVelocity[size_t(c)], "$.particles.initialVelocity" + i);
      fits(pa.acceleration[size_t(c)], "$.particles.acceleration" + i);
      fits(pa.tiltDrop[size_t(c)], "$.particles.tiltDrop" + i);
    }
    fits(pa.constraintLength, "$.particles.constraintLength");
    fits(pa.mass, "$.particles.mass");
    fits(derived.invMass, "$.particles.mass");
    fits(derived.invDt, "$.timeStep");
    fits(derived.halfRod, "$.particles.constraintLength");
    fits(derived.jitterAmplitude, "$.field.jitter");
    fits(derived.fieldOriginX, "$.field.center[0]");
    fits(derived.fieldOriginZ, "$.field.center[1]");
    fits(s.field.scaleY, "$.field.scaleY");
    fits(s.field.scaleXZ, "$.field.scaleXZ");
    fits(s.field.spacing, "$.field.spacing");
    fits(s.wind.travelSpeed, "$.wind.travelSpeed");
    fits(s.terrain.flatHeight, "$.terrain.height");
    for (size_t i = 0; i < derived.gustForcePerMass.size(); ++i)
      for (int c = 0; c < 3; ++c)
        fits(derived.gustForcePerMass[i][size_t(c)],
             "$.wind.schedule[" + std::to_string(i) + "].force[" + std::to_string(c) + "]");
    if (!s.terrain.flat) {
      fits(s.terrain.cellSize, "$.terrain.cellSize");
      fits(derived.terrainInvCellSize, "$.terrain.cellSize");
      fits(derived.terrainOriginX, "$.terrain.center[0]");
      fits(derived.terrainOriginZ, "$.terrain.center[1]");
      fits(s.terrain.maxHeight, "$.terrain.maxHeight");
    }
    // Bodies: every value fits, positions within the coordinate range, mass properties exact.
    for (int c = 0; c < 3; ++c) fits(s.bodies.gravity[size_t(c)], "$.bodies.gravity[" + std::to_string(c) + "]");
    for (size_t i = 0; i < s.bodies.list.size(); ++i) {
      const BodySpec& b = s.bodies.list[i];
      const std::string q = "$.bodies.list[" + std::to_string(i) + "]";
      for (int c = 0; c < 3; ++c) {
        const std::string ix = "[" + std::to_string(c) + "]";
        for (const auto& [name, value] : {std::pair{".position", &b.position}, std::pair{".velocity", &b.velocity},
                                          std::pair{".angularVelocity", &b.angularVelocity}}) {
          std::string path = q;
          path += name;
          path += ix;
          fits((*value)[size_t(c)], path);
        }
      }
      for (int c = 0; c < 4; ++c) fits(b.orientation[size_t(c)], q + ".orientation[" + std::to_string(c) + "]");
      for (size_t k = 0; k < b.parts.size(); ++k) {
        const std::string pp = b.parts.size() == 1 ? q + ".shape" : q + ".shape.parts[" + std::to_string(k) + "]";
        fits(b.parts[k].radius, pp + ".radius");
        for (int c = 0; c < 3; ++c) {
          fits(b.parts[k].halfExtents[size_t(c)], pp + ".halfExtents[" + std::to_string(c) + "]");
          fits(b.parts[k].offset[size_t(c)], pp + ".offset[" + std::to_string(c) + "]");
        }
      }
      fits(b.mass, q + ".mass");
      try {
        (void)makeBody<S>(b, s.timeStep, s.sourceName, q);
      } catch (const std::out_of_range&) {
        throw ScenarioError(s.sourceName, q + ".mass",
                            std::string("mass properties (1/mass, 1/inertia) within the ") +
                                scalarName(ScalarTraits<S>::kind) + " range");
      }
    }
    checkResolution<S>(s);
  });
  // Scripted values are recorded as Q32.32 inputs: they must fit that format.
  for (size_t i = 0; i < s.script.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const auto raw = s.script[i].value[size_t(c)].toScaledInteger(32);
      if (!raw || *raw > Int128(INT64_MAX) || *raw < Int128(INT64_MIN))
        throw ScenarioError(s.sourceName, "$.script[" + std::to_string(i) + "].value[" + std::to_string(c) + "]",
                            "a value within +-2147483647 (inputs are Q32.32)");
    }
}
}  // namespace sg
