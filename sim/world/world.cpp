// World<S>: construction from a scenario, thread count, counts and observation; makeWorld.
// The step is in world_step.cpp, its stages in the folders named after them (docs/architecture.md),
// state I/O in sim/state/world_state.cpp.
#include "sim/world/world.h"

#include <algorithm>

#include "sim/scenario/fingerprint.h"
#include "sim/state/state_hash.h"
#include "sim/world/settings.h"

namespace sg {

namespace {
template <class S>
S toS(const Rational& r) {
  // validateForScalar checks every value first; this guard turns a missed case into an error.
  const auto v = ScalarTraits<S>::fromRational(r);
  if (!v)
    throw std::out_of_range(std::string("value ") + r.toString() + " does not fit " +
                            scalarName(ScalarTraits<S>::kind));
  return *v;
}

Rational exact(settings::Exact c) { return Rational{c.num, c.den}; }

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
  model_ = s.particles.model;
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
  particleConsts_.bladeStiffnessDt = toS<S>(c.bladeStiffnessDt);
  particleConsts_.bladeDampingPerTick = toS<S>(c.bladeDampingPerTick);
  particleConsts_.trampleDecayPerTick = toS<S>(c.trampleDecayPerTick);
  if (model_ == GrassModel::Blade) particleConsts_.invRodLength = toS<S>(c.invRodLength);

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
    bodies_.push_back(
        makeBody<S>(s.bodies.list[i], s.timeStep, s.sourceName, "$.bodies.list[" + std::to_string(i) + "]"));
  initialBodies_ = bodies_;
  // The soft step's sub-step h = dt / substeps and its rate, each rounded once from exact values.
  solver_.substeps = s.bodies.substeps;
  solver_.solveIterations = s.bodies.velocityIterations;
  solver_.islandSolveIterations = std::max(s.bodies.velocityIterations, s.bodies.islandVelocityIterations);
  solver_.relaxIterations = s.bodies.positionIterations;
  const Rational substep = *div(s.timeStep, Rational{s.bodies.substeps, 1});
  substepDt_ = toS<S>(substep);
  solver_.invSubstep = toS<S>(*div(Rational{s.bodies.substeps, 1}, s.timeStep));
  const Vec3<S> gravity(toS<S>(s.bodies.gravity[0]), toS<S>(s.bodies.gravity[1]), toS<S>(s.bodies.gravity[2]));
  gravityDt_ = gravity * particleConsts_.dt;
  solver_.gravity = gravity;
  gravitySubstep_ = gravity * substepDt_;
  solver_.restitutionThreshold = toS<S>(exact(settings::kRestitutionThreshold));
  solver_.maxPushVelocity = toS<S>(exact(settings::kContactPushMaxVelocity));
  solver_.linearSlop = toS<S>(exact(settings::kLinearSlop));
  {
    // Box2D: contact hertz at most a quarter of the sub-step rate; the terrain twice as stiff.
    const S quarterRate = solver_.invSubstep / S(4);
    const S hertz = minS(toS<S>(s.bodies.contactHertz), quarterRate);
    const S zeta = toS<S>(exact(settings::kContactDampingRatio)), pi = toS<S>(exact(settings::kPi));
    solver_.bodySoftness = makeSoftness(hertz, zeta, substepDt_, pi);
    solver_.staticSoftness = makeSoftness(S(2) * hertz, zeta, substepDt_, pi);
    // (1 / h) / omega / omega: omega^2 itself leaves fx16's range above 28 Hz.
    const S omega = S(2) * pi * hertz;
    solver_.bodyGiveTime = hertz > S(0) ? S(S(solver_.invSubstep / omega) / omega) : S(0);
    solver_.staticGiveTime = solver_.bodyGiveTime / S(4);  // twice the frequency
  }
  // A quarter turn per sub-step (Box2D v3's b2_maxRotation): (pi / 4) x substeps / dt, exact
  // before the one rounding (188 rad/s at the defaults).
  maxAngularSpeed_ =
      toS<S>(*mul(*mul(exact(settings::kPi), Rational{1, 4}), *div(Rational{s.bodies.substeps, 1}, s.timeStep)));
  speculativeDistance_ = toS<S>(exact(settings::kSpeculativeDistance));
  bodyBroadphase_ = s.bodies.bodyBroadphase;
  grassDragDt_ = toS<S>(s.bodies.grassDrag) * particleConsts_.dt;
  dragSoftness_ = makeSoftness(toS<S>(exact(settings::kDragHertz)), toS<S>(exact(settings::kDragDampingRatio)),
                               particleConsts_.dt, toS<S>(exact(settings::kPi)));
  dragMaxOffset_ = toS<S>(exact(settings::kDragMaxOffset));
  dragMaxDv_ = toS<S>(exact(settings::kDragMaxSpeedChange));
  sleepLinear_ = toS<S>(exact(settings::kSleepLinearSpeed));
  sleepAngular_ = toS<S>(exact(settings::kSleepAngularSpeed));
  ticksToSleep_ = std::max<int32_t>(1, int32_t(*div(exact(settings::kSleepTime), s.timeStep)->roundToInt64()));
  bodyParticle_.boxNormal = s.bodies.boxParticleNormal;
  bodyParticle_.broadphase = s.bodies.particleBroadphase;
  bodyParticle_.holdTips = model_ == GrassModel::Blade || s.bodies.tipContact == TipContact::Hold;
  bodyParticle_.rodLength = particleConsts_.rodLength;
  bodyParticle_.particleInvMass = toS<S>(c.invMass);
  S largest(0);
  for (const RigidBody<S>& b : bodies_) largest = maxS(largest, b.boundingRadius);
  bodyParticle_.margin = particleConsts_.rodLength + lattice_.jitterAmplitude + largest;
  bodyParticle_.pushAllowance = largest;
  bodyParticle_.anchorOriginX = lattice_.originX;
  bodyParticle_.anchorOriginZ = lattice_.originZ;
  bodyParticle_.invParticleSpacing = toS<S>(c.invParticleSpacing);

  // Patches and particles of the window: static attributes from the lattice hash, roots on the
  // terrain, particles at rest length straight up with the scenario's initial velocity.
  const size_t nPatches = size_t(patchWindow_.size());
  for (auto* v :
       {&patches_.rootX, &patches_.rootY, &patches_.rootZ, &patches_.tipOffsetX, &patches_.tipOffsetZ, &patches_.topY})
    v->assign(nPatches, S(0));
  patches_.rotation.assign(nPatches, 0);
  patches_.variant.assign(nPatches, 0);
  patches_.cut.assign(nPatches, 0);
  patches_.tiltLevel.assign(nPatches, 0);
  particles_.resize(size_t(grid_.size()), model_ == GrassModel::Blade && !c.trampleDecayPerTick.isZero());
  int64_t startI = 0, startJ = 0;
  edgeRing_.configure(lattice_, s.lod.edgeSpacing, lodWindow_ ? s.lod.edgeRows : 0);
  initialVelocity_ = Vec3<S>(toS<S>(s.particles.initialVelocity[0]), toS<S>(s.particles.initialVelocity[1]),
                             toS<S>(s.particles.initialVelocity[2]));
  if (lodWindow_) {
    // The window starts centred on lod.center (default: the field centre).
    const Rational cx = s.lod.centerGiven ? s.lod.centerX : f.centerX,
                   cz = s.lod.centerGiven ? s.lod.centerZ : f.centerZ;
    startI = clampWindowOrigin(nearestParticleColumn(toS<S>(cx), lattice_.originX) - (grid_.countX - 1) / 2, true);
    startJ = clampWindowOrigin(nearestParticleColumn(toS<S>(cz), lattice_.originZ) - (grid_.countZ - 1) / 2, false);
  }
  fillWindow(startI, startJ, true);
  dispX_.assign(size_t(grid_.size()), S(0));
  dispY_.assign(size_t(grid_.size()), S(0));
  dispZ_.assign(size_t(grid_.size()), S(0));
  // kStateHashGroupElements (4096, as settings::kTargetChunkElements) particles' worth of whole rows:
  // a chunk is the state hash's row group, whose digests the particle pass takes when it has moved
  // the chunk (state_hash.h).
  rowsPerChunk_ = stateHashRowsPerGroup(grid_.countX);
  setThreads(pool_->threads());
  takeFixedFaults();
  updatePatchState();
}

template <class S>
void World<S>::setThreads(int threads) {
  if (threads < 1) threads = 1;
  if (threads != pool_->threads()) pool_ = std::make_unique<ChunkPool>(threads);
  rowScratch_.assign(size_t(threads) * size_t(3 * (grid_.countX + patchWindow_.sizeI)), S(0));
}

template <class S>
WorldCounts World<S>::counts() const {
  WorldCounts n{
      lattice_.patchesX,       lattice_.patchesZ,        grid_.countX, grid_.countZ, grid_.k, pool_->threads(),
      int64_t(bodies_.size()), int64_t(contacts_.size())};
  n.lodWindow = lodWindow_;
  n.windowPatchesX = patchWindow_.sizeI;
  n.windowPatchesZ = patchWindow_.sizeJ;
  n.windowOriginI = patchWindow_.originI;
  n.windowOriginJ = patchWindow_.originJ;
  return n;
}

template <class S>
void World<S>::observe(Observation& out) const {
  syncFromDevice();
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
