#include "replay/variant.h"

#include <set>
#include <sstream>
#include <stdexcept>

#include "sim/scenario/json_bounds.h"

namespace sg {
namespace {
[[noreturn]] void bad(const std::string& setting, const std::string& expected) {
  throw std::invalid_argument(setting + ": expected " + expected);
}
const char* broadphaseName(ParticleBroadphase b) { return b == ParticleBroadphase::Brute ? "brute" : "grid"; }
const char* bodyBroadphaseName(BodyBroadphase b) { return b == BodyBroadphase::SweepAndPrune ? "sap" : "brute"; }

}  // namespace

VariantSettings VariantSettings::parse(const std::string& text) {
  VariantSettings v;
  // A NUL (or another control character) inside the text cut the error line short where it was
  // printed as a C string, naming a valid item as the fault (a recording's header, an independent
  // pass): refused whole, escaped.
  for (const char ch : text)
    if ((static_cast<unsigned char>(ch) < 0x20 && ch != ' ' && ch != '\t') || ch == 0x7f)
      bad("'" + echoText(escapeControl(text)) + "'", "printable KEY=VALUE items (a control character inside)");
  // "interp=2," or "interp=2,,scalar=fx16" ran as "interp=2" (commas became spaces): an empty
  // item between commas is a typo, as `render --debug 'particles,'` already says.
  {
    std::string item;
    std::istringstream items(text + ",");
    while (std::getline(items, item, ','))
      if (item.find_first_not_of(" \t") == std::string::npos)
        bad("'" + text + "'", "KEY=VALUE items separated by single commas (an empty item)");
  }
  std::string spaced = text;
  for (char& ch : spaced)
    if (ch == ',') ch = ' ';
  std::istringstream in(spaced);
  std::string item;
  std::set<std::string> seen;
  while (in >> item) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size())
      bad(item, "key=value with a key scalar, interp, broadphase, body-broadphase, dt, lod, model, threads or physics");
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    // "scalar=fx16,scalar=double" silently took the last: a variant names each setting once.
    if (!seen.insert(key).second) bad(item, "each key once (" + key + " is given twice)");
    if (key == "scalar") {
      const auto kind = parseScalarKind(value);
      if (!kind) bad(item, "scalar=fx32, fx16, float or double");
      v.scalar = *kind;
    } else if (key == "interp") {
      if (value.size() != 1 || value[0] < '1' || value[0] > '4') bad(item, "interp=1, 2, 3 or 4");
      v.interpolation = value[0] - '0';
    } else if (key == "broadphase") {
      if (value == "grid")
        v.broadphase = ParticleBroadphase::Grid;
      else if (value == "brute")
        v.broadphase = ParticleBroadphase::Brute;
      else
        bad(item, "broadphase=grid or brute");
    } else if (key == "body-broadphase") {
      if (value == "brute")
        v.bodyBroadphase = BodyBroadphase::Brute;
      else if (value == "sap")
        v.bodyBroadphase = BodyBroadphase::SweepAndPrune;
      else
        bad(item, "body-broadphase=brute or sap");
    } else if (key == "dt") {
      std::string why;
      const auto dt = Rational::parse(value, &why);
      if (!dt || dt->isNegative() || dt->isZero() || compare(*dt, Rational{1, 1}) > 0 ||
          compare(*dt, Rational{1, 100000}) < 0)
        bad(item, "dt=a time step from 1e-5 to 1 s, e.g. dt=1/120");
      v.timeStep = *dt;
    } else if (key == "threads") {
      int n = 0;
      for (char ch : value) {
        if (ch < '0' || ch > '9' || n > 256) bad(item, "threads=1..256");
        n = n * 10 + (ch - '0');
      }
      if (n < 1 || n > 256) bad(item, "threads=1..256");
      v.threads = n;
    } else if (key == "lod") {
      if (value == "off")
        v.lod = LodMode::Off;
      else if (value == "window")
        v.lod = LodMode::Window;
      else
        bad(item, "lod=off or window");
    } else if (key == "model") {
      if (value == "thesis")
        v.model = GrassModel::Thesis;
      else if (value == "pbd")
        v.model = GrassModel::Pbd;
      else if (value == "blade")
        v.model = GrassModel::Blade;
      else
        bad(item, "model=thesis, pbd or blade");
    } else if (key == "physics") {
      if (value == "cpu")
        v.physics = PhysicsPath::Cpu;
      else if (value == "gpu")
        v.physics = PhysicsPath::Gpu;
      else if (value == "gpu-readback")
        v.physics = PhysicsPath::GpuReadback;
      else
        bad(item, "physics=cpu, gpu or gpu-readback");
    } else {
      bad(item, "a key scalar, interp, broadphase, body-broadphase, dt, lod, model, threads or physics");
    }
  }
  return v;
}

VariantSettings VariantSettings::over(const VariantSettings& base) const {
  VariantSettings v = base;
  if (scalar) v.scalar = scalar;
  if (interpolation) v.interpolation = interpolation;
  if (broadphase) v.broadphase = broadphase;
  if (bodyBroadphase) v.bodyBroadphase = bodyBroadphase;
  if (timeStep) v.timeStep = timeStep;
  if (threads) v.threads = threads;
  if (lod) v.lod = lod;
  if (model) v.model = model;
  if (physics) v.physics = physics;
  return v;
}

void VariantSettings::applyTo(Scenario& s) const {
  if (scalar) s.scalar = *scalar;
  if (interpolation) s.particles.interpolation = *interpolation;
  if (broadphase) s.bodies.particleBroadphase = *broadphase;
  if (bodyBroadphase) s.bodies.bodyBroadphase = *bodyBroadphase;
  if (timeStep) s.timeStep = *timeStep;
  if (lod) s.lod.mode = *lod;
  if (model && *model != s.particles.model) {
    // Into or out of the blade model: the new model's acceleration, initial velocity and damping
    // (scenario.h), as a scenario written for it would have by default.
    if ((*model == GrassModel::Blade) != (s.particles.model == GrassModel::Blade)) {
      const Scenario::Particles defaults;
      const bool blade = *model == GrassModel::Blade;
      s.particles.acceleration =
          blade ? Rational3{Rational{0, 1}, Rational{-981, 100}, Rational{0, 1}} : defaults.acceleration;
      s.particles.initialVelocity =
          blade ? Rational3{Rational{0, 1}, Rational{0, 1}, Rational{0, 1}} : defaults.initialVelocity;
      s.particles.damping = blade ? Rational{1, 1} : defaults.damping;
    }
    s.particles.model = *model;
  }
}

VariantSettings VariantSettings::resolvedFrom(const Scenario& s) {
  VariantSettings v;
  v.scalar = s.scalar;
  v.interpolation = s.particles.interpolation;
  v.broadphase = s.bodies.particleBroadphase;
  v.bodyBroadphase = s.bodies.bodyBroadphase;
  v.timeStep = s.timeStep;
  v.lod = s.lod.mode;
  if (s.particles.model != GrassModel::Thesis || s.particles.model != s.particles.writtenModel)
    v.model = s.particles.model;
  return v;
}

std::string VariantSettings::describe() const {
  std::string out;
  auto add = [&](const std::string& kv) { out += (out.empty() ? "" : " ") + kv; };
  if (scalar) add(std::string("scalar=") + scalarName(*scalar));
  if (interpolation) add("interp=" + std::to_string(*interpolation));
  if (broadphase) add(std::string("broadphase=") + broadphaseName(*broadphase));
  if (bodyBroadphase) add(std::string("body-broadphase=") + bodyBroadphaseName(*bodyBroadphase));
  if (timeStep) add("dt=" + timeStep->toString());
  if (lod) add(std::string("lod=") + (*lod == LodMode::Window ? "window" : "off"));
  if (model) add(std::string("model=") + grassModelName(*model));
  if (threads) add("threads=" + std::to_string(*threads));
  if (physics) add(std::string("physics=") + physicsPathName(*physics));
  return out;
}

bool VariantSettings::mustBeIdenticalTo(const VariantSettings& reference) const {
  const VariantSettings mine = over(reference);
  // On a device only the fixed-point formats keep the CPU's bits (docs/gpu-physics.md).
  const bool deviceFloat = mine.physics.value_or(PhysicsPath::Cpu) != PhysicsPath::Cpu &&
                           (mine.scalar == ScalarKind::Float || mine.scalar == ScalarKind::Double);
  return !deviceFloat && mine.scalar == reference.scalar && mine.interpolation == reference.interpolation &&
         mine.timeStep == reference.timeStep &&
         mine.lod.value_or(LodMode::Off) == reference.lod.value_or(LodMode::Off) &&
         mine.model.value_or(GrassModel::Thesis) == reference.model.value_or(GrassModel::Thesis);
}

}  // namespace sg
