// The world as tools and users see it: a scalar-erased interface over World<S> (world.h), with
// what a step returns and how a bad saved state is reported. Part of the public API: it includes
// no Eigen and no World<S>, so a user's build needs neither.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/particles/particle_kernel.h"
#include "sim/scenario/scenario.h"
#include "sim/world/stage.h"
#include "sim/world/tick_input.h"

namespace sg {

class ParticleDeviceProvider;  // sim/particles/particle_device.h

/// A simulation fault: arithmetic that did not fit the scalar, reported with where it happened.
struct SimError {
  int64_t tick = -1;
  Stage stage = Stage::Count;
  int64_t particle = -1;               ///< particle index, -1 if not particle-specific
  int32_t body = -1;                   ///< body index, -1 if not body-specific, kSomeBody if unknown
  int64_t latticeI = 0, latticeJ = 0;  ///< patch coordinates of that particle
  std::string what;                    ///< "fixed-point overflow", "non-finite value", ...
  std::string message() const;
};

struct StepResult {
  bool ok = true;
  SimError error;
};

/// A malformed or mismatched saved state; names the byte offset and what was expected.
class StateError : public std::runtime_error {
 public:
  StateError(uint64_t offset, const std::string& expected);
  uint64_t offset() const { return offset_; }

 private:
  uint64_t offset_;
};

struct WorldCounts {
  int64_t patchesX = 0, patchesZ = 0;      ///< the field
  int64_t particlesX = 0, particlesZ = 0;  ///< simulated (the window's, with the level of detail on)
  int interpolation = 1;
  int threads = 1;
  int64_t bodies = 0;
  int64_t contacts = 0;                            ///< body contacts found in the last tick
  bool lodWindow = false;                          ///< the level-of-detail window is on
  int64_t windowPatchesX = 0, windowPatchesZ = 0;  ///< simulated patches (the field when off)
  int64_t windowOriginI = 0, windowOriginJ = 0;    ///< lattice patch of the window's first corner
  int64_t patches() const { return patchesX * patchesZ; }
  int64_t simulatedPatches() const { return windowPatchesX * windowPatchesZ; }
  int64_t particles() const { return particlesX * particlesZ; }
};

/// What diff and compare measure, converted to double: every tuft's tip and every body's pose.
struct Observation {
  int64_t tick = 0;
  int64_t patchesX = 0, patchesZ = 0;
  std::vector<double> tipX, tipY, tipZ;  ///< per patch (row-major, i fastest): top-vertex centre, m
  std::vector<double> bodyPosition;      ///< 3 per body, m
  std::vector<double> bodyOrientation;   ///< 4 per body (w, x, y, z)
  int64_t contacts = 0;                  ///< body contacts found in the last tick
};

/// The whole state as plain numbers (converted to double: exact for fx32 values below 2^21 m,
/// for fx16, float and double always), for analysis tools that do not link the library
/// (`simgrass replay --to T --export-state s.json`, docs/state-format.md). Not a way back in:
/// restoreState() takes the binary state.
struct StateExport {
  ScalarKind scalar = ScalarKind::Fx32;
  int64_t tick = 0;
  int interpolation = 1;
  int64_t fieldPatchesX = 0, fieldPatchesZ = 0;
  /// Simulated particles: lattice columns particleOriginI .. + particlesX - 1 (particle lattice:
  /// particle (I, J) sits on patch (k I, k J)), rows likewise; row-major, I fastest.
  int64_t particleOriginI = 0, particleOriginJ = 0, particlesX = 0, particlesZ = 0;
  std::vector<double> particlePosition;  ///< x, y, z per particle, m
  std::vector<double> particleVelocity;  ///< x, y, z per particle, m/s
  /// Simulated patches (the level-of-detail window, or the field): row-major, i fastest.
  int64_t patchOriginI = 0, patchOriginJ = 0, patchesX = 0, patchesZ = 0;
  std::vector<double> tipOffset;  ///< x, y, z per patch: top-vertex centre minus root, m
  struct Body {
    std::array<double, 3> position{}, velocity{}, angularVelocity{};  ///< m, m/s, rad/s (world)
    std::array<double, 4> orientation{};                              ///< w, x, y, z
    int32_t templateBody = -1;  ///< the scenario body it is (or copies, when spawned)
    bool asleep = false;
    bool bladeOn = false;  ///< a mower whose blade is on
  };
  std::vector<Body> bodies;
  std::vector<std::array<int64_t, 2>> cuts;  ///< mown patches (i, j), in increasing order
};

/// Scalar-erased interface used by tools (command line, replay, viewer).
class SimWorld {
 public:
  virtual ~SimWorld() = default;
  virtual ScalarKind scalar() const = 0;
  virtual int64_t tick() const = 0;
  virtual WorldCounts counts() const = 0;
  /// Advances one tick. After a fault the world stays failed and every later call fails too.
  virtual StepResult step(const TickInput& input, StageObserver* observer = nullptr) = 0;
  /// The state hash (sim/state/state_hash.h): XXH3-64 of the canonical serialisation (the bytes
  /// of saveState()) with each particle array's row groups replaced by their digests. Takes the
  /// digests on the world's threads when the last step did not: call it from one thread at a time,
  /// never from inside one of the world's own pool jobs.
  virtual uint64_t stateHash() const = 0;
  /// Asks the next step to take the particle row groups' digests as it moves them (on its threads, with
  /// the rows in cache), so that stateHash() after it hashes only the small sections. A recorder
  /// or a replay calls it before each tick it checks. Changes no state and no hash. On the device
  /// path the step takes none (stateHash() takes them after copying the particles back).
  virtual void requestStateHash() = 0;
  virtual std::vector<uint8_t> saveState() const = 0;
  /// Throws StateError when the bytes are not a state of this world's scenario and scalar.
  virtual void restoreState(std::span<const uint8_t> bytes) = 0;
  virtual void setThreads(int threads) = 0;
  /// Which implementation runs the hot loops (the fused particle pass and the patch stage). Every
  /// kernel gives the same state bits and fault reports; a kernel the CPU lacks falls back to the
  /// scalar reference.
  virtual void setParticleKernel(ParticleKernel kernel) = 0;
  virtual ParticleKernel particleKernel() const = 0;
  /// Moves the grass stages onto a device from `provider` (PhysicsPath::Gpu, GpuReadback) or back
  /// to the CPU (Cpu; provider unused). Returns "" on success, else one line saying why this world
  /// cannot (the world is then unchanged). Every path gives the same state bits and fault reports
  /// (docs/gpu-physics.md).
  virtual std::string setPhysicsPath(PhysicsPath path, ParticleDeviceProvider* provider) = 0;
  virtual PhysicsPath physicsPath() const = 0;
  /// Host <-> device copies of the world's current device so far (zero on the CPU path).
  virtual DeviceTraffic deviceTraffic() const = 0;
  /// The device's per-patch draw buffer (ParticleDevice::patchDrawBuffer, an OpenGL buffer name)
  /// while it holds the patch state of the current tick, else 0 (the CPU path, gpu-readback, or a
  /// state the host set since: a restore, a window move). A renderer in the device's context
  /// draws the tuft tops from it; everything else about a tuft stays on the host.
  virtual uint32_t devicePatchDrawBuffer() const = 0;
  /// The whole state as plain numbers (StateExport).
  virtual void exportState(StateExport& out) const = 0;
  /// Fills `out` (reusing its storage) with the current tips and body poses.
  virtual void observe(Observation& out) const = 0;
  /// The scenario body (index into scenario.bodies.list) whose spec body `body` copies: its own
  /// index for a scenario body, the Spawn command's template for a spawned one; -1 if no such body.
  virtual int32_t bodyTemplate(int64_t body) const = 0;
  /// Whether body `body` is a mower whose blade is on (MowerOn/MowerOff; mowers start on).
  virtual bool bladeOn(int64_t body) const = 0;
};

/// Builds a world for scenario.scalar. Throws ScenarioError when the scenario does not fit it.
std::unique_ptr<SimWorld> makeWorld(const Scenario& scenario, int threads = 1, uint64_t memoryLimitBytes = 0);

}  // namespace sg
