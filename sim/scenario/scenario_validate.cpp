// Scalar-specific checks: does this scenario fit the chosen number format and the memory?
#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "sim/bodies/rigid_body.h"
#include "sim/scenario/derived.h"
#include "sim/scenario/fx16_envelope.h"
#include "sim/scenario/json_bounds.h"

namespace sg {
namespace {

/// Q16.16's largest value: the largest 1/mass and 1/inertia fx16 holds.
constexpr double kFx16MaxImpulse = 32767.0;

/// Why a body's mass properties do not fit S: the first of 1/mass, inertia and 1/inertia (per
/// principal axis) beyond the range, computed in double, with what to do about it.
template <class S>
std::string massPropertiesOutOfRange(const BodySpec& b, const Scenario& s, const std::string& path) {
  std::ostringstream o;
  o << "mass properties (1/mass, inertia, 1/inertia) within the " << scalarName(ScalarTraits<S>::kind) << " range";
  try {
    const RigidBody<double> exact = makeBody<double>(b, s.timeStep, s.sourceName, path);
    const double limit = ScalarTraits<S>::kind == ScalarKind::Fx16 ? kFx16MaxImpulse : 2147483647.0;
    const char* axes = "xyz";
    if (exact.invMass > limit) {
      o << ", got 1/mass = " << exact.invMass << " 1/kg (lighter than " << 1 / limit << " kg)";
    } else {
      for (int k = 0; k < 3; ++k) {
        if (exact.invInertiaLocal[k] > limit) {
          o << ", got 1/inertia about " << axes[k] << " = " << exact.invInertiaLocal[k]
            << " 1/(kg m^2): the body is too small and light (its inertia must be at least " << 1 / limit << " kg m^2)";
          if (ScalarTraits<S>::kind == ScalarKind::Fx16) o << "; use fx32 for bodies this small (docs/fixed-point.md)";
          return o.str();
        }
        if (exact.inertiaLocal[k] > limit) {
          o << ", got inertia about " << axes[k] << " = " << exact.inertiaLocal[k] << " kg m^2";
          return o.str();
        }
      }
    }
  } catch (const std::exception&) {
    // The double body could not be built either: the plain message.
  }
  return o.str();
}
double d(const Rational& r) { return r.toDouble(); }

std::string metres(double v) {
  std::ostringstream o;
  o.precision(6);
  o << v << " m";
  return o.str();
}

template <class S>
void checkResolution(const Scenario& s);

/// The body of validateInputTrack, for an input track ($.commands) or a scenario ($.script).
void validateInputTrack(const InputTrack& track, ScalarKind scalar, const std::string& commandsPath) {
  dispatchScalar(scalar, [&]<class S>() {
    const double limit = ScalarTraits<S>::maxCoordinate;
    const char* name = scalarName(ScalarTraits<S>::kind);
    // Inputs are recorded as Q32.32 (tick_input.h) and rounded into S on use: a value must fit
    // both, or it would saturate (Q32.32) or fault in the step (inputScalar).
    auto fits = [&](const Rational& v, const std::string& path, double bound, const char* what) {
      const auto raw = v.toScaledInteger(32);
      const bool q32 = raw && *raw <= Int128(INT64_MAX) && *raw >= Int128(INT64_MIN);
      if (!q32 || !ScalarTraits<S>::fromRational(v) || !(std::fabs(v.toDouble()) <= bound)) {
        std::ostringstream o;
        o.precision(6);
        // Q32.32 caps every scalar's inputs below 2^31 (float and double included).
        if (bound < 2147483648.0)
          o << what << " within the " << name << " range (|value| <= " << bound << "), got " << v.toString();
        else
          o << what << " within the input range (|value| < 2^31: inputs are recorded as Q32.32), got " << v.toString();
        throw ScenarioError(track.sourceName, path, o.str());
      }
    };
    for (size_t i = 0; i < track.camera.size(); ++i)
      for (int c = 0; c < 3; ++c)
        fits(track.camera[i].position[size_t(c)],
             "$.camera[" + std::to_string(i) + "].position[" + std::to_string(c) + "]", limit, "a camera coordinate");
    for (const ScriptedCommand& cmd : track.commands) {
      // Positions (displace, teleport, spawn) stay in the coordinate range; velocities and
      // impulses in it too (a velocity beyond it leaves the range within a second).
      const char* what = cmd.kind == BodyCommandKind::Teleport || cmd.kind == BodyCommandKind::Spawn ? "a position"
                         : cmd.kind == BodyCommandKind::Displace                                     ? "a displacement"
                                                                                                     : "a value";
      for (int c = 0; c < 3; ++c)
        fits(cmd.value[size_t(c)],
             commandsPath + "[" + std::to_string(cmd.source) + "].value[" + std::to_string(c) + "]", limit, what);
    }
  });
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
  if (!s.bodies.list.empty()) {  // the soft step's sub-step h = timeStep / substeps (world.cpp)
    nonZero(*div(s.timeStep, Rational{s.bodies.substeps, 1}), "$.bodies.substeps", "a sub-step (timeStep / substeps)");
    // A spring of 0 Hz would be taken as a rigid contact without push-out (makeSoftness): a
    // frequency the scalar rounds to zero is an error, not that switch.
    nonZero(s.bodies.contactHertz, "$.bodies.contactHertz", "a contact frequency");
  }
  nonZero(s.field.spacing, "$.field.spacing", "a spacing");
  nonZero(s.particles.constraintLength, "$.particles.constraintLength", "a constraint length");
  nonZero(s.wind.travelSpeed, "$.wind.travelSpeed", "a travel speed");
  auto perTick = deterministicPow(s.particles.damping, s.timeStep);
  nonZero(perTick, "$.particles.damping", "a damping whose per-tick factor damping^dt stays a value");
  if (s.particles.model == GrassModel::Blade) {
    const ScenarioConstants c = deriveConstants(s);
    nonZero(c.bladeStiffnessDt, "$.particles.blade.frequency", "a blade stiffness x timeStep (from the frequency)");
    // exp(-4 pi dampingRatio frequency timeStep) below the scalar's resolution stops every blade
    // dead each tick: named with its exponent, not as the 0 it rounds to.
    if (!T::fromRational(c.bladeDampingPerTick) || *T::fromRational(c.bladeDampingPerTick) == S(0)) {
      std::ostringstream o;
      o.precision(4);
      o << "a damping whose per-tick decay exp(-4 pi dampingRatio frequency timeStep) = exp(-"
        << c.bladeDampingRate.toDouble() * s.timeStep.toDouble() << ") does not round to zero in "
        << scalarName(T::kind) << ", got dampingRatio " << s.particles.blade.dampingRatio.toString();
      throw ScenarioError(s.sourceName, "$.particles.blade.dampingRatio", o.str());
    }
    if (!c.trampleDecayPerTick.isZero())
      nonZero(c.trampleDecayPerTick, "$.particles.blade.trampleSeconds", "a timeStep / trampleSeconds");
  }
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
  // p, v, anchor, displacement; a trampling blade its trample level
  const bool tramples = s.particles.model == GrassModel::Blade && !s.particles.blade.trampleSeconds.isZero();
  const uint64_t perParticle = 9 * sz + 3 * sz + (tramples ? sz : 0);
  // Per particle row of the whole field (not only the window): the gust front's delays from the
  // first and the last row (int64 each, twice: the constants and the schedule) and the row's
  // wind acceleration.
  const uint64_t fieldRows = (uint64_t(s.field.patchesZ) - 1 + k - 1) / k + 1;
  const uint64_t rows = fieldRows * (uint64_t(4 * 8) + 3 * sz);
  // A heightmap is held three times: the scenario's decoded samples, the world's heights in S
  // and the scenario copy a recording or a viewer keeps (one byte per sample each but the heights).
  const uint64_t samples =
      s.terrain.flat ? 0 : uint64_t(s.terrain.heightmap.width) * uint64_t(s.terrain.heightmap.height);
  const uint64_t terrain = samples * (2 + sz);
  return nx * nz * perPatch + px * pz * perParticle + ring + rows + terrain;
}

void validateForScalar(const Scenario& s, ScalarKind scalar, uint64_t memoryLimitBytes) {
  // Memory first: a field that cannot be allocated is the clearest message.
  const uint64_t bytes = estimateWorldBytes(s, scalar);
  if (memoryLimitBytes != 0 && bytes > memoryLimitBytes) {
    std::ostringstream o;
    o.precision(3);
    const bool heightmap = !s.terrain.flat;
    o << "a " << (heightmap ? "field and heightmap" : "field") << " that fits in memory: " << s.field.patchesX << " x "
      << s.field.patchesZ << " patches";
    if (heightmap) o << " and " << s.terrain.heightmap.width << " x " << s.terrain.heightmap.height << " samples";
    o << " need " << double(bytes) / (1 << 30) << " GiB, the limit is " << double(memoryLimitBytes) / (1 << 30)
      << " GiB";
    // Blame the bigger of the two: the heightmap when it alone is over half the estimate.
    Scenario flat;
    flat.field = s.field;
    flat.particles = s.particles;
    flat.lod = s.lod;
    const uint64_t fieldBytes = estimateWorldBytes(flat, scalar);
    throw ScenarioError(s.sourceName, heightmap && bytes - fieldBytes > fieldBytes ? "$.terrain.file" : "$.field",
                        o.str());
  }
  // Every exact constant the world will use (throws with a path if one cannot be formed).
  const ScenarioConstants derived = deriveConstants(s);
  // The blade's spring is integrated explicitly (sim/particles/blade.h): stable while
  // omega dt < 2, accurate to a few per cent of the period while omega dt <= 1.
  // The stiffness is (2 pi f)^2 - acceleration.y / L: the error names whichever term is larger
  // (under gravity a short blade, g / L, can be what is too stiff for the step).
  const auto omegaDtSquared = mul(derived.bladeStiffnessDt, s.timeStep);
  if (s.particles.model == GrassModel::Blade && (!omegaDtSquared || compare(*omegaDtSquared, Rational{1, 1}) > 0)) {
    const double omega = 2 * std::numbers::pi * s.particles.blade.frequency.toDouble();
    const double lift = -s.particles.acceleration[1].toDouble() / s.particles.constraintLength.toDouble();
    std::ostringstream o;
    o.precision(4);
    o << "a blade whose stiffness x timeStep^2 is at most 1 (the explicit spring's omega dt <= 1), got stiffness "
      << derived.bladeStiffness.toDouble() << " /s^2 = (2 pi frequency)^2 = " << omega * omega
      << " plus -acceleration.y / constraintLength = " << lift << ", at timeStep " << s.timeStep.toString()
      << ": lower the frequency, lengthen the blade or shorten the time step";
    throw ScenarioError(
        s.sourceName, omega * omega >= lift ? "$.particles.blade.frequency" : "$.particles.constraintLength", o.str());
  }
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
    // A reach is a sum of terms; the fault is reported at the largest term's key, the one to change.
    auto largest = [](std::initializer_list<std::pair<double, const char*>> terms) {
      const char* path = terms.begin()->second;
      double most = -1;
      for (const auto& [value, key] : terms)
        if (!(value <= most)) most = value, path = key;  // NaN/inf terms win
      return path;
    };
    // The field's half extent is spacing x patches: blame the spacing when even a one-patch field
    // at that spacing would not fit, else the patch count along the axis that does not fit.
    const bool spacingAlone = std::fabs(sp) * (1 + 2 * k) / 2 > limit;
    const char* extentX = spacingAlone ? "$.field.spacing" : "$.field.patchesX";
    const char* extentZ = spacingAlone ? "$.field.spacing" : "$.field.patchesZ";
    check(reachX,
          largest({{reachX - std::fabs(d(s.field.centerX)), extentX},
                   {std::fabs(d(s.field.centerX)), "$.field.center[0]"}}),
          "a field (|center| + spacing x patches / 2)");
    check(reachZ,
          largest({{reachZ - std::fabs(d(s.field.centerZ)), extentZ},
                   {std::fabs(d(s.field.centerZ)), "$.field.center[1]"}}),
          "a field (|center| + spacing x patches / 2)");
    check(ground + tall,
          largest({{ground, s.terrain.flat ? "$.terrain.height" : "$.terrain.maxHeight"},
                   {std::fabs(d(s.particles.constraintLength)), "$.particles.constraintLength"},
                   {std::fabs(d(s.field.scaleY)), "$.field.scaleY"}}),
          "a blade top (terrain height + constraintLength + scaleY)");
    if (!s.terrain.flat) {
      const double cs = d(s.terrain.cellSize);
      const double halfW = cs * s.terrain.heightmap.width / 2, halfH = cs * s.terrain.heightmap.height / 2;
      check(std::fabs(d(s.terrain.centerX)) + halfW,
            largest({{halfW, "$.terrain.cellSize"}, {std::fabs(d(s.terrain.centerX)), "$.terrain.center[0]"}}),
            "a heightmap (|center| + cellSize x samples / 2)");
      check(std::fabs(d(s.terrain.centerZ)) + halfH,
            largest({{halfH, "$.terrain.cellSize"}, {std::fabs(d(s.terrain.centerZ)), "$.terrain.center[1]"}}),
            "a heightmap (|center| + cellSize x samples / 2)");
    }
    for (size_t i = 0; i < s.wind.schedule.size(); ++i)
      for (int c = 0; c < 3; ++c)
        check(std::fabs(d(s.wind.schedule[i].force[c])),
              ("$.wind.schedule[" + std::to_string(i) + "].force[" + std::to_string(c) + "]").c_str(), "a force");
    // Every other number the world converts must fit too (velocities, accelerations, ...).
    // `derivedName`: the value checked is a constant the world derives from the one at `path`
    // (1/mass, 1/dt, ...); the message says so instead of calling 1e30 the value written.
    auto fits = [&](const Rational& r, const std::string& path, const char* derivedName = nullptr) {
      if (!ScalarTraits<S>::fromRational(r) || !(std::fabs(r.toDouble()) <= limit)) {
        const std::string range = std::string(scalarName(ScalarTraits<S>::kind)) +
                                  " range (|value| <= " + metres(limit).substr(0, metres(limit).size() - 2) + ")";
        if (derivedName)
          throw ScenarioError(s.sourceName, path,
                              "a value whose " + std::string(derivedName) + " is within the " + range + ", got " +
                                  derivedName + " = " + echoText(r.toString()));
        throw ScenarioError(s.sourceName, path, "a value within the " + range + ", got " + echoText(r.toString()));
      }
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
    fits(derived.invMass, "$.particles.mass", "1/mass");
    fits(derived.invDt, "$.timeStep", "1/timeStep");
    if (!s.bodies.list.empty())
      fits(*div(Rational{s.bodies.substeps, 1}, s.timeStep), "$.bodies.substeps", "substeps/timeStep");
    fits(derived.halfRod, "$.particles.constraintLength", "constraintLength/2");
    fits(derived.jitterAmplitude, "$.field.jitter", "jitter x spacing");
    fits(derived.fieldOriginX, "$.field.center[0]", "field corner x");
    fits(derived.fieldOriginZ, "$.field.center[1]", "field corner z");
    fits(s.field.scaleY, "$.field.scaleY");
    fits(s.field.scaleXZ, "$.field.scaleXZ");
    fits(s.field.spacing, "$.field.spacing");
    fits(s.wind.travelSpeed, "$.wind.travelSpeed");
    fits(s.terrain.flatHeight, "$.terrain.height");
    for (size_t i = 0; i < derived.gustForcePerMass.size(); ++i)
      for (int c = 0; c < 3; ++c)
        fits(derived.gustForcePerMass[i][size_t(c)],
             "$.wind.schedule[" + std::to_string(i) + "].force[" + std::to_string(c) + "]", "force/mass");
    if (!s.terrain.flat) {
      fits(s.terrain.cellSize, "$.terrain.cellSize");
      fits(derived.terrainInvCellSize, "$.terrain.cellSize", "1/cellSize");
      fits(derived.terrainOriginX, "$.terrain.center[0]", "heightmap corner x");
      fits(derived.terrainOriginZ, "$.terrain.center[1]", "heightmap corner z");
      fits(s.terrain.maxHeight, "$.terrain.maxHeight");
    }
    // Bodies: every value fits, positions within the coordinate range, mass properties exact.
    for (int c = 0; c < 3; ++c) fits(s.bodies.gravity[size_t(c)], "$.bodies.gravity[" + std::to_string(c) + "]");
    for (size_t i = 0; i < s.bodies.list.size(); ++i) {
      const BodySpec& b = s.bodies.list[i];
      const std::string q = "$.bodies.list[" + std::to_string(i) + "]";
      for (int c = 0; c < 3; ++c) {
        // Appended, not "[" + std::to_string(c) + "]": GCC 12 at -O3 reports that expression's
        // inlined copy as an overlapping memcpy (a false positive, GCC bug 105329) where it sees
        // more of the code at once (the unity build).
        std::string ix = "[";
        ix += std::to_string(c);
        ix += "]";
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
        const std::string pp = !b.compound ? q + ".shape" : q + ".shape.parts[" + std::to_string(k) + "]";
        fits(b.parts[k].radius, pp + ".radius");
        for (int c = 0; c < 3; ++c) {
          fits(b.parts[k].halfExtents[size_t(c)], pp + ".halfExtents[" + std::to_string(c) + "]");
          fits(b.parts[k].offset[size_t(c)], pp + ".offset[" + std::to_string(c) + "]");
        }
      }
      fits(b.mass, q + ".mass");
      fits(b.friction, q + ".friction");
      fits(b.restitution, q + ".restitution");
      fits(b.linearDamping, q + ".linearDamping");
      fits(b.angularDamping, q + ".angularDamping");
      // The shape must fit the coordinate range too: its bounding radius |offset| + |halfExtents|
      // is computed in S (a fixed-point norm squares each component).
      for (size_t k = 0; k < b.parts.size(); ++k) {
        const std::string pp = !b.compound ? q + ".shape" : q + ".shape.parts[" + std::to_string(k) + "]";
        const ShapeSpec& part = b.parts[k];
        double reach2 = 0, off2 = 0;
        for (int c = 0; c < 3; ++c) {
          const double h =
              part.type == ShapeType::Sphere ? (c == 0 ? d(part.radius) : 0) : d(part.halfExtents[size_t(c)]);
          reach2 += h * h;
          off2 += d(part.offset[size_t(c)]) * d(part.offset[size_t(c)]);
        }
        check(std::sqrt(reach2), (pp + (part.type == ShapeType::Sphere ? ".radius" : ".halfExtents")).c_str(),
              "a body part whose size");
        check(std::sqrt(off2), (pp + ".offset").c_str(), "a body part offset whose length");
        // Squares of sizes are formed in S (norm(), contact distances, sums of two): keep them
        // within a quarter of the range like coordinates (fixed point only).
        if (ScalarTraits<S>::isFixed && !(std::max(reach2, off2) <= limit))
          throw ScenarioError(s.sourceName, pp,
                              std::string("a body part whose squared size and offset fit ") +
                                  scalarName(ScalarTraits<S>::kind) +
                                  " (|size|^2 <= " + metres(limit).substr(0, metres(limit).size() - 2) + ")");
      }
      takeFixedFaults();
      try {
        (void)makeBody<S>(b, s.timeStep, s.sourceName, q);
      } catch (const std::out_of_range&) {
        throw ScenarioError(s.sourceName, q + ".mass", massPropertiesOutOfRange<S>(b, s, q));
      }
      if (takeFixedFaults() != 0)
        throw ScenarioError(s.sourceName, q + ".shape",
                            std::string("a body whose shape and mass properties fit the ") +
                                scalarName(ScalarTraits<S>::kind) + " range");
    }
    // Everything else the world converts (world.cpp toS): no value may reach a throwing conversion.
    fits(s.bodies.mowerCutHeight, "$.bodies.mowerCutHeight");
    fits(s.bodies.grassDrag, "$.bodies.grassDrag");
    fits(s.bodies.contactHertz, "$.bodies.contactHertz");
    fits(derived.invParticleSpacing, "$.field.spacing", "1/(spacing x interpolation)");
    fits(derived.dampingPerTick, "$.particles.damping", "damping per tick");
    if (s.particles.model == GrassModel::Blade) {
      fits(derived.bladeStiffnessDt, "$.particles.blade.frequency", "stiffness x timeStep");
      fits(derived.bladeDampingPerTick, "$.particles.blade.dampingRatio", "the damping per tick");
      fits(derived.trampleDecayPerTick, "$.particles.blade.trampleSeconds", "timeStep / trampleSeconds");
      fits(derived.invRodLength, "$.particles.constraintLength", "1/constraintLength");
    }
    if (s.markings.enabled) {
      const auto& m = s.markings;
      check(std::fabs(d(m.centerX)), "$.markings.center[0]", "a markings centre");
      check(std::fabs(d(m.centerZ)), "$.markings.center[1]", "a markings centre");
      check(d(m.length), "$.markings.length", "a markings length");
      check(d(m.width), "$.markings.width", "a markings width");
      check(d(m.lineWidth), "$.markings.lineWidth", "a markings line width");
      check(d(m.centerCircleRadius), "$.markings.centerCircleRadius", "a centre circle radius");
    }
    if (s.lod.mode == LodMode::Window && s.lod.centerGiven) {
      check(std::fabs(d(s.lod.centerX)), "$.lod.center[0]", "a window centre");
      check(std::fabs(d(s.lod.centerZ)), "$.lod.center[1]", "a window centre");
    }
    checkResolution<S>(s);
  });
  // The scenario's own camera track and script are inputs like an input track's.
  InputTrack own;
  own.sourceName = s.sourceName;
  own.camera = s.camera;
  own.commands = s.script;
  validateInputTrack(own, scalar, "$.script");
  // fx16's impact envelope, once every value is known to fit: every contact impulse and inverse
  // effective mass the scene can produce fits Q16.16 (fx16_envelope.h; docs/fixed-point.md).
  if (scalar == ScalarKind::Fx16) checkFx16ImpactEnvelope(s);
}

void validateInputTrack(const InputTrack& track, ScalarKind scalar) { validateInputTrack(track, scalar, "$.commands"); }
}  // namespace sg
