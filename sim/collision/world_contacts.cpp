// The body stages of World<S>: collision detection (body pairs through the selected broad
// phase, then bodies against the terrain, with speculative contacts up to each body's reach this
// tick) and the response (the soft step of sim/collision/contact_solver.h: sub-steps of gravity,
// the gyroscopic term, warm start, solve, position integration and relax, island by island and
// on the pool's threads (solver_islands.h); then restitution and
// damping; the continuous sweep of fast bodies against a heightmap; then mowing, and the grass
// pushed out of every body, with optional grass drag).
#include <cmath>

#include "sim/bodies/integrate_bodies.h"
#include "sim/collision/body_pairs.h"
#include "sim/collision/continuous_terrain.h"
#include "sim/collision/solver_islands.h"
#include "sim/world/settings.h"
#include "sim/world/world.h"
#include "sim/world/world_rows.h"

namespace sg {

namespace {

/// Runs work(c) for chunks [0, n) on the pool (inline when one thread or one chunk), and raises on
/// this thread every fixed-point fault the chunks raised, with those pending before. Fault bits are
/// sticky per thread: a chunk's are taken where it ran, so without this a fault raised on a worker
/// was lost and one raised here was not. With it, bodiesFaulted sees the same bits, and makes the
/// same report, for any thread count. The chunks must write disjoint data.
template <class Work>
void runCarryingFaults(ChunkPool& pool, int64_t n, Work&& work) {
  if (pool.threads() == 1 || n < 2) {
    for (int64_t c = 0; c < n; ++c) work(c);
    return;
  }
  std::vector<uint32_t> faults(size_t(n), 0);
  const uint32_t pending = takeFixedFaults();
  pool.run(n, [&](int64_t c, int) {
    takeFixedFaults();
    work(c);
    faults[size_t(c)] = takeFixedFaults();
  });
  uint32_t all = pending;
  for (const uint32_t f : faults) all |= f;
  if (all != 0) detail::raiseFixedFault(all);
}

/// Chunks of the body stages' parallel parts: at most a fixed count, as the particle rows'
/// chunks, so the cuts are the same for any thread count (they decide only who does what; 16
/// keeps 2 to 8 threads busy on islands of unequal size), and each worth at least
/// kBodyChunkWeight (a body or a row each weighs 1, a row in the solve 4): a few bodies are not
/// worth waking the pool for.
constexpr int64_t kBodyChunks = 16;
constexpr int64_t kBodyChunkWeight = 32;

/// Cuts [0, items) into ranges of about equal weight (weight(k) per item; see kBodyChunks), each
/// cut moved forward to where `allowed` holds. Only who does what depends on it, never a bit.
template <class Weight, class Allowed>
std::vector<size_t> balancedCuts(size_t items, Weight&& weight, Allowed&& allowed) {
  int64_t total = 0;
  for (size_t k = 0; k < items; ++k) total += weight(k);
  const int64_t chunks = std::clamp<int64_t>(total / kBodyChunkWeight, 1, kBodyChunks);
  std::vector<size_t> cuts{0};
  int64_t done = 0;
  for (size_t k = 0; k < items && int64_t(cuts.size()) < chunks; ++k) {
    done += weight(k);
    if (done * chunks < total * int64_t(cuts.size())) continue;
    const size_t at = allowed(k + 1);
    if (at > cuts.back() && at < items) cuts.push_back(at);
  }
  cuts.push_back(items);
  return cuts;
}

}  // namespace

template <class S>
void World<S>::detectContacts() {
  contacts_.clear();
  // How far each body can move this tick, (|v| + |w| r + |g| dt) dt (m): pairs and terrain that
  // close within it get speculative contacts, so no body passes through another, or through the
  // terrain below it, in one tick. The terrain test looks under the body's present position; a
  // fast body that a slope turns within the tick is swept after the solve (continuous_terrain.h;
  // at its end-of-tick rotation). Not covered: a body sped up beyond its reach by another within
  // the tick.
  const S dt = particleConsts_.dt;
  const S gravityGain = length3(gravityDt_.x(), gravityDt_.y(), gravityDt_.z());
  std::vector<S> reach(bodies_.size(), S(0)), grown(bodies_.size(), S(0)), turning(bodies_.size(), S(0));
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const RigidBody<S>& b = bodies_[i];  // asleep too: it may be woken below
    const Vec3<S>& v = b.velocity;
    const Vec3<S>& w = b.angularVelocity;
    const S surfaceSpeed = length3(w.x(), w.y(), w.z()) * b.boundingRadius;  // m/s, from turning
    turning[i] = surfaceSpeed * dt;
    reach[i] = (length3(v.x(), v.y(), v.z()) + surfaceSpeed + gravityGain) * dt;
    grown[i] = reach[i] + speculativeDistance_ / S(2);
  }
  // Sleeping bodies keep no contacts among themselves or with the terrain; an awake body that
  // touches a sleeping one wakes it and what rests with it (pairs in (i, j) order: the same
  // wake-ups for any broad phase). A wake-up can make pairs seen earlier in the pass active, so
  // the pass runs again until nothing more wakes (each rerun wakes at least one island).
  // With every body asleep no pair can make a contact or wake anything (commands wake bodies
  // before this stage): the broad phase is skipped, as Box2D skips sleeping islands.
  bool anyAwake = false;
  for (const RigidBody<S>& b : bodies_) anyAwake = anyAwake || !b.asleep;
  const auto pairs = anyAwake ? bodyPairs(bodies_, bodyBroadphase_, grown) : std::vector<std::pair<int32_t, int32_t>>{};
  for (bool woke = true; woke;) {
    woke = false;
    contacts_.clear();
    for (const auto& [i, j] : pairs) {
      RigidBody<S>& a = bodies_[size_t(i)];
      RigidBody<S>& b = bodies_[size_t(j)];
      if (a.asleep && b.asleep) continue;
      const size_t before = contacts_.size();
      // A sphere's row is kept when its path comes within the speculative distance of the other
      // part, widened by what the straight path leaves out: each body's turning (its surface
      // moves |w| r) and gravity's gain over the tick. Not the slop alone: a ball that another
      // speeds up within the tick is not on its start-of-tick path, and the 2 cm every pair keeps
      // stop a struck ball in a row of touching or near ones (with a 5 mm margin, the middle one
      // of three 0.1 m balls 6 mm apart, struck at 30 m/s, ended past its neighbour's centre; an
      // independent review, 2026-11-28). A pair farther apart than that was never covered.
      // Each body's own motion first: the difference of two fx16 velocities near the range's
      // edge leaves it (and a fault in this filter would stop a tick the solver can take).
      const PairSweep<S> sweep{Vec3<S>(a.velocity * dt - b.velocity * dt),
                               speculativeDistance_ + turning[size_t(i)] + turning[size_t(j)] + gravityGain * dt};
      collideBodies(i, a, j, b, contacts_, speculativeDistance_ + reach[size_t(i)] + reach[size_t(j)], &sweep);
      if (int64_t(contacts_.size()) > settings::kMaxContacts) return failWithTooManyContacts(i);
      if (contacts_.size() > before && (a.asleep || b.asleep)) {
        wakeIsland(a.asleep ? i : j);
        woke = true;
      }
    }
  }
  // Bodies against the terrain, in ranges of bodies on the pool, appended in body order (the
  // order one pass over the bodies gives, which the stable sort keeps for equal keys).
  const std::vector<size_t> cuts = balancedCuts(
      bodies_.size(), [&](size_t i) { return int64_t(bodies_[i].asleep ? 0 : 1); }, [](size_t i) { return i; });
  std::vector<std::vector<Contact<S>>> terrainContacts(cuts.size() - 1);
  runCarryingFaults(*pool_, int64_t(cuts.size()) - 1, [&](int64_t c) {
    for (size_t i = cuts[size_t(c)]; i < cuts[size_t(c) + 1]; ++i)
      if (!bodies_[i].asleep && int64_t(terrainContacts[size_t(c)].size()) <= settings::kMaxContacts) {
        // A sphere part's ghosts over a heightmap, as against the bodies above: its path over the
        // tick, widened by its turning and gravity's gain.
        const PairSweep<S> sweep{Vec3<S>(bodies_[i].velocity * dt),
                                 speculativeDistance_ + turning[i] + gravityGain * dt};
        collideBodyTerrain(int32_t(i), bodies_[i], terrain_, terrainContacts[size_t(c)],
                           speculativeDistance_ + reach[i], &sweep);
      }
  });
  // A range stops once its own list is past the budget, so the total is past it exactly when the
  // whole pass's would be: the same verdict for any thread count.
  size_t total = contacts_.size();
  for (const std::vector<Contact<S>>& list : terrainContacts) total += list.size();
  if (int64_t(total) > settings::kMaxContacts) return failWithTooManyContacts(-1);
  for (const std::vector<Contact<S>>& list : terrainContacts)
    contacts_.insert(contacts_.end(), list.begin(), list.end());
  sortContacts(contacts_);
}

template <class S>
void World<S>::failWithTooManyContacts(int32_t body) {
  contacts_.clear();
  failed_ = true;
  failure_ = SimError{};
  failure_.tick = tick_;
  failure_.stage = Stage::Collision;
  failure_.body = body >= 0 ? body : kSomeBody;
  failure_.what = "more than " + std::to_string(settings::kMaxContacts) +
                  " contacts (bodies heaped inside one another; docs/robustness.md)";
}

template <class S>
bool World<S>::bodiesFaulted(Stage stage) {
  using T = ScalarTraits<S>;
  const uint32_t faults = takeFixedFaults();
  // Float and double: finite and within the range a saved state may hold (maxStateMagnitude),
  // so that every state a run reaches can be recorded and read back. Fixed point: its faults.
  auto inRange = [](S v) {
    if constexpr (T::isFixed) {
      return true;
    } else {
      return T::isFinite(v) && !(std::fabs(double(v)) > T::maxStateMagnitude);
    }
  };
  // A body is named only when its own values are out of range (float, double); fixed-point
  // faults say that something overflowed on some thread, not in which body.
  int32_t outOfRange = -1;
  for (size_t i = 0; i < bodies_.size() && outOfRange < 0; ++i) {
    const RigidBody<S>& b = bodies_[i];
    bool ok = true;
    for (int k = 0; k < 3; ++k)
      ok = ok && inRange(b.position[k]) && inRange(b.velocity[k]) && inRange(b.angularVelocity[k]);
    if (!ok) outOfRange = int32_t(i);
  }
  if (faults != 0 || outOfRange >= 0) {
    failed_ = true;
    failure_ = SimError{};
    failure_.tick = tick_;
    failure_.stage = stage;
    failure_.body = outOfRange >= 0 ? outOfRange : kSomeBody;
    failure_.what =
        faults ? fixedFaultName(faults) : "a value that is not finite or beyond +-2^48 (a saved state's range)";
    return true;
  }
  for (const CachedImpulse<S>& c : impulseCache_) {
    bool ok = inRange(c.normal) && inRange(c.tangent1) && inRange(c.tangent2);
    for (int k = 0; k < 3; ++k) ok = ok && inRange(c.point[k]);
    if (ok) continue;
    failed_ = true;
    failure_ = SimError{};
    failure_.tick = tick_;
    failure_.stage = stage;
    failure_.body = c.bodyA;
    failure_.what = "a contact impulse beyond +-2^48 (a saved state's range)";
    return true;
  }
  return false;
}

template <class S>
void World<S>::prepareContactRows() {
  contactRows_.resize(contacts_.size());
  const std::vector<size_t> cuts = balancedCuts(
      contacts_.size(), [](size_t) { return int64_t(1); }, [&](size_t i) { return nextPairStart(contacts_, i); });
  runCarryingFaults(*pool_, int64_t(cuts.size()) - 1, [&](int64_t c) {
    prepareContacts(bodies_, contacts_, impulseCache_, solver_.substeps, contactRows_, cuts[size_t(c)],
                    cuts[size_t(c) + 1]);
  });
}

template <class S>
void World<S>::solveIslands() {
  // Islands share no body: each one's sub-steps read and write its own bodies and rows only.
  const SolverIslands islands = solverIslands(bodies_, contacts_);
  const IslandStep<S> step{gravitySubstep_, maxAngularSpeed_, substepDt_};
  const std::vector<size_t> cuts = balancedCuts(
      islands.count(),
      [&](size_t k) { return int64_t(islands.rowsOf(k).size()) * 4 + int64_t(islands.bodiesOf(k).size()); },
      [](size_t k) { return k; });
  runCarryingFaults(*pool_, int64_t(cuts.size()) - 1, [&](int64_t c) {
    for (size_t k = cuts[size_t(c)]; k < cuts[size_t(c) + 1]; ++k)
      solveIsland(bodies_, contactRows_, islands.bodiesOf(k), islands.rowsOf(k), solver_, step);
  });
}

template <class S>
bool World<S>::respondToContacts() {
  // Before gravity: the approach velocities.
  prepareContactRows();
  // Where each body starts the tick: the continuous sweep below tests the path from here.
  std::vector<Vec3<S>> start;
  if (!terrain_.flat()) {
    start.reserve(bodies_.size());
    for (const RigidBody<S>& b : bodies_) start.push_back(b.position);
  }
  solveIslands();
  // Stored before restitution: the next tick warm-starts with the sub-step's resting impulse, not
  // with the one-off bounce (re-applied, it held a bounced ball on the ground for a tick).
  storeImpulses(bodies_, contacts_, contactRows_, solver_, impulseCache_);
  applyRestitution(bodies_, contactRows_, solver_);
  applyDamping(bodies_);
  sweepFastBodiesAgainstTerrain(bodies_, start, terrain_, solver_.linearSlop);
  if (bodiesFaulted(Stage::Response)) return false;
  mowGrass();
  // Grass: pushed out of every body. On a device the push runs there (world_device.cpp): the
  // particles stay on the device; where it could not push, the host does, from the same state.
  const GrassPushers<S> pushers = prepareGrassPushers(bodies_, grid_, bodyParticle_);
  // Faults of the mowing and the pushers' set-up were raised on this thread: taken here, before
  // the push's chunks, each of which starts by clearing its thread's faults (a chunk that ran here
  // lost them, one that ran on another thread left them pending: a report that depended on
  // scheduling).
  if (const uint32_t faults = takeFixedFaults()) return failWith(Stage::Response, faults);
  std::vector<int64_t> pushed;
  if (device_ && devicePush(pushers, &pushed)) return grassDragDt_ > S(0) ? applyGrassDrag(pushed) : true;
  return pushGrassOnHost(pushers);
}

template <class S>
bool World<S>::pushGrassOnHost(const GrassPushers<S>& pushers) {
  const bool drag = grassDragDt_ > S(0);
  // Per-row push counts (integers, summed in row order below: the same for any thread count).
  std::vector<int64_t> pushed(drag ? size_t(grid_.countZ) * bodies_.size() : 0, 0);
  const bool ok = runParticleRows(Stage::Response, [&](int64_t row, int64_t, int64_t) {
    return pushParticlesOutOfBodies(particles_, grid_, pushers, bodyParticle_, row, row + 1,
                                    drag ? pushed.data() + size_t(row) * bodies_.size() : nullptr, particleKernel_);
  });
  if (!ok || !drag) return ok;
  std::vector<int64_t> perBody(bodies_.size(), 0);
  for (size_t b = 0; b < bodies_.size(); ++b)
    for (int64_t row = 0; row < grid_.countZ; ++row) perBody[b] += pushed[size_t(row) * bodies_.size() + b];
  return applyGrassDrag(perBody);
}

template <class S>
bool World<S>::applyGrassDrag(const std::vector<int64_t>& pushedPerBody) {
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const int64_t tufts = pushedPerBody[b];
    if (tufts == 0) continue;
    RigidBody<S>& body = bodies_[b];
    const S loss = minS(S(1), mulInt(grassDragDt_ * body.invMass, tufts));
    body.velocity *= S(1) - loss;
    body.angularVelocity *= S(1) - loss;
  }
  return !bodiesFaulted(Stage::Response);
}

#define SG_INSTANTIATE_CONTACTS(S)                                 \
  template void World<S>::detectContacts();                        \
  template void World<S>::failWithTooManyContacts(int32_t);        \
  template bool World<S>::bodiesFaulted(Stage);                    \
  template bool World<S>::respondToContacts();                     \
  template bool World<S>::pushGrassOnHost(const GrassPushers<S>&); \
  template bool World<S>::applyGrassDrag(const std::vector<int64_t>&);

SG_FOR_EACH_SCALAR(SG_INSTANTIATE_CONTACTS)

}  // namespace sg
