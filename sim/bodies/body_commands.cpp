// Body commands of World<S>: the recorded inputs that push, teleport, reset, spawn bodies and
// switch mower blades (tick_input.h), applied at the start of a tick in their recorded order.
#include <algorithm>

#include "sim/bodies/integrate_bodies.h"
#include "sim/world/input_conversion.h"
#include "sim/world/world.h"

namespace sg {

template <class S>
void World<S>::applyCommands(const TickInput& input) {
  for (const BodyCommand& cmd : input.bodies) {
    if (cmd.body < 0 || size_t(cmd.body) >= bodies_.size()) continue;  // validated by the reader
    if (cmd.kind == BodyCommandKind::Spawn) {
      spawnBody(cmd.body, cmd.value);
      continue;
    }
    RigidBody<S>& b = bodies_[size_t(cmd.body)];
    // The blade switches touch only a mower's blade (not its sleep): anything else ignores them.
    if (cmd.kind == BodyCommandKind::MowerOn || cmd.kind == BodyCommandKind::MowerOff) {
      if (b.mower) b.bladeOn = cmd.kind == BodyCommandKind::MowerOn;
      continue;
    }
    wakeIsland(cmd.body);  // and whatever rests with it: pushing a support wakes its load
    const Vec3<S> v = inputVector<S>(cmd.value);
    // A body moved without moving through space (teleport, displace, reset) may leave what rested
    // on it in mid-air, asleep with no contact to wake it: wake what was near where it was.
    if (cmd.kind == BodyCommandKind::Teleport || cmd.kind == BodyCommandKind::Displace ||
        cmd.kind == BodyCommandKind::Reset)
      wakeBodiesNear(b.position, b.boundingRadius);
    switch (cmd.kind) {
      case BodyCommandKind::Displace:
        b.position += v;
        break;
      case BodyCommandKind::AddVelocity:
        b.velocity += v;
        break;
      case BodyCommandKind::Impulse:
        b.velocity += v * b.invMass;
        break;
      case BodyCommandKind::Teleport:  // v names the body's origin, as the scenario's position does
        b.position = v + b.rotation * b.centreOfMassLocal;
        b.velocity = Vec3<S>::Zero();
        b.angularVelocity = Vec3<S>::Zero();
        break;
      case BodyCommandKind::Reset:
        resetBody(size_t(cmd.body));
        break;
      case BodyCommandKind::DragTo:
        applyDrag(b, v);
        break;
      case BodyCommandKind::Spawn:
      case BodyCommandKind::MowerOn:
      case BodyCommandKind::MowerOff:
        break;  // handled above
    }
  }
}

template <class S>
void World<S>::applyDrag(RigidBody<S>& b, const Vec3<S>& target) {
  // Box2D's mouse joint without its accumulated impulse (a fresh command every tick): the soft
  // constraint C = p - target solved once over the tick, dv = massScale (-v - biasRate C). Per
  // axis, the offset and the change are clamped (settings.h): bounded inputs, bounded products.
  const Softness<S>& soft = dragSoftness_;
  for (int a = 0; a < 3; ++a) {
    const S offset = minS(maxS(S(b.position[a] - target[a]), S(-dragMaxOffset_)), dragMaxOffset_);
    const S dv = soft.massScale * S(-b.velocity[a] - soft.biasRate * offset);
    b.velocity[a] += minS(maxS(dv, S(-dragMaxDv_)), dragMaxDv_);
  }
}

template <class S>
void World<S>::wakeBodiesNear(const Vec3<S>& centre, S radius) {
  // Within the two bounding radii plus 5 cm along every axis (a box around the bounding sphere:
  // a few more wake-ups in its corners, and no square that could overflow fx16 for big bodies).
  const S margin = S(1) / S(20);
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const RigidBody<S>& other = bodies_[i];
    if (!other.asleep) continue;
    const S reach = radius + other.boundingRadius + margin;
    const Vec3<S> d = other.position - centre;
    // What that body rested on, or held up, wakes with it.
    if (abs(d.x()) < reach && abs(d.y()) < reach && abs(d.z()) < reach) wakeIsland(int32_t(i));
  }
}

template <class S>
void World<S>::wakeIsland(int32_t body) {
  // A sleeping island keeps no contacts, so its members are found by proximity: flood from the
  // body through every sleeping body whose bounds come within 5 cm (per axis) of a woken one.
  // Bodies are visited in id order from a stack of ids: the same wake-ups on every run.
  const S margin = S(1) / S(20);
  std::vector<int32_t> pending{body};
  wake(bodies_[size_t(body)]);
  while (!pending.empty()) {
    const RigidBody<S>& from = bodies_[size_t(pending.back())];
    pending.pop_back();
    for (size_t i = 0; i < bodies_.size(); ++i) {
      RigidBody<S>& other = bodies_[i];
      if (!other.asleep) continue;
      const S reach = from.boundingRadius + other.boundingRadius + margin;
      const Vec3<S> d = other.position - from.position;
      if (abs(d.x()) < reach && abs(d.y()) < reach && abs(d.z()) < reach) {
        wake(other);
        pending.push_back(int32_t(i));
      }
    }
  }
}

template <class S>
void World<S>::resetBody(size_t body) {
  // The start pose: the scenario's for a scenario body, the spawn position and the template's
  // orientation for a spawned one; at rest and awake either way (the scenario's initial
  // velocity is not given again), its blade left as it is.
  const size_t scenarioBodies = initialBodies_.size();
  const RigidBody<S>& start = initialBodies_[size_t(bodyTemplate(int64_t(body)))];
  RigidBody<S>& b = bodies_[body];
  b.position = body < scenarioBodies
                   ? start.position
                   : inputVector<S>(spawns_[body - scenarioBodies].position) + start.rotation * start.centreOfMassLocal;
  b.orientation = start.orientation;
  b.velocity = Vec3<S>::Zero();
  b.angularVelocity = Vec3<S>::Zero();
  b.stillTicks = 0;
  b.asleep = false;
  b.updateDerived();
  dropCachedImpulses(body);
}

template <class S>
void World<S>::spawnBody(int32_t templateBody, const InputVec3& at) {
  // Beyond the cap the command is ignored (every replay ignores it the same way).
  if (bodies_.size() >= size_t(kMaxBodies)) return;
  Spawned spawned{bodyTemplate(templateBody), at};  // a spawned template stands for its own template
  RigidBody<S> b = initialBodies_[size_t(spawned.templateBody)];
  b.position = inputVector<S>(at) + b.rotation * b.centreOfMassLocal;  // `at` names the origin
  b.velocity = Vec3<S>::Zero();
  b.angularVelocity = Vec3<S>::Zero();
  b.updateDerived();
  bodies_.push_back(b);
  spawns_.push_back(spawned);
}

template <class S>
void World<S>::dropCachedImpulses(size_t body) {
  const int32_t id = int32_t(body);
  std::erase_if(impulseCache_, [id](const CachedImpulse<S>& c) { return c.bodyA == id || c.bodyB == id; });
}

template <class S>
int32_t World<S>::bodyTemplate(int64_t body) const {
  const int64_t scenarioBodies = int64_t(initialBodies_.size());
  if (body < 0 || body >= int64_t(bodies_.size())) return -1;
  return body < scenarioBodies ? int32_t(body) : spawns_[size_t(body - scenarioBodies)].templateBody;
}

template <class S>
bool World<S>::bladeOn(int64_t body) const {
  return body >= 0 && body < int64_t(bodies_.size()) && bodies_[size_t(body)].mower && bodies_[size_t(body)].bladeOn;
}

#define SG_INSTANTIATE_COMMANDS(S)                                  \
  template void World<S>::applyCommands(const TickInput&);          \
  template void World<S>::applyDrag(RigidBody<S>&, const Vec3<S>&); \
  template void World<S>::resetBody(size_t);                        \
  template void World<S>::wakeBodiesNear(const Vec3<S>&, S);        \
  template void World<S>::wakeIsland(int32_t);                      \
  template void World<S>::spawnBody(int32_t, const InputVec3&);     \
  template void World<S>::dropCachedImpulses(size_t);               \
  template int32_t World<S>::bodyTemplate(int64_t) const;           \
  template bool World<S>::bladeOn(int64_t) const;

SG_FOR_EACH_SCALAR(SG_INSTANTIATE_COMMANDS)

}  // namespace sg
