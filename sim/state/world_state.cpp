// World<S> state I/O: the canonical serialisation (state_format.h) that saveState() writes and
// stateHash() hashes, restoreState() section by section, and the plain-number export that
// `simgrass replay --export-state s.json` writes.
#include <algorithm>
#include <string>

#include "sim/state/state_format.h"
#include "sim/state/state_hash.h"
#include "sim/state/state_reader.h"
#include "sim/state/state_sink.h"
#include "sim/world/world.h"

namespace sg {

using state::Section;

namespace {
void putSection(StateSink& sink, Section section, uint64_t payloadBytes) {
  sink.write(state::kSectionTags[int(section)], 4);
  sink.put(payloadBytes);
}

/// Float and double states: n values at the cursor, each finite and within +-2^48 (a NaN or a
/// 1e45 in a restored state would reach the step as undefined behaviour, not as a fault). Fixed
/// states need no check: every raw value is a value of the type. Reads a copy of the cursor.
template <class S>
void checkFloatValues(state::Cursor at, uint64_t n, const char* what) {
  if constexpr (!ScalarTraits<S>::isFixed) {
    for (uint64_t i = 0; i < n; ++i) {
      const uint64_t offset = at.offset();
      const double v = double(at.read<S>(what));
      if (!(v >= -ScalarTraits<S>::maxStateMagnitude && v <= ScalarTraits<S>::maxStateMagnitude))
        throw StateError(offset, std::string("a finite ") + what + " within +-2^48");
    }
  }
}
}  // namespace

template <class S>
void World<S>::serialise(StateSink& sink, const uint64_t* groupDigests) const {
  using namespace state;
  syncFromDevice();
  const uint64_t n = uint64_t(grid_.size());
  sink.write(kMagic, sizeof kMagic);

  putSection(sink, Section::Head, kHeadBytes);
  sink.put(kVersion);
  sink.put(uint8_t(ScalarTraits<S>::kind));
  sink.put(uint8_t(grid_.k));
  sink.put(uint16_t(0));
  sink.put(configHash_);
  sink.put(tick_);
  sink.put(int64_t(n));
  sink.put(uint32_t(bodies_.size()));
  sink.put(uint32_t(0));

  // The particle arrays, or for the state hash their row groups' digests (state_hash.h); the
  // section lengths are the saved ones either way.
  const size_t groups = size_t(particleGroups());
  putSection(sink, Section::Particles, 6 * n * sizeof(S));
  size_t array = 0;
  for (const auto* v :
       {&particles_.px, &particles_.py, &particles_.pz, &particles_.vx, &particles_.vy, &particles_.vz}) {
    if (groupDigests)
      sink.putArray(groupDigests + groups * array++, groups);
    else
      sink.putArray(v->data(), v->size());
  }
  if (!particles_.trample.empty()) {
    putSection(sink, Section::Trample, n * sizeof(S));
    if (groupDigests)
      sink.putArray(groupDigests + groups * array, groups);
    else
      sink.putArray(particles_.trample.data(), n);
  }

  putSection(sink, Section::Bodies, bodies_.size() * (13 * sizeof(S) + kBodyExtraBytes));
  for (const RigidBody<S>& b : bodies_) {
    const S values[13] = {b.position.x(),       b.position.y(),    b.position.z(),        b.orientation.w(),
                          b.orientation.x(),    b.orientation.y(), b.orientation.z(),     b.velocity.x(),
                          b.velocity.y(),       b.velocity.z(),    b.angularVelocity.x(), b.angularVelocity.y(),
                          b.angularVelocity.z()};
    sink.putArray(values, 13);
    sink.put(b.stillTicks);
    sink.put(uint8_t((b.asleep ? kBodyAsleep : 0) | (b.mower && !b.bladeOn ? kBodyBladeOff : 0)));
    sink.put(uint8_t(0));
    sink.put(uint16_t(0));
  }

  putSection(sink, Section::Spawns, 4 + spawns_.size() * kSpawnBytes);
  sink.put(uint32_t(spawns_.size()));
  for (const Spawned& sp : spawns_) {
    sink.put(sp.templateBody);
    sink.put(int32_t(0));
    sink.put(sp.position.x);
    sink.put(sp.position.y);
    sink.put(sp.position.z);
  }

  // Warm-start impulses shape the next tick, so they are state.
  putSection(sink, Section::Impulses, 8 + impulseCache_.size() * (6 * sizeof(S) + kImpulseExtraBytes));
  sink.put(uint64_t(impulseCache_.size()));
  for (const CachedImpulse<S>& c : impulseCache_) {
    sink.put(c.bodyA);
    sink.put(c.bodyB);
    sink.put(c.featureA);
    sink.put(c.featureB);
    const S impulses[6] = {c.normal, c.tangent1, c.tangent2, c.point.x(), c.point.y(), c.point.z()};
    sink.putArray(impulses, 6);
  }

  // Persistent patch edits (mower cuts) by lattice coordinates, in key order.
  putSection(sink, Section::Cuts, 8 + cuts_.size() * 16);
  sink.put(uint64_t(cuts_.size()));
  for (const auto& [key, value] : cuts_) {
    sink.put(key.first);
    sink.put(key.second);
  }

  // The particle arrays above are in the window's toroidal storage order, a function of its
  // origin alone.
  putSection(sink, Section::Window, 16);
  sink.put(lodWindow_ ? grid_.window.originI : int64_t(0));
  sink.put(lodWindow_ ? grid_.window.originJ : int64_t(0));
}

template <class S>
uint64_t World<S>::stateHash() const {
  syncFromDevice();
  // The digests the last step's particle pass took (requestStateHash), or taken now.
  std::vector<uint64_t> fresh;
  if (!rowDigestsCurrent_) fresh = particleGroupDigests();
  HashSink h;
  serialise(h, rowDigestsCurrent_ ? rowDigests_.data() : fresh.data());
  return h.digest();
}

template <class S>
int64_t World<S>::particleGroups() const {
  const int64_t perGroup = stateHashRowsPerGroup(grid_.countX);
  return (grid_.countZ + perGroup - 1) / perGroup;
}

template <class S>
std::vector<uint64_t> World<S>::particleGroupDigests() const {
  syncFromDevice();
  std::vector<uint64_t> digests(size_t(particles_.trample.empty() ? 6 : 7) * size_t(particleGroups()));
  pool_->run(particleGroups(), [&](int64_t g, int) { digestParticleGroup(g, digests.data()); });
  return digests;
}

template <class S>
void World<S>::digestParticleGroup(int64_t group, uint64_t* out) const {
  const int64_t perGroup = stateHashRowsPerGroup(grid_.countX), width = grid_.countX;
  const int64_t begin = group * perGroup * width, end = std::min(grid_.countZ, (group + 1) * perGroup) * width;
  const size_t groups = size_t(particleGroups()), n = size_t(end - begin);
  out += size_t(group);
  for (const auto* v :
       {&particles_.px, &particles_.py, &particles_.pz, &particles_.vx, &particles_.vy, &particles_.vz}) {
    *out = rowDigest(v->data() + begin, n);
    out += groups;
  }
  if (!particles_.trample.empty()) *out = rowDigest(particles_.trample.data() + begin, n);
}

template <class S>
std::vector<uint8_t> World<S>::saveState() const {
  ByteSink b;
  b.bytes.reserve(256 + 6 * size_t(grid_.size()) * sizeof(S) + bodies_.size() * 128);
  serialise(b);
  return std::move(b.bytes);
}

template <class S>
void World<S>::restoreState(std::span<const uint8_t> bytes) {
  using namespace state;
  // Everything is read and checked into locals first; the world changes only once all of it
  // passed, so a bad state leaves the world as it was.
  const uint64_t n = uint64_t(grid_.size());
  const size_t scenarioBodies = initialBodies_.size();
  StateReader reader(bytes);

  Cursor head = reader.next(Section::Head, kHeadBytes);
  head.expect<uint32_t>(kVersion, "state format version 2");
  head.expect<uint8_t>(uint8_t(ScalarTraits<S>::kind),
                       std::string("a state of scalar ") + scalarName(ScalarTraits<S>::kind));
  head.expect<uint8_t>(uint8_t(grid_.k), "interpolation k = " + std::to_string(grid_.k));
  head.expect<uint16_t>(0, "reserved 0");
  head.expect<uint64_t>(configHash_, "a state saved from the same scenario (fingerprint differs)");
  const uint64_t tickAt = head.offset();
  const int64_t tick = head.read<int64_t>("the tick");
  if (tick < 0) throw StateError(tickAt, "a non-negative tick, got " + std::to_string(tick));
  head.expect<int64_t>(int64_t(n), std::to_string(n) + " particles");
  const uint64_t bodiesAt = head.offset();
  const uint32_t bodyCount = head.read<uint32_t>("the body count");
  // Spawns add bodies up to kMaxBodies (only to worlds that have a template body).
  const size_t maxBodies = scenarioBodies == 0 ? 0 : size_t(bodyIndexLimit(scenarioBodies));
  if (bodyCount < scenarioBodies || bodyCount > maxBodies)
    throw StateError(
        bodiesAt, (maxBodies == scenarioBodies ? std::to_string(scenarioBodies)
                                               : std::to_string(scenarioBodies) + " to " + std::to_string(maxBodies)) +
                      " bodies, got " + std::to_string(bodyCount));
  head.expect<uint32_t>(0, "reserved 0");

  Cursor particles = reader.next(Section::Particles, int64_t(6 * n * sizeof(S)));  // read last
  checkFloatValues<S>(particles, 6 * n, "particle position or velocity");
  std::vector<S> trample;
  if (!particles_.trample.empty()) {  // a trampling world's states have the section, others never
    Cursor trampleSection = reader.next(Section::Trample, int64_t(n * sizeof(S)));
    trample.resize(n);
    const uint64_t start = trampleSection.offset();
    trampleSection.readArray(trample.data(), n, "trample levels");
    for (uint64_t i = 0; i < n; ++i)
      if (!(trample[i] >= S(0) && trample[i] <= S(1)))  // false for a NaN
        throw StateError(start + i * sizeof(S), "a trample level from 0 to 1");
  }

  Cursor bodySection = reader.next(Section::Bodies, int64_t(bodyCount * (13 * sizeof(S) + kBodyExtraBytes)));
  struct BodyRecord {
    S v[13];
    int32_t stillTicks;
    uint8_t flags;
    uint64_t at;
  };
  std::vector<BodyRecord> records(bodyCount);
  for (BodyRecord& r : records) {
    r.at = bodySection.offset();
    checkFloatValues<S>(bodySection, 13, "body pose or velocity");
    bodySection.readArray(r.v, 13, "a body's pose and velocities");
    const uint64_t stillAt = bodySection.offset();
    r.stillTicks = bodySection.read<int32_t>("a body's still-tick count");
    // A running world counts an awake body's still ticks up to ticksToSleep, where it falls asleep
    // and the count stops; anything else was never saved (and INT32_MAX would overflow the count).
    const int32_t maxStill = std::max<int32_t>(ticksToSleep_, 1);
    if (r.stillTicks < 0 || r.stillTicks > maxStill)
      throw StateError(stillAt, "a still-tick count from 0 to " + std::to_string(maxStill) + ", got " +
                                    std::to_string(r.stillTicks));
    const uint64_t flagsAt = bodySection.offset();
    r.flags = bodySection.read<uint8_t>("a body's flags");
    if (r.flags & ~(kBodyAsleep | kBodyBladeOff)) throw StateError(flagsAt, "body flags 0 to 3");
    bodySection.expect<uint8_t>(0, "reserved 0");
    bodySection.expect<uint16_t>(0, "reserved 0");
  }
  bodySection.expectEnd("BODY");

  Cursor spawnSection = reader.next(Section::Spawns);
  const uint64_t spawnCountAt = spawnSection.offset();
  const uint32_t spawnCount = spawnSection.read<uint32_t>("the spawn count");
  if (spawnCount != bodyCount - scenarioBodies)
    throw StateError(spawnCountAt, std::to_string(bodyCount - scenarioBodies) +
                                       " spawned bodies (the body count less " + std::to_string(scenarioBodies) +
                                       " scenario bodies), got " + std::to_string(spawnCount));
  spawnSection.need(uint64_t(spawnCount) * kSpawnBytes, "the spawned bodies");
  std::vector<Spawned> spawns;
  for (uint32_t i = 0; i < spawnCount; ++i) {
    const uint64_t at = spawnSection.offset();
    const int32_t templateBody = spawnSection.read<int32_t>("a spawn template");
    if (templateBody < 0 || size_t(templateBody) >= scenarioBodies)
      throw StateError(at, "a spawn template between 0 and " + std::to_string(scenarioBodies - 1));
    spawnSection.expect<int32_t>(0, "reserved 0");
    InputVec3 p;
    p.x = spawnSection.read<int64_t>("a spawn position");
    p.y = spawnSection.read<int64_t>("a spawn position");
    p.z = spawnSection.read<int64_t>("a spawn position");
    spawns.push_back(Spawned{templateBody, p});
  }
  spawnSection.expectEnd("SPWN");
  for (uint32_t b = 0; b < bodyCount; ++b) {
    if (!(records[b].flags & kBodyBladeOff)) continue;
    const size_t t = b < scenarioBodies ? b : size_t(spawns[b - scenarioBodies].templateBody);
    if (!initialBodies_[t].mower)
      throw StateError(records[b].at + 13 * sizeof(S) + 4,
                       "no blade-off flag: body " + std::to_string(b) + " is no mower");
  }

  Cursor impulseSection = reader.next(Section::Impulses);
  const uint64_t cachedAt = impulseSection.offset();
  const uint64_t cached = impulseSection.read<uint64_t>("the warm-start impulse count");
  const uint64_t entryBytes = 6 * sizeof(S) + kImpulseExtraBytes;
  if (cached > impulseSection.remaining() / entryBytes || impulseSection.remaining() != cached * entryBytes)
    throw StateError(cachedAt, "a warm-start impulse count that fills section 'CONT', got " + std::to_string(cached));
  std::vector<CachedImpulse<S>> cache(cached);
  for (CachedImpulse<S>& c : cache) {
    const uint64_t at = impulseSection.offset();
    c.bodyA = impulseSection.read<int32_t>("a contact body");
    c.bodyB = impulseSection.read<int32_t>("a contact body");
    const int32_t nb = int32_t(bodyCount);
    if (c.bodyA < 0 || c.bodyA >= nb || c.bodyB < kTerrainBody || c.bodyB >= nb)
      throw StateError(at, "contact bodies between -1 and " + std::to_string(nb - 1));
    c.featureA = impulseSection.read<uint32_t>("a contact feature");
    c.featureB = impulseSection.read<uint32_t>("a contact feature");
    S v[6];
    checkFloatValues<S>(impulseSection, 6, "contact impulse or point");
    impulseSection.readArray(v, 6, "contact impulses and point");
    c.normal = v[0];
    c.tangent1 = v[1];
    c.tangent2 = v[2];
    c.point = Vec3<S>(v[3], v[4], v[5]);
  }

  Cursor cutSection = reader.next(Section::Cuts);
  const uint64_t editsAt = cutSection.offset();
  const uint64_t edits = cutSection.read<uint64_t>("the mown-patch count");
  if (edits > cutSection.remaining() / 16 || cutSection.remaining() != edits * 16)
    throw StateError(editsAt, "a mown-patch count that fills section 'CUTS', got " + std::to_string(edits));
  std::map<std::pair<int64_t, int64_t>, uint8_t> cuts;
  for (uint64_t e = 0; e < edits; ++e) {
    const uint64_t at = cutSection.offset();
    const int64_t i = cutSection.read<int64_t>("a patch column");
    const int64_t j = cutSection.read<int64_t>("a patch row");
    if (i < 0 || j < 0 || i >= lattice_.patchesX || j >= lattice_.patchesZ)
      throw StateError(at, "a patch inside the field");
    if (!cuts.empty() && !(cuts.rbegin()->first < std::make_pair(i, j)))
      throw StateError(at, "mown patches in increasing (i, j) order");
    cuts.emplace_hint(cuts.end(), std::make_pair(i, j), uint8_t(1));
  }

  Cursor windowSection = reader.next(Section::Window, 16);
  const int64_t originI = windowSection.read<int64_t>("the window origin");
  const int64_t originJ = windowSection.read<int64_t>("the window origin");
  const bool originValid =
      lodWindow_ ? originI == clampWindowOrigin(originI, true) && originJ == clampWindowOrigin(originJ, false)
                 : originI == 0 && originJ == 0;
  if (!originValid)
    throw StateError(windowSection.offset() - 16,
                     lodWindow_ ? "a window origin that keeps the window inside the field"
                                : "window origin (0, 0) (this world has no level-of-detail window)");
  reader.expectEnd();

  // Everything checked: apply. Static window data first (anchors, patches, cut flags from the
  // restored cuts), then the particles' dynamic state over it.
  deviceAhead_ = false;  // the restored state replaces a device's: uploaded before the next pass
  hostAhead_ = true;
  deviceDisplacementCurrent_ = false;
  cuts_ = std::move(cuts);
  if (lodWindow_) fillWindow(originI, originJ, false);
  for (auto* v : {&particles_.px, &particles_.py, &particles_.pz, &particles_.vx, &particles_.vy, &particles_.vz})
    particles.readArray(v->data(), n, "particle state");
  if (!trample.empty()) particles_.trample = std::move(trample);
  // Scenario bodies, then a copy of the template of each spawned one; the state over them.
  bodies_.resize(scenarioBodies, initialBodies_.empty() ? RigidBody<S>{} : initialBodies_[0]);
  for (size_t i = 0; i < scenarioBodies; ++i) bodies_[i] = initialBodies_[i];
  for (const Spawned& sp : spawns) bodies_.push_back(initialBodies_[size_t(sp.templateBody)]);
  spawns_ = std::move(spawns);
  for (size_t i = 0; i < bodies_.size(); ++i) {
    RigidBody<S>& b = bodies_[i];
    const BodyRecord& r = records[i];
    b.position = Vec3<S>(r.v[0], r.v[1], r.v[2]);
    b.orientation = Quat<S>(r.v[3], r.v[4], r.v[5], r.v[6]);
    b.velocity = Vec3<S>(r.v[7], r.v[8], r.v[9]);
    b.angularVelocity = Vec3<S>(r.v[10], r.v[11], r.v[12]);
    b.stillTicks = r.stillTicks;
    b.asleep = (r.flags & kBodyAsleep) != 0;
    b.bladeOn = (r.flags & kBodyBladeOff) == 0;
    b.updateDerived();
  }
  impulseCache_ = std::move(cache);
  if (!lodWindow_) {
    std::fill(patches_.cut.begin(), patches_.cut.end(), uint8_t(0));
    for (const auto& [key, value] : cuts_) patches_.cut[patchWindow_.storageIndex(key.first, key.second)] = 1;
  }
  ++patchInputsRevision_;
  tick_ = tick;
  failed_ = false;
  failure_ = SimError{};
  rowDigestsCurrent_ = false;  // new particles: the state hash takes its digests afresh
  updatePatchState();
}

template <class S>
void World<S>::exportState(StateExport& out) const {
  using T = ScalarTraits<S>;
  syncFromDevice();
  out = StateExport{};
  out.scalar = T::kind;
  out.tick = tick_;
  out.interpolation = grid_.k;
  out.fieldPatchesX = lattice_.patchesX;
  out.fieldPatchesZ = lattice_.patchesZ;
  // Particles in lattice order (rows of the window from its origin), not the toroidal storage.
  const LatticeWindow& w = grid_.window;
  out.particleOriginI = w.originI;
  out.particleOriginJ = w.originJ;
  out.particlesX = w.sizeI;
  out.particlesZ = w.sizeJ;
  for (int64_t J = w.originJ; J < w.originJ + w.sizeJ; ++J)
    for (int64_t I = w.originI; I < w.originI + w.sizeI; ++I) {
      const size_t q = w.storageIndex(I, J);
      for (const auto* v : {&particles_.px, &particles_.py, &particles_.pz})
        out.particlePosition.push_back(T::toDouble((*v)[q]));
      for (const auto* v : {&particles_.vx, &particles_.vy, &particles_.vz})
        out.particleVelocity.push_back(T::toDouble((*v)[q]));
    }
  const LatticeWindow& pw = patchWindow_;
  out.patchOriginI = pw.originI;
  out.patchOriginJ = pw.originJ;
  out.patchesX = pw.sizeI;
  out.patchesZ = pw.sizeJ;
  for (int64_t j = pw.originJ; j < pw.originJ + pw.sizeJ; ++j)
    for (int64_t i = pw.originI; i < pw.originI + pw.sizeI; ++i) {
      const size_t p = pw.storageIndex(i, j);
      out.tipOffset.push_back(T::toDouble(patches_.tipOffsetX[p]));
      out.tipOffset.push_back(T::toDouble(patches_.topY[p] - patches_.rootY[p]));
      out.tipOffset.push_back(T::toDouble(patches_.tipOffsetZ[p]));
    }
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const RigidBody<S>& b = bodies_[i];
    StateExport::Body e;
    for (int a = 0; a < 3; ++a) {
      e.position[size_t(a)] = T::toDouble(b.position[a]);
      e.velocity[size_t(a)] = T::toDouble(b.velocity[a]);
      e.angularVelocity[size_t(a)] = T::toDouble(b.angularVelocity[a]);
    }
    e.orientation = {T::toDouble(b.orientation.w()), T::toDouble(b.orientation.x()), T::toDouble(b.orientation.y()),
                     T::toDouble(b.orientation.z())};
    e.templateBody = bodyTemplate(int64_t(i));
    e.asleep = b.asleep;
    e.bladeOn = b.mower && b.bladeOn;
    out.bodies.push_back(e);
  }
  for (const auto& [key, value] : cuts_) out.cuts.push_back({key.first, key.second});
}

#define SG_INSTANTIATE_STATE_IO(S)                                       \
  template void World<S>::serialise(StateSink&, const uint64_t*) const;  \
  template uint64_t World<S>::stateHash() const;                         \
  template int64_t World<S>::particleGroups() const;                     \
  template std::vector<uint64_t> World<S>::particleGroupDigests() const; \
  template void World<S>::digestParticleGroup(int64_t, uint64_t*) const; \
  template std::vector<uint8_t> World<S>::saveState() const;             \
  template void World<S>::restoreState(std::span<const uint8_t>);        \
  template void World<S>::exportState(StateExport&) const;
SG_FOR_EACH_SCALAR(SG_INSTANTIATE_STATE_IO)

}  // namespace sg
