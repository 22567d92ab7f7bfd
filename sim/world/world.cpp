// World<S>: construction from a scenario, the step as a sequence of stages, and state I/O.
#include "sim/world/world.h"

#include <bit>
#include <cstring>
#include <type_traits>

#include "sim/bodies/integrate_bodies.h"
#include "sim/collision/body_pairs.h"
#include "sim/particles/particle_row.h"
#include "sim/world/state_sink.h"

namespace sg {

static_assert(std::endian::native == std::endian::little,
              "the canonical state serialisation writes arrays as they are in memory: little-endian hosts only");

namespace {
constexpr char kStateMagic[8] = {'S', 'G', 'S', 'T', 'A', 'T', 'E', '1'};
constexpr uint32_t kStateVersion = 1;
constexpr size_t kStateHeaderBytes = 40;
/// Opens the body-input block at the end of a state: spawned bodies and switched-off blades.
constexpr char kBodyInputMagic[8] = {'S', 'G', 'B', 'O', 'D', 'Y', 'X', '1'};
constexpr int64_t kTargetChunkElements = 4096;  // chunk size: fixed by problem size only

template <class S>
S toS(const Rational& r) {
  // validateForScalar checks every value first; this guard turns a missed case into an error.
  const auto v = ScalarTraits<S>::fromRational(r);
  if (!v) throw std::out_of_range(std::string("value ") + r.toString() + " does not fit " + scalarName(ScalarTraits<S>::kind));
  return *v;
}

void hashRational(HashSink& h, const Rational& r) {
  // Two's complement limbs, low first: the bytes a builtin __int128 has in memory on the
  // little-endian hosts this serialisation supports, whichever Int128 type the build uses.
  const uint64_t limbs[4] = {low64(r.num), high64(r.num), low64(r.den), high64(r.den)};
  h.write(limbs, sizeof limbs);
}

/// Fingerprint of everything that shapes the world (not the name or description), so a saved
/// state is only restored into a world built from an equivalent scenario.
uint64_t scenarioFingerprint(const Scenario& s) {
  HashSink h;
  const auto& f = s.field;
  const auto& p = s.particles;
  const int64_t ints[] = {f.patchesX, f.patchesZ, f.atlasVariants, p.interpolation, int64_t(p.constraintMode),
                          int64_t(s.wind.travel), int64_t(s.scalar), s.terrain.flat ? 1 : 0,
                          int64_t(s.terrain.heightmap.width), int64_t(s.terrain.heightmap.height)};
  h.write(ints, sizeof ints);
  h.write(&s.seed, sizeof s.seed);
  for (const Rational* r : {&s.timeStep, &f.spacing, &f.jitter, &f.centerX, &f.centerZ, &f.scaleY, &f.scaleXZ,
                            &p.constraintLength, &p.mass, &p.damping, &s.wind.travelSpeed, &s.terrain.flatHeight,
                            &s.terrain.cellSize, &s.terrain.maxHeight, &s.terrain.centerX, &s.terrain.centerZ})
    hashRational(h, *r);
  for (int c = 0; c < 3; ++c) {
    hashRational(h, p.initialVelocity[size_t(c)]);
    hashRational(h, p.acceleration[size_t(c)]);
    hashRational(h, p.tiltDrop[size_t(c)]);
  }
  for (const WindGust& g : s.wind.schedule) {
    for (const Rational& r : g.force) hashRational(h, r);
    hashRational(h, g.duration);
  }
  h.write(s.terrain.heightmap.samples.data(), s.terrain.heightmap.samples.size());
  if (s.lod.mode == LodMode::Window) {  // worlds without the window keep their fingerprint
    const int64_t lod[] = {1, s.lod.windowX, s.lod.windowZ, s.lod.edgeSpacing, s.lod.edgeRows, s.lod.centerGiven ? 1 : 0};
    h.write(lod, sizeof lod);
    hashRational(h, s.lod.centerX);
    hashRational(h, s.lod.centerZ);
  }
  if (!s.bodies.list.empty()) {  // worlds without bodies keep the fingerprint they always had
    const auto& b = s.bodies;
    // Not the broad phases: they are promised to give the same state, so they must not change it.
    const int64_t settings[] = {b.velocityIterations, b.positionIterations, int64_t(b.boxParticleNormal),
                                int64_t(b.list.size())};
    h.write(settings, sizeof settings);
    for (const Rational& g : b.gravity) hashRational(h, g);
    hashRational(h, b.grassDrag);
    hashRational(h, b.mowerCutHeight);
    for (const BodySpec& body : b.list) {
      h.write(body.name.data(), body.name.size());
      for (const ShapeSpec& part : body.parts) {
        const int64_t type = int64_t(part.type);
        h.write(&type, sizeof type);
        hashRational(h, part.radius);
        for (const Rational& r : part.halfExtents) hashRational(h, r);
        for (const Rational& r : part.offset) hashRational(h, r);
      }
      for (const Rational* r : {&body.mass, &body.linearDamping, &body.angularDamping, &body.restitution, &body.friction})
        hashRational(h, *r);
      const int64_t flags = (body.mower ? 1 : 0) | (body.canSleep ? 2 : 0);
      h.write(&flags, sizeof flags);
    }
  }
  return h.digest();
}
}  // namespace

std::string SimError::message() const {
  std::string m = "simulation error at tick " + std::to_string(tick) + ", stage '" + stageName(stage) + "'";
  if (body >= 0) m += ", body " + std::to_string(body);
  if (particle >= 0)
    m += ", particle " + std::to_string(particle) + " (patch " + std::to_string(latticeI) + ", " +
         std::to_string(latticeJ) + ")";
  return m + ": " + what;
}

StateError::StateError(uint64_t offset, const std::string& expected)
    : std::runtime_error("byte " + std::to_string(offset) + ": expected " + expected), offset_(offset) {}

// ---- construction ---------------------------------------------------------------------------

template <class S>
World<S>::World(const Scenario& s, int threads) : pool_(std::make_unique<ChunkPool>(threads < 1 ? 1 : threads)) {
  configHash_ = scenarioFingerprint(s);
  constraintMode_ = s.particles.constraintMode;
  const ScenarioConstants c = deriveConstants(s);
  const auto& f = s.field;
  const int k = s.particles.interpolation;

  lattice_.patchesX = f.patchesX;
  lattice_.patchesZ = f.patchesZ;
  lattice_.spacing = toS<S>(f.spacing);
  lattice_.jitterAmplitude = toS<S>(c.jitterAmplitude);
  lattice_.originX = toS<S>(c.fieldOriginX);
  lattice_.originZ = toS<S>(c.fieldOriginZ);
  lattice_.seed = s.seed;
  lattice_.atlasVariants = f.atlasVariants;
  terrain_ = Terrain<S>(s.terrain, c);

  grid_.k = k;
  lodWindow_ = s.lod.mode == LodMode::Window;
  grid_.window.fieldI = c.particlesX;
  grid_.window.fieldJ = c.particlesZ;
  patchWindow_.fieldI = f.patchesX;
  patchWindow_.fieldJ = f.patchesZ;
  if (lodWindow_) {
    // A window keeps every patch it holds between two held particles: it spans at most the
    // particles whose patch (k a, k b) lies in the field, and holds patches k I0 .. k (I0+W-1).
    grid_.countX = std::min(s.lod.windowX, (f.patchesX - 1) / k + 1);
    grid_.countZ = std::min(s.lod.windowZ, (f.patchesZ - 1) / k + 1);
    patchWindow_.sizeI = (grid_.countX - 1) * k + 1;
    patchWindow_.sizeJ = (grid_.countZ - 1) * k + 1;
  } else {
    grid_.countX = c.particlesX;
    grid_.countZ = c.particlesZ;
    patchWindow_.sizeI = f.patchesX;
    patchWindow_.sizeJ = f.patchesZ;
  }
  grid_.window.sizeI = grid_.countX;
  grid_.window.sizeJ = grid_.countZ;

  particleConsts_.dt = toS<S>(s.timeStep);
  particleConsts_.invDt = toS<S>(c.invDt);
  particleConsts_.dampingPerTick = toS<S>(c.dampingPerTick);
  particleConsts_.rodLength = toS<S>(s.particles.constraintLength);

  patchConsts_.k = k;
  for (const Rational& w : c.interpolationWeights) patchConsts_.weight.push_back(toS<S>(w));
  exactRowWeights_ = rowWeightsAreExact(patchConsts_);
  patchConsts_.rodLength = particleConsts_.rodLength;
  patchConsts_.halfRod = toS<S>(c.halfRod);
  patchConsts_.scaleY = toS<S>(f.scaleY);
  mowerCutHeight_ = toS<S>(s.bodies.mowerCutHeight);
  patchConsts_.cutReduction = maxS(patchConsts_.scaleY - mowerCutHeight_, S(0));
  patchConsts_.minimumTop = patchConsts_.scaleY / S(10);
  if (s.markings.enabled) {
    const auto& m = s.markings;
    markings_.enabled = true;
    markings_.centerX = toS<S>(m.centerX);
    markings_.centerZ = toS<S>(m.centerZ);
    markings_.halfLength = toS<S>(m.length) / S(2);
    markings_.halfWidth = toS<S>(m.width) / S(2);
    markings_.halfLine = toS<S>(m.lineWidth) / S(2);
    markings_.circleRadius = toS<S>(m.centerCircleRadius);
  }
  for (int i = 0; i < 3; ++i) patchConsts_.drop[i] = toS<S>(s.particles.tiltDrop[size_t(i)]);

  for (const auto& force : c.gustForcePerMass) {
    windConsts_.forceX.push_back(toS<S>(force[0]));
    windConsts_.forceY.push_back(toS<S>(force[1]));
    windConsts_.forceZ.push_back(toS<S>(force[2]));
  }
  windConsts_.accX = toS<S>(s.particles.acceleration[0]);
  windConsts_.accY = toS<S>(s.particles.acceleration[1]);
  windConsts_.accZ = toS<S>(s.particles.acceleration[2]);
  windConsts_.dt = particleConsts_.dt;
  windSchedule_ = WindSchedule::build(s, c);

  // Rigid bodies.
  for (size_t i = 0; i < s.bodies.list.size(); ++i)
    bodies_.push_back(makeBody<S>(s.bodies.list[i], s.timeStep, s.sourceName, "$.bodies.list[" + std::to_string(i) + "]"));
  initialBodies_ = bodies_;
  gravityDt_ = Vec3<S>(toS<S>(s.bodies.gravity[0]), toS<S>(s.bodies.gravity[1]), toS<S>(s.bodies.gravity[2])) *
               particleConsts_.dt;
  solver_.velocityIterations = s.bodies.velocityIterations;
  solver_.positionIterationsPerContact = s.bodies.positionIterations;
  // Approaches slower than 1 m/s do not bounce (Box2D's b2_velocityThreshold): below that,
  // restitution plus the energy the position projection adds keeps a ball hopping forever.
  solver_.restitutionThreshold = S(1);
  solver_.linearSlop = toS<S>(Rational{1, 2000});  // 0.5 mm
  bodyBroadphase_ = s.bodies.bodyBroadphase;
  grassDragDt_ = toS<S>(s.bodies.grassDrag) * particleConsts_.dt;
  sleepLinear_ = toS<S>(Rational{1, 20});   // 5 cm/s
  sleepAngular_ = toS<S>(Rational{1, 20});  // 0.05 rad/s
  ticksToSleep_ = std::max<int32_t>(1, int32_t(*div(Rational{1, 2}, s.timeStep)->roundToInt64()));  // 0.5 s
  bodyParticle_.boxNormal = s.bodies.boxParticleNormal;
  bodyParticle_.broadphase = s.bodies.particleBroadphase;
  bodyParticle_.particleInvMass = toS<S>(c.invMass);
  S largest(0);
  for (const RigidBody<S>& b : bodies_) largest = maxS(largest, b.boundingRadius);
  bodyParticle_.margin = particleConsts_.rodLength + lattice_.jitterAmplitude + largest;
  bodyParticle_.anchorOriginX = lattice_.originX;
  bodyParticle_.anchorOriginZ = lattice_.originZ;
  bodyParticle_.invParticleSpacing = toS<S>(c.invParticleSpacing);

  // Patches and particles of the window: static attributes from the lattice hash, roots on the
  // terrain, particles at rest length straight up with the scenario's initial velocity.
  const size_t nPatches = size_t(patchWindow_.size());
  for (auto* v : {&patches_.rootX, &patches_.rootY, &patches_.rootZ, &patches_.tipOffsetX, &patches_.tipOffsetZ,
                  &patches_.topY})
    v->assign(nPatches, S(0));
  patches_.rotation.assign(nPatches, 0);
  patches_.variant.assign(nPatches, 0);
  patches_.cut.assign(nPatches, 0);
  patches_.tiltLevel.assign(nPatches, 0);
  particles_.resize(size_t(grid_.size()));
  int64_t startI = 0, startJ = 0;
  edgeRing_.configure(lattice_, s.lod.edgeSpacing, lodWindow_ ? s.lod.edgeRows : 0);
  initialVelocity_ = Vec3<S>(toS<S>(s.particles.initialVelocity[0]), toS<S>(s.particles.initialVelocity[1]),
                             toS<S>(s.particles.initialVelocity[2]));
  if (lodWindow_) {
    // The window starts centred on lod.center (default: the field centre).
    const Rational cx = s.lod.centerGiven ? s.lod.centerX : f.centerX, cz = s.lod.centerGiven ? s.lod.centerZ : f.centerZ;
    startI = clampWindowOrigin(nearestParticleColumn(toS<S>(cx), lattice_.originX) - (grid_.countX - 1) / 2, true);
    startJ = clampWindowOrigin(nearestParticleColumn(toS<S>(cz), lattice_.originZ) - (grid_.countZ - 1) / 2, false);
  }
  fillWindow(startI, startJ, true);
  dispX_.assign(size_t(grid_.size()), S(0));
  dispY_.assign(size_t(grid_.size()), S(0));
  dispZ_.assign(size_t(grid_.size()), S(0));
  rowsPerChunk_ = std::max<int64_t>(1, kTargetChunkElements / grid_.countX);
  setThreads(pool_->threads());
  takeFixedFaults();
  updatePatchState();
}

// ---- the level-of-detail window (sim/lod/lattice_window.h, docs/level-of-detail.md) ----------

template <class S>
int64_t World<S>::nearestParticleColumn(S coordinate, S fieldOrigin) const {
  return floorToInt((coordinate - fieldOrigin) * bodyParticle_.invParticleSpacing + S(1) / S(2));
}

template <class S>
int64_t World<S>::clampWindowOrigin(int64_t origin, bool alongX) const {
  const LatticeWindow& w = grid_.window;
  // The last origin keeps every held patch inside the field: k (origin + size - 1) <= patches - 1.
  const int64_t last = alongX ? (patchWindow_.fieldI - 1) / grid_.k - (w.sizeI - 1)
                              : (patchWindow_.fieldJ - 1) / grid_.k - (w.sizeJ - 1);
  return std::clamp<int64_t>(origin, 0, std::max<int64_t>(0, last));
}

template <class S>
void World<S>::initParticle(int64_t I, int64_t J, bool initialVelocity) {
  const size_t q = grid_.window.storageIndex(I, J);
  S x, z;
  lattice_.rootXZ(I * grid_.k, J * grid_.k, &x, &z);
  const S y = terrain_.heightAt(x, z);
  particles_.anchorX[q] = x;
  particles_.anchorY[q] = y;
  particles_.anchorZ[q] = z;
  particles_.px[q] = x;
  particles_.py[q] = y + particleConsts_.rodLength;
  particles_.pz[q] = z;
  // Particles entering a moving window start at rest; the scenario's initial velocity is the
  // thesis' start-up kick for the first window only.
  const Vec3<S> v = initialVelocity ? initialVelocity_ : Vec3<S>::Zero();
  particles_.vx[q] = v.x();
  particles_.vy[q] = v.y();
  particles_.vz[q] = v.z();
}

template <class S>
void World<S>::initPatch(int64_t i, int64_t j) {
  const size_t p = patchWindow_.storageIndex(i, j);
  lattice_.rootXZ(i, j, &patches_.rootX[p], &patches_.rootZ[p]);
  patches_.rootY[p] = terrain_.heightAt(patches_.rootX[p], patches_.rootZ[p]);
  patches_.rotation[p] = lattice_.rotation(i, j);
  patches_.variant[p] = lattice_.variant(i, j);
  // Markings use the un-jittered lattice point: straight lines despite the jitter.
  if (markings_.onLine(lattice_.originX + mulInt(lattice_.spacing, i), lattice_.originZ + mulInt(lattice_.spacing, j)))
    patches_.variant[p] = uint8_t(lattice_.atlasVariants);
  // Mown tufts stay mown: the cut lives in the persistent world data, not in the window.
  patches_.cut[p] = cuts_.count({i, j}) ? 1 : 0;
}

template <class S>
void World<S>::fillWindow(int64_t originI, int64_t originJ, bool initialVelocity) {
  moveWindowTo(originI, originJ, initialVelocity, true);
}

template <class S>
void World<S>::moveWindowTo(int64_t originI, int64_t originJ, bool initialVelocity, bool everything) {
  const LatticeWindow oldParticles = grid_.window, oldPatches = patchWindow_;
  grid_.window.originI = originI;
  grid_.window.originJ = originJ;
  patchWindow_.originI = originI * grid_.k;
  patchWindow_.originJ = originJ * grid_.k;
  // Only what enters is written: rows new to the window entirely, other rows only in the
  // columns new to it. Each cell depends on its lattice coordinates alone, so the result is the
  // same whatever the path and the thread count.
  auto fill = [&](const LatticeWindow& now, const LatticeWindow& before, auto&& init) {
    pool_->run(now.sizeJ, [&](int64_t r, int) { forEachEnteringCell(now, before, everything, r, init); });
  };
  fill(grid_.window, oldParticles, [&](int64_t I, int64_t J) { initParticle(I, J, initialVelocity); });
  fill(patchWindow_, oldPatches, [&](int64_t i, int64_t j) { initPatch(i, j); });
  if (lodWindow_)
    edgeRing_.follow(patchWindow_, terrain_, markings_, [&](int64_t i, int64_t j) { return cuts_.count({i, j}) > 0; },
                     everything);
}

template <class S>
void World<S>::followCamera(const InputVec3& camera) {
  // The window's centre follows the camera's nearest particle column and row with a dead zone of
  // one particle spacing: a camera that stops, or wobbles across a cell border, moves nothing.
  // (The thesis accumulated projected camera motion per side; this is a function of the camera
  // position and the window alone, so it cannot drift.)
  const auto toScalar = [](int64_t raw) {
    return ScalarTraits<S>::fromRational(Rational{raw, int64_t(1) << 32}).value_or(S(0));
  };
  const int64_t camI = nearestParticleColumn(toScalar(camera.x), lattice_.originX);
  const int64_t camJ = nearestParticleColumn(toScalar(camera.z), lattice_.originZ);
  auto follow = [](int64_t origin, int64_t size, int64_t cam) {
    const int64_t centre = origin + (size - 1) / 2;
    if (cam > centre + 1) return origin + (cam - 1 - centre);
    if (cam < centre - 1) return origin - (centre - 1 - cam);
    return origin;
  };
  const int64_t I0 = clampWindowOrigin(follow(grid_.window.originI, grid_.window.sizeI, camI), true);
  const int64_t J0 = clampWindowOrigin(follow(grid_.window.originJ, grid_.window.sizeJ, camJ), false);
  if (I0 != grid_.window.originI || J0 != grid_.window.originJ) moveWindowTo(I0, J0, false, false);
}

template <class S>
void World<S>::setThreads(int threads) {
  if (threads < 1) threads = 1;
  if (threads != pool_->threads()) pool_ = std::make_unique<ChunkPool>(threads);
  rowScratch_.assign(size_t(threads) * size_t(3 * (grid_.countX + patchWindow_.sizeI)), S(0));
}

template <class S>
WorldCounts World<S>::counts() const {
  WorldCounts n{lattice_.patchesX, lattice_.patchesZ, grid_.countX, grid_.countZ, grid_.k, pool_->threads(),
                int64_t(bodies_.size()), int64_t(contacts_.size())};
  n.lodWindow = lodWindow_;
  n.windowPatchesX = patchWindow_.sizeI;
  n.windowPatchesZ = patchWindow_.sizeJ;
  n.windowOriginI = patchWindow_.originI;
  n.windowOriginJ = patchWindow_.originJ;
  return n;
}

// ---- the step -------------------------------------------------------------------------------

template <class S>
template <class Fn>
bool World<S>::runParticleRows(Stage stage, Fn&& rowKernel) {
  const int64_t chunks = (grid_.countZ + rowsPerChunk_ - 1) / rowsPerChunk_;
  std::vector<RowFault> faultAt(static_cast<size_t>(chunks));
  std::vector<uint32_t> faultBits(size_t(chunks), 0);
  pool_->run(chunks, [&](int64_t c, int) {
    takeFixedFaults();
    const int64_t b1 = std::min(grid_.countZ, (c + 1) * rowsPerChunk_);
    for (int64_t b = c * rowsPerChunk_; b < b1; ++b) {
      RowFault fault{-1, stage};
      // A kernel returns the faulting particle (-1: none), or a RowFault when it spans stages.
      if constexpr (std::is_same_v<decltype(rowKernel(b, b, b)), RowFault>)
        fault = rowKernel(b, b * grid_.countX, (b + 1) * grid_.countX);
      else
        fault.particle = rowKernel(b, b * grid_.countX, (b + 1) * grid_.countX);
      if (fault.particle >= 0) {
        faultAt[size_t(c)] = fault;
        faultBits[size_t(c)] = takeFixedFaults();
        return;
      }
    }
  });
  // The first faulting chunk in index order: the same report for any thread count.
  for (int64_t c = 0; c < chunks; ++c) {
    if (faultAt[size_t(c)].particle < 0) continue;
    const int64_t q = faultAt[size_t(c)].particle;
    failed_ = true;
    failure_.tick = tick_;
    failure_.stage = faultAt[size_t(c)].stage;
    failure_.particle = q;
    failure_.latticeI = grid_.window.latticeColumn(q % grid_.countX) * grid_.k;
    failure_.latticeJ = grid_.window.latticeRow(q / grid_.countX) * grid_.k;
    failure_.what = faultBits[size_t(c)] ? fixedFaultName(faultBits[size_t(c)]) : "non-finite value";
    return false;
  }
  return true;
}

template <class S>
void World<S>::updatePatchState() {
  const S rod = particleConsts_.rodLength;
  pool_->run((grid_.countZ + rowsPerChunk_ - 1) / rowsPerChunk_, [&](int64_t c, int) {
    const int64_t b1 = std::min(grid_.countZ, (c + 1) * rowsPerChunk_);
    particleDisplacement(particles_, c * rowsPerChunk_ * grid_.countX, b1 * grid_.countX, rod, dispX_, dispY_, dispZ_);
  });
  updatePatchesFromDisplacement();
}

template <class S>
void World<S>::updatePatchesFromDisplacement() {
  if (grid_.k == 1) {  // patch and particle windows coincide: storage index for storage index
    const PatchWriter<S> out(patches_, patchConsts_);
    const S *dx = dispX_.data(), *dy = dispY_.data(), *dz = dispZ_.data();
    pool_->run((grid_.countZ + rowsPerChunk_ - 1) / rowsPerChunk_, [&](int64_t c, int) {
      const int64_t q0 = c * rowsPerChunk_ * grid_.countX;
      const int64_t q1 = std::min(grid_.countZ, (c + 1) * rowsPerChunk_) * grid_.countX;
      if constexpr (ScalarTraits<S>::isFixed)
        if (particleKernel_ == ParticleKernel::Avx2)
          return writePatchesAvx2(out, size_t(q0), dx + q0, dy + q0, dz + q0, q1 - q0);
      for (int64_t q = q0; q < q1; ++q)
        out.writeFast(size_t(q), dx[q], dy[q], dz[q]);  // same bits as write(): patch_state.h
    });
    return;
  }
  const bool vector = particleKernel_ == ParticleKernel::Avx2;
  const LatticeWindow& pw = patchWindow_;
  const int64_t patchRowsPerChunk = std::max<int64_t>(1, kTargetChunkElements / pw.sizeI);
  pool_->run((pw.sizeJ + patchRowsPerChunk - 1) / patchRowsPerChunk, [&](int64_t c, int worker) {
    S* scratch = rowScratch_.data() + size_t(worker) * size_t(3 * (grid_.countX + pw.sizeI));
    const int64_t j1 = pw.originJ + std::min(pw.sizeJ, (c + 1) * patchRowsPerChunk);
    for (int64_t j = pw.originJ + c * patchRowsPerChunk; j < j1; ++j)
      exactRowWeights_ && grid_.k == 2 ? updatePatchRow<S, 2>(patches_, pw, j, grid_.window, dispX_, dispY_, dispZ_, patchConsts_, scratch, vector)
      : exactRowWeights_ && grid_.k == 4 ? updatePatchRow<S, 4>(patches_, pw, j, grid_.window, dispX_, dispY_, dispZ_, patchConsts_, scratch, vector)
                                          : updatePatchRow<S>(patches_, pw, j, grid_.window, dispX_, dispY_, dispZ_, patchConsts_, scratch);
  });
}

namespace {
template <class S>
Vec3<S> inputVector(const InputVec3& v) {
  auto component = [](int64_t raw) { return ScalarTraits<S>::fromRational(Rational{raw, int64_t(1) << 32}).value_or(S(0)); };
  return Vec3<S>(component(v.x), component(v.y), component(v.z));
}
}  // namespace

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
    wake(b);
    const Vec3<S> v = inputVector<S>(cmd.value);
    switch (cmd.kind) {
      case BodyCommandKind::Displace: b.position += v; break;
      case BodyCommandKind::AddVelocity: b.velocity += v; break;
      case BodyCommandKind::Impulse: b.velocity += v * b.invMass; break;
      case BodyCommandKind::Teleport:
        b.position = v;
        b.velocity = Vec3<S>::Zero();
        b.angularVelocity = Vec3<S>::Zero();
        break;
      case BodyCommandKind::Reset: resetBody(size_t(cmd.body)); break;
      case BodyCommandKind::Spawn:
      case BodyCommandKind::MowerOn:
      case BodyCommandKind::MowerOff: break;  // handled above
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
  b.position = body < scenarioBodies ? start.position : inputVector<S>(spawns_[body - scenarioBodies].position);
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
  b.position = inputVector<S>(at);
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
void World<S>::mowGrass() {
  // A mower part cuts every tuft whose point at the blade height (root + mowerCutHeight) lies
  // inside it. Cuts are keyed by lattice coordinates and never undone.
  const S invSpacing = S(1) / lattice_.spacing;
  for (const RigidBody<S>& body : bodies_) {
    if (!body.mower || !body.bladeOn) continue;  // a switched-off blade still collides, but cuts nothing
    for (size_t part = 0; part < body.parts.size(); ++part) {
      const BodyPart<S>& shape = body.parts[part];
      const Pose<S> pose = body.partPose(part);
      const S reach = shape.boundingRadius + lattice_.jitterAmplitude + lattice_.spacing;
      const int64_t i0 = std::max<int64_t>(0, floorToInt((pose.position.x() - reach - lattice_.originX) * invSpacing));
      const int64_t i1 = std::min<int64_t>(lattice_.patchesX - 1, floorToInt((pose.position.x() + reach - lattice_.originX) * invSpacing) + 1);
      const int64_t j0 = std::max<int64_t>(0, floorToInt((pose.position.z() - reach - lattice_.originZ) * invSpacing));
      const int64_t j1 = std::min<int64_t>(lattice_.patchesZ - 1, floorToInt((pose.position.z() + reach - lattice_.originZ) * invSpacing) + 1);
      // Roots come from the lattice, not the window: a mower cuts wherever it drives.
      for (int64_t j = j0; j <= j1; ++j)
        for (int64_t i = i0; i <= i1; ++i) {
          if (cuts_.count({i, j})) continue;
          S rootX, rootZ;
          lattice_.rootXZ(i, j, &rootX, &rootZ);
          const Vec3<S> blade(rootX, terrain_.heightAt(rootX, rootZ) + mowerCutHeight_, rootZ);
          bool inside;
          if (shape.type == ShapeType::Sphere) {
            const Vec3<S> d = blade - pose.position;
            inside = abs(d.x()) < shape.radius && abs(d.y()) < shape.radius && abs(d.z()) < shape.radius &&
                     length3(d.x(), d.y(), d.z()) < shape.radius;
          } else {
            const Vec3<S> local = pose.toLocal(blade);
            inside = abs(local.x()) < shape.halfExtents.x() && abs(local.y()) < shape.halfExtents.y() &&
                     abs(local.z()) < shape.halfExtents.z();
          }
          if (!inside) continue;
          if (patchWindow_.contains(i, j)) patches_.cut[patchWindow_.storageIndex(i, j)] = 1;
          cuts_.emplace(std::make_pair(i, j), uint8_t(1));
        }
    }
  }
}

template <class S>
bool World<S>::respondToContacts() {
  applyGravity(bodies_, gravityDt_);
  solveContactVelocities(bodies_, contacts_, solver_, impulseCache_);
  solveContactPositions(bodies_, contacts_, solver_);
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

template <class S>
StepResult World<S>::step(const TickInput& input, StageObserver* observer) {
  if (failed_) return {false, failure_};
  auto begin = [&](Stage st) { if (observer) observer->stageBegin(st); };
  auto end = [&](Stage st) { if (observer) observer->stageEnd(st); };
  const bool hasBodies = !bodies_.empty();
  takeFixedFaults();
  if (lodWindow_) {
    begin(Stage::Window);
    if (input.hasCamera) followCamera(input.camera);
    end(Stage::Window);
  }
  if (hasBodies) {
    applyCommands(input);
    if (bodiesFaulted(Stage::Collision)) return {false, failure_};
  }

  begin(Stage::Wind);
  computeRowAcceleration(windSchedule_, windConsts_, tick_, &rowAccel_);
  if (const uint32_t f = takeFixedFaults()) {
    failed_ = true;
    failure_ = SimError{};
    failure_.tick = tick_;
    failure_.stage = Stage::Wind;
    failure_.what = fixedFaultName(f);
  }
  end(Stage::Wind);
  if (failed_) return {false, failure_};

  // A scenario without bodies pays nothing for the two body stages.
  if (hasBodies) {
    begin(Stage::Collision);
    detectContacts();
    const bool detected = !bodiesFaulted(Stage::Collision);
    end(Stage::Collision);
    if (!detected) return {false, failure_};
    begin(Stage::Response);
    const bool responded = respondToContacts();
    end(Stage::Response);
    if (!responded) return {false, failure_};
  }

  const ParticleConstants<S>& c = particleConsts_;
  const bool pbd = constraintMode_ == ConstraintMode::Pbd;
  // Integration, the rod constraint and the tip displacement run as one pass, row by row
  // (sim/particles/particle_row.h): bit-identical to three passes, a third of the memory traffic.
  // Its time is reported under Stage::Integrate; Stage::Constraints names a projection fault.
  begin(Stage::Integrate);
  const bool moved = runParticleRows(Stage::Integrate, [&](int64_t row, int64_t b, int64_t e) {
    const size_t windRow = size_t(grid_.window.latticeRow(row));  // the wind acts per lattice row
    const S dvx = rowAccel_.x[windRow], dvy = rowAccel_.y[windRow], dvz = rowAccel_.z[windRow];
    const ParticleKernel kernel = particleKernel_;
    return pbd ? advanceParticleRow<S, true>(kernel, particles_, b, e, dvx, dvy, dvz, c, dispX_, dispY_, dispZ_)
               : advanceParticleRow<S, false>(kernel, particles_, b, e, dvx, dvy, dvz, c, dispX_, dispY_, dispZ_);
  });
  if (moved && hasBodies) {
    integrateBodyPositions(bodies_, c.dt);
    updateSleep(bodies_, sleepLinear_, sleepAngular_, ticksToSleep_);
    if (bodiesFaulted(Stage::Integrate)) return {false, failure_};
  }
  end(Stage::Integrate);
  if (!moved) return {false, failure_};

  begin(Stage::PatchState);
  updatePatchesFromDisplacement();
  end(Stage::PatchState);

  ++tick_;
  return {};
}

// ---- state I/O --------------------------------------------------------------------------------

template <class S>
void World<S>::serialise(StateSink& sink) const {
  // Header (40 bytes, little-endian): magic, version, scalar, k, reserved, fingerprint, tick,
  // particle count. Then px, py, pz, vx, vy, vz as raw scalar bits, then the count of persistent
  // patch edits (mower cuts; always 0 until the rigid-body issue).
  static_assert(sizeof(S) * 13 == sizeof(S[13]));
  uint8_t header[kStateHeaderBytes] = {};
  std::memcpy(header, kStateMagic, 8);
  std::memcpy(header + 8, &kStateVersion, 4);
  header[12] = uint8_t(ScalarTraits<S>::kind);
  header[13] = uint8_t(grid_.k);
  const uint16_t bodyCount = uint16_t(bodies_.size());
  std::memcpy(header + 14, &bodyCount, 2);
  std::memcpy(header + 16, &configHash_, 8);
  std::memcpy(header + 24, &tick_, 8);
  const int64_t n = grid_.size();
  std::memcpy(header + 32, &n, 8);
  sink.write(header, sizeof header);
  for (const auto* v : {&particles_.px, &particles_.py, &particles_.pz, &particles_.vx, &particles_.vy, &particles_.vz})
    sink.write(v->data(), v->size() * sizeof(S));
  // Bodies (only when there are any, so body-free states are unchanged): 13 scalars each.
  for (const RigidBody<S>& b : bodies_) {
    const S values[13] = {b.position.x(), b.position.y(), b.position.z(), b.orientation.w(), b.orientation.x(),
                          b.orientation.y(), b.orientation.z(), b.velocity.x(), b.velocity.y(), b.velocity.z(),
                          b.angularVelocity.x(), b.angularVelocity.y(), b.angularVelocity.z()};
    sink.write(values, sizeof values);
    const int32_t sleep[2] = {b.stillTicks, b.asleep ? 1 : 0};
    sink.write(sleep, sizeof sleep);
  }
  if (!bodies_.empty()) {  // warm-start impulses: they shape the next tick, so they are state
    const uint64_t cached = impulseCache_.size();
    sink.write(&cached, sizeof cached);
    for (const CachedImpulse<S>& c : impulseCache_) {
      const int32_t ids[2] = {c.bodyA, c.bodyB};
      const uint32_t features[2] = {c.featureA, c.featureB};
      const S impulses[6] = {c.normal, c.tangent1, c.tangent2, c.point.x(), c.point.y(), c.point.z()};
      sink.write(ids, sizeof ids);
      sink.write(features, sizeof features);
      sink.write(impulses, sizeof impulses);
    }
  }
  // Persistent patch edits: mown patches (i, j), in key order.
  const uint64_t edits = cuts_.size();
  sink.write(&edits, sizeof edits);
  for (const auto& [key, value] : cuts_) {
    const int64_t ij[2] = {key.first, key.second};
    sink.write(ij, sizeof ij);
  }
  // The level-of-detail window's origin (only when it is on: other states are unchanged). The
  // particle arrays above are in its toroidal storage order, a function of the origin alone.
  if (lodWindow_) {
    const int64_t origin[2] = {grid_.window.originI, grid_.window.originJ};
    sink.write(origin, sizeof origin);
  }
  // Body inputs (only once a body was spawned or a blade switched off, so every other state is
  // unchanged): magic, spawn count, per spawn (template, 0, position as Q32.32), then the count
  // of switched-off blades and their bodies in increasing order. The spawned bodies' dynamic
  // state is in the body blocks above (the header's body count includes them).
  std::vector<int64_t> bladesOff;
  for (size_t i = 0; i < bodies_.size(); ++i)
    if (bodies_[i].mower && !bodies_[i].bladeOn) bladesOff.push_back(int64_t(i));
  if (spawns_.empty() && bladesOff.empty()) return;
  sink.write(kBodyInputMagic, sizeof kBodyInputMagic);
  const uint64_t spawned = spawns_.size();
  sink.write(&spawned, sizeof spawned);
  for (const Spawned& sp : spawns_) {
    const int32_t ids[2] = {sp.templateBody, 0};
    const int64_t at[3] = {sp.position.x, sp.position.y, sp.position.z};
    sink.write(ids, sizeof ids);
    sink.write(at, sizeof at);
  }
  const uint64_t off = bladesOff.size();
  sink.write(&off, sizeof off);
  if (!bladesOff.empty()) sink.write(bladesOff.data(), bladesOff.size() * sizeof(int64_t));
}

template <class S>
uint64_t World<S>::stateHash() const {
  HashSink h;
  serialise(h);
  return h.digest();
}

template <class S>
std::vector<uint8_t> World<S>::saveState() const {
  ByteSink b;
  b.bytes.reserve(kStateHeaderBytes + 6 * size_t(grid_.size()) * sizeof(S) + 8);
  serialise(b);
  return std::move(b.bytes);
}

template <class S>
void World<S>::readBodyInputBlock(std::span<const uint8_t> bytes, size_t at, size_t bodyCount,
                                  std::vector<Spawned>* spawns, std::vector<uint8_t>* bladeOff) const {
  const size_t scenarioBodies = initialBodies_.size();
  auto need = [&](size_t from, size_t count, const std::string& what) {
    if (bytes.size() - from < count) throw StateError(bytes.size(), what + " (the data ends early)");
  };
  need(at, 16, "the body-input block: magic 'SGBODYX1' and a spawn count");
  if (std::memcmp(bytes.data() + at, kBodyInputMagic, 8) != 0)
    throw StateError(at, std::to_string(at) + " bytes of state or the body-input magic 'SGBODYX1', got " +
                             std::to_string(bytes.size()) + " bytes");
  uint64_t spawned;
  std::memcpy(&spawned, bytes.data() + at + 8, 8);
  if (spawned != bodyCount - scenarioBodies)
    throw StateError(at + 8, std::to_string(bodyCount - scenarioBodies) + " spawned bodies (the header's count), got " +
                                 std::to_string(spawned));
  size_t p = at + 16;
  need(p, size_t(spawned) * 32 + 8, "spawned bodies and a switched-off blade count");
  for (uint64_t i = 0; i < spawned; ++i, p += 32) {
    int32_t ids[2];
    int64_t xyz[3];
    std::memcpy(ids, bytes.data() + p, 8);
    std::memcpy(xyz, bytes.data() + p + 8, 24);
    if (ids[0] < 0 || size_t(ids[0]) >= scenarioBodies || ids[1] != 0)
      throw StateError(p, "a spawn template between 0 and " + std::to_string(scenarioBodies - 1) + ", then 0");
    spawns->push_back(Spawned{ids[0], InputVec3{xyz[0], xyz[1], xyz[2]}});
  }
  uint64_t off;
  std::memcpy(&off, bytes.data() + p, 8);
  if (off > bodyCount) throw StateError(p, "at most " + std::to_string(bodyCount) + " switched-off blades, got " + std::to_string(off));
  p += 8;
  if (bytes.size() - p != size_t(off) * 8)
    throw StateError(std::min(bytes.size(), p + size_t(off) * 8),
                     std::to_string(p + size_t(off) * 8) + " bytes of state, got " + std::to_string(bytes.size()));
  if (spawned == 0 && off == 0) throw StateError(at, "no body-input block when nothing was spawned or switched off");
  int64_t previous = -1;
  for (uint64_t i = 0; i < off; ++i, p += 8) {
    int64_t body;
    std::memcpy(&body, bytes.data() + p, 8);
    if (body <= previous || body >= int64_t(bodyCount))
      throw StateError(p, "switched-off blades in increasing body order, below " + std::to_string(bodyCount));
    const size_t t = size_t(body) < scenarioBodies ? size_t(body) : size_t((*spawns)[size_t(body) - scenarioBodies].templateBody);
    if (!initialBodies_[t].mower) throw StateError(p, "a mower's blade (body " + std::to_string(body) + " is no mower)");
    (*bladeOff)[size_t(body)] = 1;
    previous = body;
  }
}

template <class S>
void World<S>::restoreState(std::span<const uint8_t> bytes) {
  const size_t n = size_t(grid_.size());
  const size_t scenarioBodies = initialBodies_.size();
  if (bytes.size() < kStateHeaderBytes) throw StateError(bytes.size(), "a 40-byte state header (the data ends early)");
  if (std::memcmp(bytes.data(), kStateMagic, 8) != 0) throw StateError(0, "the state magic 'SGSTATE1'");
  uint32_t version;
  std::memcpy(&version, bytes.data() + 8, 4);
  if (version != kStateVersion)
    throw StateError(8, "state format version " + std::to_string(kStateVersion) + ", got " + std::to_string(version));
  if (bytes[12] != uint8_t(ScalarTraits<S>::kind))
    throw StateError(12, std::string("a state of scalar ") + scalarName(ScalarTraits<S>::kind));
  if (bytes[13] != uint8_t(grid_.k)) throw StateError(13, "interpolation k = " + std::to_string(grid_.k));
  uint16_t bodyCount;
  std::memcpy(&bodyCount, bytes.data() + 14, 2);
  // Spawns add bodies up to kMaxBodies (only to worlds that have a template body).
  const size_t maxBodies = scenarioBodies == 0 ? 0 : std::max(scenarioBodies, size_t(kMaxBodies));
  if (bodyCount < scenarioBodies || bodyCount > maxBodies)
    throw StateError(14, (maxBodies == scenarioBodies ? std::to_string(scenarioBodies)
                                                      : std::to_string(scenarioBodies) + " to " + std::to_string(maxBodies)) +
                             " bodies, got " + std::to_string(bodyCount));
  const size_t bodyBytes = size_t(bodyCount) * (13 * sizeof(S) + 8);
  uint64_t fingerprint;
  std::memcpy(&fingerprint, bytes.data() + 16, 8);
  if (fingerprint != configHash_) throw StateError(16, "a state saved from the same scenario (fingerprint differs)");
  int64_t tick, count;
  std::memcpy(&tick, bytes.data() + 24, 8);
  std::memcpy(&count, bytes.data() + 32, 8);
  if (tick < 0) throw StateError(24, "a non-negative tick");
  if (count != int64_t(n)) throw StateError(32, std::to_string(n) + " particles, got " + std::to_string(count));
  // Warm-start cache (only with bodies): count, then (ids, features, 3 impulses) per entry.
  const size_t cacheAt = kStateHeaderBytes + 6 * n * sizeof(S) + bodyBytes;
  const size_t entryBytes = 16 + 6 * sizeof(S);
  std::vector<CachedImpulse<S>> cache;
  size_t editsAt = cacheAt;
  if (bodyCount > 0) {
    if (bytes.size() < cacheAt + 8) throw StateError(bytes.size(), "the contact-impulse count (the data ends early)");
    uint64_t cached;
    std::memcpy(&cached, bytes.data() + cacheAt, 8);
    if (cached > (bytes.size() - cacheAt - 8) / entryBytes)
      throw StateError(cacheAt, "a contact-impulse count that fits the data, got " + std::to_string(cached));
    for (uint64_t e = 0; e < cached; ++e) {
      const size_t at = cacheAt + 8 + size_t(e) * entryBytes;
      CachedImpulse<S> c;
      int32_t ids[2];
      uint32_t features[2];
      S impulses[6];
      std::memcpy(ids, bytes.data() + at, 8);
      std::memcpy(features, bytes.data() + at + 8, 8);
      std::memcpy(impulses, bytes.data() + at + 16, sizeof impulses);
      const int32_t nb = int32_t(bodyCount);
      if (ids[0] < 0 || ids[0] >= nb || ids[1] < kTerrainBody || ids[1] >= nb)
        throw StateError(at, "contact bodies between -1 and " + std::to_string(nb - 1));
      c = CachedImpulse<S>{ids[0], ids[1], features[0], features[1], impulses[0], impulses[1], impulses[2],
                           Vec3<S>(impulses[3], impulses[4], impulses[5])};
      cache.push_back(c);
    }
    editsAt = cacheAt + 8 + size_t(cached) * entryBytes;
  }
  const size_t fixedSize = editsAt + 8;
  if (bytes.size() < fixedSize)
    throw StateError(bytes.size(), std::to_string(fixedSize) + " bytes of state, got " + std::to_string(bytes.size()));
  uint64_t edits;
  std::memcpy(&edits, bytes.data() + editsAt, 8);
  if (edits > uint64_t(lattice_.patchesX * lattice_.patchesZ))
    throw StateError(editsAt, "at most one edit per patch, got " + std::to_string(edits));
  const size_t windowAt = fixedSize + size_t(edits) * 16;
  const size_t blockAt = windowAt + (lodWindow_ ? 16 : 0);
  // The body-input block follows when the bytes go on (only worlds with bodies have one).
  const bool hasBlock = scenarioBodies > 0 && bytes.size() > blockAt;
  if (!hasBlock && bytes.size() != blockAt)
    throw StateError(std::min(bytes.size(), blockAt), std::to_string(blockAt) + " bytes of state, got " +
                                                          std::to_string(bytes.size()));
  std::vector<Spawned> spawns;
  std::vector<uint8_t> bladeOff(bodyCount, 0);
  if (hasBlock) readBodyInputBlock(bytes, blockAt, bodyCount, &spawns, &bladeOff);
  else if (bodyCount != scenarioBodies)
    throw StateError(blockAt, "the body-input block 'SGBODYX1' for " + std::to_string(bodyCount - scenarioBodies) +
                                  " spawned bodies (the data ends early)");
  int64_t windowOrigin[2] = {0, 0};
  if (lodWindow_) {
    std::memcpy(windowOrigin, bytes.data() + windowAt, 16);
    if (windowOrigin[0] != clampWindowOrigin(windowOrigin[0], true) || windowOrigin[1] != clampWindowOrigin(windowOrigin[1], false))
      throw StateError(windowAt, "a window origin that keeps the window inside the field");
  }
  std::map<std::pair<int64_t, int64_t>, uint8_t> cuts;
  for (uint64_t e = 0; e < edits; ++e) {
    int64_t ij[2];
    const size_t at = fixedSize + size_t(e) * 16;
    std::memcpy(ij, bytes.data() + at, 16);
    if (ij[0] < 0 || ij[1] < 0 || ij[0] >= lattice_.patchesX || ij[1] >= lattice_.patchesZ)
      throw StateError(at, "a patch inside the field");
    if (!cuts.empty() && !(cuts.rbegin()->first < std::make_pair(ij[0], ij[1])))
      throw StateError(at, "patch edits in increasing (i, j) order");
    cuts.emplace(std::make_pair(ij[0], ij[1]), uint8_t(1));
  }
  // Static window data first (anchors, patches, cut flags from the restored cuts), then the
  // particles' dynamic state over it.
  cuts_ = std::move(cuts);
  if (lodWindow_) fillWindow(windowOrigin[0], windowOrigin[1], false);
  const uint8_t* src = bytes.data() + kStateHeaderBytes;
  for (auto* v : {&particles_.px, &particles_.py, &particles_.pz, &particles_.vx, &particles_.vy, &particles_.vz}) {
    std::memcpy(v->data(), src, n * sizeof(S));
    src += n * sizeof(S);
  }
  // Scenario bodies, then a copy of the template of each spawned one; the state over them.
  bodies_.resize(scenarioBodies, initialBodies_.empty() ? RigidBody<S>{} : initialBodies_[0]);
  for (const Spawned& sp : spawns) bodies_.push_back(initialBodies_[size_t(sp.templateBody)]);
  spawns_ = std::move(spawns);
  for (size_t i = 0; i < bodies_.size(); ++i) bodies_[i].bladeOn = bladeOff[i] == 0;
  for (RigidBody<S>& b : bodies_) {
    S v[13];
    std::memcpy(v, src, sizeof v);
    src += sizeof v;
    b.position = Vec3<S>(v[0], v[1], v[2]);
    b.orientation = Quat<S>(v[3], v[4], v[5], v[6]);
    b.velocity = Vec3<S>(v[7], v[8], v[9]);
    b.angularVelocity = Vec3<S>(v[10], v[11], v[12]);
    int32_t sleep[2];
    std::memcpy(sleep, src, sizeof sleep);
    src += sizeof sleep;
    b.stillTicks = sleep[0] < 0 ? 0 : sleep[0];
    b.asleep = sleep[1] != 0;
    b.updateDerived();
  }
  impulseCache_ = std::move(cache);
  if (!lodWindow_) {
    std::fill(patches_.cut.begin(), patches_.cut.end(), uint8_t(0));
    for (const auto& [key, value] : cuts_) patches_.cut[patchWindow_.storageIndex(key.first, key.second)] = 1;
  }
  tick_ = tick;
  failed_ = false;
  failure_ = SimError{};
  updatePatchState();
}

template <class S>
void World<S>::observe(Observation& out) const {
  out.tick = tick_;
  out.patchesX = lattice_.patchesX;
  out.patchesZ = lattice_.patchesZ;
  const size_t n = size_t(lattice_.patchesX * lattice_.patchesZ);
  out.tipX.resize(n);
  out.tipY.resize(n);
  out.tipZ.resize(n);
  // The whole field: held patches as simulated, the others standing at rest (what the window
  // leaves out is exactly what compare's lod variant measures).
  const S zero(0);
  for (int64_t j = 0; j < lattice_.patchesZ; ++j)
    for (int64_t i = 0; i < lattice_.patchesX; ++i) {
      const size_t o = size_t(j * lattice_.patchesX + i);
      S x, y, z;
      if (patchWindow_.contains(i, j)) {
        const size_t p = patchWindow_.storageIndex(i, j);
        x = patches_.rootX[p] + patches_.tipOffsetX[p];
        y = patches_.topY[p];
        z = patches_.rootZ[p] + patches_.tipOffsetZ[p];
      } else {
        lattice_.rootXZ(i, j, &x, &z);
        const S top = patchConsts_.scaleY - (cuts_.count({i, j}) ? patchConsts_.cutReduction : zero);
        y = terrain_.heightAt(x, z) + (top < patchConsts_.minimumTop ? patchConsts_.minimumTop : top);
      }
      out.tipX[o] = ScalarTraits<S>::toDouble(x);
      out.tipY[o] = ScalarTraits<S>::toDouble(y);
      out.tipZ[o] = ScalarTraits<S>::toDouble(z);
    }
  out.bodyPosition.clear();
  out.bodyOrientation.clear();
  for (const RigidBody<S>& b : bodies_) {
    for (int a = 0; a < 3; ++a) out.bodyPosition.push_back(ScalarTraits<S>::toDouble(b.position[a]));
    for (const S q : {b.orientation.w(), b.orientation.x(), b.orientation.y(), b.orientation.z()})
      out.bodyOrientation.push_back(ScalarTraits<S>::toDouble(q));
  }
  out.contacts = int64_t(contacts_.size());
}

std::unique_ptr<SimWorld> makeWorld(const Scenario& scenario, int threads, uint64_t memoryLimitBytes) {
  validateForScalar(scenario, scenario.scalar, memoryLimitBytes);
  return dispatchScalar(scenario.scalar, [&]<class S>() -> std::unique_ptr<SimWorld> {
    return std::make_unique<World<S>>(scenario, threads);
  });
}

template class World<Fx32>;
template class World<Fx16>;
template class World<float>;
template class World<double>;

}  // namespace sg
