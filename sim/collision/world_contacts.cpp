// The body stages of World<S>: collision detection (body pairs through the selected broad
// phase, then bodies against the terrain) and the response (gravity, the gyroscopic term, contact impulses, position
// projection, mowing, and the grass pushed out of every body, with optional grass drag).
#include "sim/bodies/gyroscopic.h"
#include "sim/bodies/integrate_bodies.h"
#include "sim/collision/body_pairs.h"
#include "sim/world/world.h"
#include "sim/world/world_rows.h"

namespace sg {

template <class S>
void World<S>::detectContacts() {
  contacts_.clear();
  // Sleeping bodies keep no contacts among themselves or with the terrain; an awake body that
  // touches a sleeping one wakes it (pairs in (i, j) order: the same wake-ups for any broad phase).
  for (const auto& [i, j] : bodyPairs(bodies_, bodyBroadphase_)) {
    RigidBody<S>& a = bodies_[size_t(i)];
    RigidBody<S>& b = bodies_[size_t(j)];
    if (a.asleep && b.asleep) continue;
    const size_t before = contacts_.size();
    collideBodies(i, a, j, b, contacts_);
    if (contacts_.size() > before) {
      if (a.asleep) wake(a);
      if (b.asleep) wake(b);
    }
  }
  for (size_t i = 0; i < bodies_.size(); ++i)
    if (!bodies_[i].asleep) collideBodyTerrain(int32_t(i), bodies_[i], terrain_, contacts_);
  sortContacts(contacts_);
}

template <class S>
bool World<S>::bodiesFaulted(Stage stage) {
  using T = ScalarTraits<S>;
  const uint32_t faults = takeFixedFaults();
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const RigidBody<S>& b = bodies_[i];
    bool finite = true;
    for (int k = 0; k < 3; ++k)
      finite = finite && T::isFinite(b.position[k]) && T::isFinite(b.velocity[k]) && T::isFinite(b.angularVelocity[k]);
    if (faults == 0 && finite) continue;
    failed_ = true;
    failure_ = SimError{};
    failure_.tick = tick_;
    failure_.stage = stage;
    failure_.body = int32_t(i);
    failure_.what = faults ? fixedFaultName(faults) : "non-finite value";
    return true;
  }
  return false;
}

template <class S>
bool World<S>::respondToContacts() {
  prepareContactRows(bodies_, contacts_, contactRows_);  // before gravity: the approach velocities
  applyGravity(bodies_, gravityDt_);
  applyGyroscopicTerm(bodies_, particleConsts_.dt);
  solveContactVelocities(bodies_, contacts_, contactRows_, solver_, impulseCache_);
  solveContactPositions(bodies_, contacts_, contactRows_, particleConsts_.dt, solver_);
  if (bodiesFaulted(Stage::Response)) return false;
  mowGrass();
  // Grass: pushed out of every body (particle rows in parallel, bodies in id order).
  const std::vector<ParticleRange> ranges = particleRanges(bodies_, grid_, bodyParticle_);
  const bool drag = grassDragDt_ > S(0);
  // Per-row push counts (integers, summed in row order below: the same for any thread count).
  std::vector<int64_t> pushed(drag ? size_t(grid_.countZ) * bodies_.size() : 0, 0);
  const bool ok = runParticleRows(Stage::Response, [&](int64_t row, int64_t, int64_t) {
    return pushParticlesOutOfBodies(particles_, grid_, bodies_, ranges, bodyParticle_, row, row + 1,
                                    drag ? pushed.data() + size_t(row) * bodies_.size() : nullptr);
  });
  if (!ok || !drag) return ok;
  for (size_t b = 0; b < bodies_.size(); ++b) {
    int64_t tufts = 0;
    for (int64_t row = 0; row < grid_.countZ; ++row) tufts += pushed[size_t(row) * bodies_.size() + b];
    if (tufts == 0) continue;
    RigidBody<S>& body = bodies_[b];
    const S loss = minS(S(1), mulInt(grassDragDt_ * body.invMass, tufts));
    body.velocity *= S(1) - loss;
    body.angularVelocity *= S(1) - loss;
  }
  return !bodiesFaulted(Stage::Response);
}

#define SG_INSTANTIATE_CONTACTS(S)              \
  template void World<S>::detectContacts();     \
  template bool World<S>::bodiesFaulted(Stage); \
  template bool World<S>::respondToContacts();

SG_FOR_EACH_SCALAR(SG_INSTANTIATE_CONTACTS)

}  // namespace sg
