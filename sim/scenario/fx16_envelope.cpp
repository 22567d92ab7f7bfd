#include "sim/scenario/fx16_envelope.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "sim/bodies/rigid_body.h"
#include "sim/world/settings.h"

namespace sg {
namespace {

/// Q16.16's largest value: the most N s a row's impulse, or 1/kg its inverse effective mass, holds.
constexpr double kFx16Largest = 32767.0;

double real(const Rational& r) { return r.toDouble(); }
double magnitude(const Rational3& v) {
  return std::sqrt(real(v[0]) * real(v[0]) + real(v[1]) * real(v[1]) + real(v[2]) * real(v[2]));
}
double exactToDouble(const settings::Exact& e) { return double(e.num) / double(e.den); }

/// One body as the envelope sees it: a listed body, or one the script spawns.
struct EnvelopeBody {
  std::string path;  ///< "$.bodies.list[i]" or "$.script[k]" (a spawn)
  double mass = 0;   ///< kg
  double restitution = 0;
  double invMass = 0;          ///< 1/kg
  double invInertia = 0;       ///< 1/I_min (1/(kg m^2)), the largest principal inverse inertia
  double reach = 0;            ///< m, the bounding radius about the centre of mass
  bool sphere = false;         ///< one sphere about its centre of mass: every row's arm is along its normal
  double startSpeed = 0;       ///< m/s
  double top = 0;              ///< m, the highest its centre of mass starts or is put
  double addedSpeed = 0;       ///< m/s, the script's velocity changes, summed
  double dragSpeed = 0;        ///< m/s, what the script's drag spring can give it
  std::string largestCommand;  ///< the script command that adds the most speed ("" if none)
  double largestCommandSpeed = 0;
  double friction = 0;
  double spinEnergyPerMass = 0;  ///< J/kg: its start spin's energy, at most I_max |w0|^2 / 2, over m
  double lowestCentre = 0;       ///< m: how far above the ground its centre of mass stays at least
  int templateBody = 0;          ///< the listed body whose spec it has (itself, or a spawn's template)
  double ownSpeed = 0;           ///< m/s, w: its start, its fall and the script's changes
  double speed = 0;              ///< m/s, the bound s (filled last)
};

EnvelopeBody fromSpec(const BodySpec& spec, const Scenario& s, const std::string& path, int templateBody) {
  EnvelopeBody e;
  e.path = path;
  e.templateBody = templateBody;
  e.mass = real(spec.mass);
  e.restitution = real(spec.restitution);
  e.friction = real(spec.friction);
  const RigidBody<double> body = makeBody<double>(spec, s.timeStep, s.sourceName, path);
  const Vec3<double>& inertia = body.inertiaLocal;
  const double smallestInertia = std::min({inertia.x(), inertia.y(), inertia.z()});
  const double largestInertia = std::max({inertia.x(), inertia.y(), inertia.z()});
  const double reach = body.boundingRadius;
  e.reach = reach;
  e.invMass = body.invMass;
  e.sphere = body.parts.size() == 1 && body.parts[0].type == ShapeType::Sphere && body.parts[0].offset.isZero();
  e.invInertia = smallestInertia > 0 ? 1.0 / smallestInertia : 0.0;
  e.startSpeed = magnitude(spec.velocity);
  const double spin = magnitude(spec.angularVelocity);
  e.spinEnergyPerMass = 0.5 * largestInertia * spin * spin * body.invMass;
  // The centre of mass (the parts' offsets may put it far from the author's origin), and how low
  // it can come: a lone sphere or box about it keeps it its radius or smallest half extent up.
  e.top = body.position.y();
  if (body.parts.size() == 1 && body.parts[0].offset.isZero()) {
    const BodyPart<double>& part = body.parts[0];
    e.lowestCentre = part.type == ShapeType::Sphere
                         ? part.radius
                         : std::min({part.halfExtents.x(), part.halfExtents.y(), part.halfExtents.z()});
  }
  return e;
}

double lowestGround(const Scenario& s) {
  if (s.terrain.flat) return real(s.terrain.flatHeight);
  const auto& samples = s.terrain.heightmap.samples;
  const int lowest = samples.empty() ? 0 : *std::min_element(samples.begin(), samples.end());
  return real(s.terrain.maxHeight) * lowest / 255.0;
}

[[noreturn]] void refuseScene(const Scenario& s, const std::string& path, const std::string& what) {
  throw ScenarioError(s.sourceName, path, what);
}

std::string shortNumber(double v) {
  std::ostringstream o;
  o.precision(6);
  o << v;
  return o.str();
}

}  // namespace

void checkFx16ImpactEnvelope(const Scenario& s) {
  if (s.bodies.list.empty()) return;
  std::vector<EnvelopeBody> bodies;
  for (size_t i = 0; i < s.bodies.list.size(); ++i)
    bodies.push_back(fromSpec(s.bodies.list[i], s, "$.bodies.list[" + std::to_string(i) + "]", int(i)));
  // The script's commands (in tick order, as the world applies them): spawns append bodies,
  // displacements and teleports raise the highest point, velocity changes add speed.
  const double dragOmega = 2.0 * std::numbers::pi * exactToDouble(settings::kDragHertz);
  const double dragReach = std::sqrt(3.0) * exactToDouble(settings::kDragMaxOffset);
  for (const ScriptedCommand& c : s.script) {
    if (c.kind == BodyCommandKind::Spawn) {
      // A spawn of a spawned body copies that body's template (the world keeps its spec).
      if (c.body < 0 || size_t(c.body) >= bodies.size() || bodies.size() >= size_t(kMaxBodies)) continue;
      const int templateBody = bodies[size_t(c.body)].templateBody;
      const BodySpec& spec = s.bodies.list[size_t(templateBody)];
      EnvelopeBody e = fromSpec(spec, s, "$.script[" + std::to_string(c.source) + "]", templateBody);
      e.startSpeed = 0;  // a spawn is at rest, its origin at the command's value
      e.spinEnergyPerMass = 0;
      e.top += real(c.value[1]) - real(spec.position[1]);
      bodies.push_back(e);
      continue;
    }
    if (c.body < 0 || size_t(c.body) >= bodies.size()) continue;
    EnvelopeBody& e = bodies[size_t(c.body)];
    switch (c.kind) {
      // `top` is an upper bound of the body's height so far: a displacement can only raise it by
      // its own rise, a teleport puts the body at the value (at rest).
      case BodyCommandKind::Displace:
        e.top += std::max(0.0, real(c.value[1]));
        break;
      case BodyCommandKind::Teleport:
        e.top = std::max(e.top, real(c.value[1]) + e.reach);
        break;
      case BodyCommandKind::AddVelocity:
      case BodyCommandKind::Impulse: {
        const double added = magnitude(c.value) / (c.kind == BodyCommandKind::Impulse ? e.mass : 1.0);
        e.addedSpeed += added;
        if (added > e.largestCommandSpeed) {
          e.largestCommandSpeed = added;
          e.largestCommand = "$.script[" + std::to_string(c.source) + "].value";
        }
        break;
      }
      // The drag spring (5 Hz, damping ratio 0.7) on an offset of at most 10 m per axis.
      case BodyCommandKind::DragTo:
        e.dragSpeed = dragOmega * dragReach;
        if (e.dragSpeed > e.largestCommandSpeed) {
          e.largestCommandSpeed = e.dragSpeed;
          e.largestCommand = "$.script[" + std::to_string(c.source) + "]";
        }
        break;
      default:
        break;
    }
  }
  // The most energy the scene can hold (J): each body's start speed and its fall to the lowest
  // ground, with the script's velocity changes on top. All of it may end up in any one body (a
  // heavy body passes its speed on to a light one), so a body's speed is bounded by
  // sqrt(2 E / m).
  const double down = std::max(0.0, -real(s.bodies.gravity[1]));
  const double gravity = magnitude(s.bodies.gravity);
  const double ground = lowestGround(s);
  // A contact meets the approach plus a tick of fall; the soft push-out of an overlap adds up to
  // 3 m/s on top, which restitution does not return (it bounces the approach only).
  const double tickOfFall = gravity * real(s.timeStep);
  const double pushOut = exactToDouble(settings::kContactPushMaxVelocity);
  double energy = 0;
  // The largest share of it, for the message: what to change.
  double largestShare = 0;
  std::string largestSource, largestWhat = "none: the push-out and a tick of fall alone";
  for (EnvelopeBody& e : bodies) {
    const double drop = std::max(0.0, e.top - ground - e.lowestCentre);
    // Its start spin may turn into speed (a spinning ball put down rolls off).
    const double fall = std::sqrt(e.startSpeed * e.startSpeed + 2.0 * e.spinEnergyPerMass + 2.0 * down * drop);
    const double own = fall + e.addedSpeed + e.dragSpeed;
    e.ownSpeed = own;
    energy += 0.5 * e.mass * own * own;
    const double scripted = 0.5 * e.mass * (own * own - fall * fall);
    const double started = 0.5 * e.mass * fall * fall;
    const bool spawned = e.path[2] == 's';
    if (scripted > largestShare && scripted >= started) {
      largestShare = scripted, largestSource = e.largestCommand,
      largestWhat = "the script's velocity changes of " + e.path;
    } else if (started > largestShare) {
      const double speedTerm = e.startSpeed * e.startSpeed, spinTerm = 2.0 * e.spinEnergyPerMass,
                   fallTerm = 2.0 * down * drop;
      const char* key = speedTerm >= spinTerm && speedTerm >= fallTerm ? ".velocity"
                        : spinTerm >= fallTerm                         ? ".angularVelocity"
                                                                       : ".position";
      largestShare = started, largestSource = spawned ? e.path + ".value" : e.path + key;
      largestWhat = key[1] == 'v'   ? "the start speed of " + e.path
                    : key[1] == 'a' ? "the start spin of " + e.path
                                    : "the fall of " + e.path + " to the lowest ground";
    }
  }
  // Speeds: the energy's bound, or an elastic strike by the fastest other body (at most twice its
  // speed) on top of the body's own, whichever is less. The second is not a proof: a chain of
  // ever lighter bodies can double a speed at each strike (fx16_envelope.h).
  double fastest = 0, secondFastest = 0;
  for (const EnvelopeBody& e : bodies) {
    if (e.ownSpeed > fastest)
      secondFastest = fastest, fastest = e.ownSpeed;
    else if (e.ownSpeed > secondFastest)
      secondFastest = e.ownSpeed;
  }
  for (EnvelopeBody& e : bodies) {
    const double striker = e.ownSpeed == fastest ? secondFastest : fastest;
    e.speed = std::min(std::sqrt(2.0 * energy / e.mass), e.ownSpeed + 2.0 * striker) + tickOfFall;
  }
  // A row's inverse effective mass 1/m + |r x n|^2 / I, with its point on or in the body:
  // |r| <= R. A sphere's rows act through its centre (their points lie on the line of centres,
  // or on its surface along the normal: r x n = 0). A speculative row's point may lie farther out,
  // in the gap a fast pair closes this tick; there the solver shortens the arm until the terms
  // fit (contact_solver.cpp, makeAxis).
  const auto inverseEffective = [&](const EnvelopeBody& e) {
    return e.invMass + (e.sphere ? 0.0 : e.reach * e.reach * e.invInertia);
  };
  const auto tooLarge = [&](const EnvelopeBody& e, const EnvelopeBody* other, double impulse, double mu) {
    std::ostringstream o;
    o << "impacts within fx16's impulse range (<= 32767 N s a contact; docs/fixed-point.md): " << e.path
      << (other ? " against " + other->path + ": reduced mass (" + shortNumber(mu) + " kg)"
                : std::string(" on the ground: mass (") + shortNumber(mu) + " kg)")
      << " x ((1 + restitution) x closing speed + 3 m/s push-out) (x friction, above 1) may reach "
      << shortNumber(impulse) << " N s, ";
    if (largestSource.empty())
      o << "with the push-out and a tick of fall alone (the scene holds no other energy)";
    else
      o << "if the scene's energy (" << shortNumber(energy) << " J, most of it " << largestWhat << ") all goes into "
        << (other ? "the pair" : "it");
    o << "; use fx32";
    // With no energy to speak of, the mass is what to change.
    refuseScene(s, !largestSource.empty() ? largestSource : e.path + (e.path[2] == 'b' ? ".mass" : ".value"), o.str());
  };
  for (const EnvelopeBody& e : bodies) {
    // Friction holds up to mu of the normal impulse: beyond mu = 1 that is the larger.
    const double impulse = ((1.0 + e.restitution) * e.speed + pushOut) * e.mass * std::max(1.0, e.friction);
    if (!(impulse <= kFx16Largest)) tooLarge(e, nullptr, impulse, e.mass);
    const double k = inverseEffective(e);
    if (!(k <= kFx16Largest)) {
      refuseScene(s, e.path + (e.path[2] == 'b' ? ".mass" : ""),
                  "a contact's inverse effective mass 1/m + r^2/I_min within fx16's range (<= 32767 /kg; "
                  "docs/fixed-point.md; r: its bounding radius), got " +
                      shortNumber(k) + " /kg (a light body this large); use fx32");
    }
  }
  // Pairs: O(n^2) over at most 1,024 bodies (half a million products at load).
  for (size_t i = 0; i < bodies.size(); ++i) {
    for (size_t j = i + 1; j < bodies.size(); ++j) {
      const EnvelopeBody& a = bodies[i];
      const EnvelopeBody& b = bodies[j];
      const double mu = a.mass * b.mass / (a.mass + b.mass);
      const double impulse = ((1.0 + std::max(a.restitution, b.restitution)) * (a.speed + b.speed) + pushOut) * mu *
                             std::max(1.0, std::sqrt(a.friction * b.friction));
      if (!(impulse <= kFx16Largest)) tooLarge(a, &b, impulse, mu);
      const double k = inverseEffective(a) + inverseEffective(b);
      if (!(k <= kFx16Largest))
        refuseScene(s, b.path + (b.path[2] == 'b' ? ".mass" : ""),
                    "a contact's inverse effective mass within fx16's range (<= 32767 /kg; docs/fixed-point.md): "
                    "with " +
                        a.path + ", 1/m + r^2/I_min summed is " + shortNumber(k) +
                        " /kg (r: the bounding radii; light bodies this large); use fx32");
    }
  }
}

}  // namespace sg
