// The world: owns the grass field, the particles, the terrain and the wind schedule, and
// advances them one fixed tick at a time. Written once over the scalar type S.
//
// Invariants (each one a test in tests/):
//   * same scenario + same inputs => the same stateHash() after every tick, for any thread
//     count, build type, compiler, architecture and particle kernel (float/double: with the
//     build's flags, docs/determinism.md);
//   * saveState() -> restoreState() into a fresh world -> continue == never interrupted;
//   * nothing inside step() reads a clock, a random generator or libm.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/bodies/rigid_body.h"
#include "sim/collision/body_particles.h"
#include "sim/collision/contact_solver.h"
#include "sim/field/grass_field.h"
#include "sim/field/markings.h"
#include "sim/lod/edge_ring.h"
#include "sim/particles/particle_device.h"
#include "sim/particles/particle_row.h"
#include "sim/particles/particles.h"
#include "sim/patches/patch_state.h"
#include "sim/scenario/scenario.h"
#include "sim/terrain/terrain.h"
#include "sim/wind/wind.h"
#include "sim/world/chunk_pool.h"
#include "sim/world/sim_world.h"
#include "sim/world/stage.h"
#include "sim/world/tick_input.h"

namespace sg {

template <class S>
class World final : public SimWorld {
 public:
  explicit World(const Scenario& scenario, int threads = 1);

  ScalarKind scalar() const override { return ScalarTraits<S>::kind; }
  int64_t tick() const override { return tick_; }
  WorldCounts counts() const override;
  StepResult step(const TickInput& input, StageObserver* observer = nullptr) override;
  uint64_t stateHash() const override;
  void requestStateHash() override { digestRowsInNextStep_ = true; }
  std::vector<uint8_t> saveState() const override;
  void restoreState(std::span<const uint8_t> bytes) override;
  void setThreads(int threads) override;
  void setParticleKernel(ParticleKernel kernel) override {
    const bool vector = kernel == ParticleKernel::Avx2 && avx2KernelAvailable();
    particleKernel_ = vector ? ParticleKernel::Avx2 : ParticleKernel::Scalar;
  }
  ParticleKernel particleKernel() const override { return particleKernel_; }
  std::string setPhysicsPath(PhysicsPath path, ParticleDeviceProvider* provider) override;
  PhysicsPath physicsPath() const override { return physicsPath_; }
  DeviceTraffic deviceTraffic() const override { return device_ ? device_->traffic() : DeviceTraffic{}; }
  uint32_t devicePatchDrawBuffer() const override { return deriveDevicePatches() ? device_->patchDrawBuffer() : 0; }
  /// The device's patch state of the current tick (derivePatches) into `out` (tests: it must
  /// equal patches()); false when no device holds it (devicePatchDrawBuffer() == 0).
  bool downloadDevicePatches(PatchArrays<S>* out) const;
  /// The patches as the host holds them, without copying a device's state back: their roots,
  /// rotations, variants and cut flags are always current, the tip offsets, tops and tilt levels
  /// only while devicePatchDrawBuffer() is 0 (a renderer drawing the tops from the device).
  const PatchArrays<S>& hostPatches() const { return patches_; }
  /// The particles as the host holds them, without copying a device's state back: the anchors
  /// are always current, the rest only while no device is ahead of the host.
  const ParticleArrays<S>& hostParticles() const { return particles_; }
  void exportState(StateExport& out) const override;
  void observe(Observation& out) const override;
  int32_t bodyTemplate(int64_t body) const override;
  bool bladeOn(int64_t body) const override;

  // Read access for tests, tools and the renderer (each copies a device's particles back first).
  const ParticleArrays<S>& particles() const {
    syncFromDevice();
    return particles_;
  }
  /// Tests and tools: set up states. The reference is good until the next step (the device copy
  /// and the state hash's digests are told of a change here, not of later writes through it).
  ParticleArrays<S>& mutableParticles() {
    syncFromDevice();
    hostAhead_ = true;
    deviceDisplacementCurrent_ = false;
    rowDigestsCurrent_ = false;
    return particles_;
  }
  const PatchArrays<S>& patches() const {
    syncFromDevice();
    return patches_;
  }
  /// Which patches patches() holds; storageIndex(i, j) finds patch (i, j) (row-major j * patchesX
  /// + i with the level of detail off).
  const LatticeWindow& patchWindow() const { return patchWindow_; }
  /// Level-of-detail level 1 (empty with the level of detail off).
  const EdgeRing<S>& edgeRing() const { return edgeRing_; }
  const ParticleGrid& particleGrid() const { return grid_; }
  const GrassLattice<S>& lattice() const { return lattice_; }
  const Terrain<S>& terrain() const { return terrain_; }
  const WindSchedule& wind() const { return windSchedule_; }
  const RowAccelerationDt<S>& rowAcceleration() const { return rowAccel_; }
  const std::vector<RigidBody<S>>& bodies() const { return bodies_; }
  std::vector<RigidBody<S>>& mutableBodies() { return bodies_; }         ///< tests: set up states
  const std::vector<Contact<S>>& contacts() const { return contacts_; }  ///< last tick's
  const std::map<std::pair<int64_t, int64_t>, uint8_t>& cuts() const { return cuts_; }
  const ParticleConstants<S>& particleConstants() const { return particleConsts_; }
  /// Recomputes the derived patch state from the particles (done by step and restore).
  void updatePatchState();               ///< tip displacement from the particles, then the patches
  void updatePatchesFromDisplacement();  ///< the patches from dispX_/dispY_/dispZ_

 private:
  // The stages of step() (world_step.cpp), in order; each returns false after recording a fault.
  bool windowStage(const TickInput& input);
  bool inputStage(const TickInput& input);
  bool windStage();
  bool collisionStage();
  bool integrateStage();
  bool patchStage();
  /// The integrate stage's particle pass on the device (physics path Gpu or GpuReadback); false
  /// when it faulted, with the tick's input back on the host for the CPU reference to redo.
  bool deviceParticlePass();
  /// The response stage's grass push on the device; false when it did not run there (a push
  /// faulted, or may have), with the state before it back on the host for the CPU to push.
  /// *pushedPerBody: each body's pushed tufts, where the grass drags the bodies.
  bool devicePush(const GrassPushers<S>& pushers, std::vector<int64_t>* pushedPerBody);
  /// After a pass or push that faulted on the device: the device's state (the input it kept) to
  /// the host, which is the truth again until the next upload. Always false.
  bool handDeviceTickBack();
  /// Why this world's grass stages cannot run on a device ("" when they can).
  std::string deviceLimitation() const;
  /// Copies the device's particles back when they are newer than the host's, and derives the
  /// patches from them (the patch stage the device path left to this point). Const: it changes
  /// no state, only where the state is held.
  void syncFromDevice() const;
  /// The grass pushed out of every body on the host (particle rows in parallel, bodies in id
  /// order), then the grass drag on the bodies; false after recording a fault (Stage::Response).
  bool pushGrassOnHost(const GrassPushers<S>& pushers);
  /// The grass drag: each body slowed by the tufts it pushed this tick (per body, summed over the
  /// field); false after recording a fault (Stage::Response).
  bool applyGrassDrag(const std::vector<int64_t>& pushedPerBody);
  /// Records a fixed-point fault of `stage` as the world's failure; returns false.
  bool failWith(Stage stage, uint32_t faults);
  template <class Fn>
  bool runParticleRows(Stage stage, Fn&& rowKernel);
  void applyCommands(const TickInput& input);
  void resetBody(size_t body);
  /// BodyCommandKind::DragTo: the mouse-drag spring pulls the centre of mass toward `target` (m).
  void applyDrag(RigidBody<S>& b, const Vec3<S>& target);
  void wakeBodiesNear(const Vec3<S>& centre,
                      S radius);  ///< every sleeping body whose bounds come within 5 cm (per axis)
  /// Wakes `body` and every sleeping body near it, transitively (sim/bodies/sleep_islands.h).
  void wakeIsland(int32_t body);
  void spawnBody(int32_t templateBody, const InputVec3& at);
  void dropCachedImpulses(size_t body);
  void detectContacts();
  void failWithTooManyContacts(int32_t body);  ///< body -1: not one pair's (the terrain pass)
  bool respondToContacts();
  /// The contact rows (prepareContacts), in ranges of whole body pairs on the pool.
  void prepareContactRows();
  /// The sub-steps of every awake island (solveIsland), on the pool when there are several.
  void solveIslands();
  bool bodiesFaulted(Stage stage);
  void mowGrass();
  /// The canonical serialisation; with `groupDigests` (particleGroupDigests' layout) each
  /// particle array's payload is its row groups' digests instead: what stateHash() hashes
  /// (state_hash.h).
  void serialise(class StateSink& sink, const uint64_t* groupDigests = nullptr) const;
  /// Row groups (stateHashRowsPerGroup) of the particle arrays.
  int64_t particleGroups() const;
  /// The digests of every particle array's row groups: array-major (px, py, pz, vx, vy, vz, then
  /// trample when the grass tramples), each array's groups in storage order. On the pool.
  std::vector<uint64_t> particleGroupDigests() const;
  /// One group's digests into `out` (particleGroupDigests' layout).
  void digestParticleGroup(int64_t group, uint64_t* out) const;
  // Level-of-detail window.
  int64_t nearestParticleColumn(S coordinate, S fieldOrigin) const;
  int64_t clampWindowOrigin(int64_t origin, bool alongX) const;
  void initParticle(int64_t I, int64_t J, bool initialVelocity);
  void initPatch(int64_t i, int64_t j);
  void fillWindow(int64_t originI, int64_t originJ, bool initialVelocity);
  void moveWindowTo(int64_t originI, int64_t originJ, bool initialVelocity, bool everything);
  void followCamera(const InputVec3& camera);

  uint64_t configHash_ = 0;
  GrassModel model_ = GrassModel::Thesis;
  /// The fused particle pass's implementation (float and double: always the reference).
  ParticleKernel particleKernel_ = defaultParticleKernel();
  GrassLattice<S> lattice_;
  PatchArrays<S> patches_;
  LatticeWindow patchWindow_;  ///< which patches patches_ holds (toroidal, like the particles)
  bool lodWindow_ = false;     ///< the level-of-detail window is on (else the window is the field)
  Vec3<S> initialVelocity_ = Vec3<S>::Zero();
  EdgeRing<S> edgeRing_;  ///< level 1 around the window (rows = 0 with the level of detail off)
  ParticleGrid grid_;
  ParticleArrays<S> particles_;
  ParticleConstants<S> particleConsts_;
  PatchStateConstants<S> patchConsts_;
  Terrain<S> terrain_;
  WindSchedule windSchedule_;
  WindConstants<S> windConsts_;
  RowAccelerationDt<S> rowAccel_;
  std::vector<RigidBody<S>> bodies_;
  /// Scenario bodies as built (Reset's start poses, Spawn's templates).
  std::vector<RigidBody<S>> initialBodies_;
  /// Spawned bodies (state): the template and the spawn position (Q32.32, Reset's start) of
  /// each, in spawn order; body scenarioBodies + n is spawns_[n].
  struct Spawned {
    int32_t templateBody = 0;
    InputVec3 position;
  };
  std::vector<Spawned> spawns_;
  /// Mown patches by lattice coordinates (i, j): persistent, ordered, saved and hashed.
  std::map<std::pair<int64_t, int64_t>, uint8_t> cuts_;
  S mowerCutHeight_{};
  FieldMarkings<S> markings_;
  std::vector<Contact<S>> contacts_;
  std::vector<CachedImpulse<S>> impulseCache_;  ///< warm-start impulses (state)
  SolverSettings<S> solver_;
  std::vector<ContactRow<S>> contactRows_;  ///< scratch of the response stage (not state)
  BodyParticleSettings<S> bodyParticle_;
  BodyBroadphase bodyBroadphase_ = BodyBroadphase::Brute;
  Vec3<S> gravityDt_ = Vec3<S>::Zero();       ///< g dt (m/s): a body's speed gain in one tick
  Vec3<S> gravitySubstep_ = Vec3<S>::Zero();  ///< g h (m/s) for one sub-step
  S substepDt_{};                             ///< h = dt / substeps (s)
  S maxAngularSpeed_{};                       ///< rad/s: a quarter turn per sub-step
  S speculativeDistance_{};                   ///< m (settings::kSpeculativeDistance)
  S sleepLinear_{}, sleepAngular_{};
  S grassDragDt_{};                  ///< grassDrag * dt (N s/m * s = kg per tuft)
  Softness<S> dragSoftness_{};       ///< the DragTo spring over one tick
  S dragMaxOffset_{}, dragMaxDv_{};  ///< m and m/s per axis (settings::kDragMaxOffset, kDragMaxSpeedChange)
  int32_t ticksToSleep_ = 30;
  std::vector<S> dispX_, dispY_, dispZ_;  ///< per-particle tip displacement (patch-state scratch)
  std::vector<S> rowScratch_;             ///< per-worker interpolation row
  int64_t rowsPerChunk_ = 1;
  // The state hash's row-group digests (state_hash.h): requested for the next step, taken by its
  // particle pass, and current until the particles change again (a step, a restore,
  // mutableParticles).
  bool digestRowsInNextStep_ = false;
  bool digestRowsThisStep_ = false;
  bool rowDigestsCurrent_ = false;
  std::vector<uint64_t> rowDigests_;
  bool exactRowWeights_ = false;  ///< k = 2 or 4 with exact weights: the patch stage uses constant weights
  int64_t tick_ = 0;
  bool failed_ = false;
  SimError failure_;
  std::unique_ptr<ChunkPool> pool_;
  // The device path (docs/gpu-physics.md). The particles live in one place at a time: the host
  // arrays above, or the device after a pass (deviceAhead_); hostAhead_ says the host arrays
  // changed since the last upload (a restore, a test's edits).
  PhysicsPath physicsPath_ = PhysicsPath::Cpu;
  std::unique_ptr<ParticleDevice<S>> device_;
  DeviceWind<S> deviceWind_;  ///< the tick's wind as the device reads it (scratch, not state)
  bool deviceAhead_ = false;
  bool hostAhead_ = false;
  /// The device's tip displacements are the current state's (a pass on the `gpu` path since the
  /// host last set the state or moved the window), and its patch stage ran on them. The patch
  /// stage runs on the device only when a renderer asks for its buffer (deriveDevicePatches):
  /// once per drawn frame, never in a headless run.
  bool deviceDisplacementCurrent_ = false;
  mutable bool devicePatchesCurrent_ = false;
  /// Runs the device's patch stage if it has not run on the current state; false when the device
  /// holds no current displacement to derive it from.
  bool deriveDevicePatches() const;
  /// Changes whenever a patch's root height or cut flag does (window moves, mowing, restores):
  /// the device copies them again (DevicePatchInputs::revision).
  uint64_t patchInputsRevision_ = 1;
};

}  // namespace sg
