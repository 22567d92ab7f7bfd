// The fused particle pass (integrate, rod constraint, tip displacement: particle_row.h) run on a
// device other than the CPU, e.g. OpenGL compute shaders (sim/gpu/, docs/gpu-physics.md). This
// header is the whole contract the core sees: no GL, no files, no clocks. A device computes
// exactly the CPU reference's bits (fx32 and fx16) and reports a fault at the same particle and
// stage; it holds the particle state between ticks, and the world copies it back only where the
// host needs it (a hash, a save, an export, the renderer's patches).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sim/collision/body_particles.h"
#include "sim/lod/lattice_window.h"
#include "sim/math/scalar.h"
#include "sim/particles/particle_kernel.h"
#include "sim/particles/particle_row.h"
#include "sim/particles/particles.h"
#include "sim/patches/patch_state.h"
#include "sim/scenario/scenario.h"

namespace sg {

/// One tick's wind as a device reads it: each storage row's runs of columns under one increment
/// (a + F/m) dt, in column order (the whole row as one run where the wind is row-uniform).
template <class S>
struct DeviceWind {
  std::vector<int32_t> rowFirstRun;  ///< countZ + 1 entries: row r's runs are [rowFirstRun[r], rowFirstRun[r + 1])
  std::vector<int32_t> runBegin;     ///< per run: the storage column it starts at (it ends where the next begins)
  std::vector<S> dvx, dvy, dvz;      ///< per run (m/s)
};

/// This tick's body pushes as a device applies them in the response stage, as the CPU does
/// (sim/collision/body_particles.h: per particle the same parts in the same order, the same
/// escape chain, the same bits). The device reads the pushers' poses, shapes, shares,
/// column ranges and row buckets, all computed on the host (prepareGrassPushers).
template <class S>
struct DevicePush {
  const GrassPushers<S>* pushers = nullptr;
  const BodyParticleSettings<S>* settings = nullptr;
  const LatticeWindow* window = nullptr;  ///< the particle window (storage row -> lattice row)
  size_t bodyCount = 0;
  /// Where given (grass drag), each body's pushed particles this tick, summed over the field
  /// (pushedPerBody's totals); bodyCount entries.
  std::vector<int64_t>* pushedPerBody = nullptr;
};

/// What the device's patch stage (patch_state.h) reads besides the particles' tip displacement:
/// the two windows (patch slot -> particle slots), the constants, and each patch slot's root
/// height and cut flag, which change only when the window moves, a tuft is mown or the state is
/// restored (`revision` then changes, and the device copies them again).
template <class S>
struct DevicePatchInputs {
  LatticeWindow particles, patches;  ///< the particle window and the patch window (k times finer)
  const PatchStateConstants<S>* constants = nullptr;
  const std::vector<S>* rootY = nullptr;      ///< per patch slot (m)
  const std::vector<uint8_t>* cut = nullptr;  ///< per patch slot: 1 where mown
  uint64_t revision = 0;                      ///< changes whenever rootY or cut change
};

/// One device's copy of a world's particles (countX x countZ, storage order).
template <class S>
class ParticleDevice {
 public:
  virtual ~ParticleDevice() = default;
  /// Copies the host's particle state (trample levels included) and anchors to the device (the
  /// host is the truth).
  virtual void upload(const ParticleArrays<S>& p) = 0;
  /// The bodies' push on the current state. Returns true when it ran: then the state is pushed,
  /// and push.pushedPerBody (where given) holds each body's count. False when a push faulted, or
  /// may have (a false alarm is allowed, never a missed fault), or the device cannot push this
  /// many particles: then the state is as it was before, and the host pushes (and reports the
  /// reference's fault).
  virtual bool push(const DevicePush<S>& push) = 0;
  /// One fused pass over every particle under `wind`. Returns the fault the CPU reference reports
  /// (the first faulting row's; within a row, run by run in column order, a run's first
  /// integration fault before any projection fault), with the fixed-point fault bits in
  /// *faultBits. A pass that faults keeps the device's state as it was before the pass (the world
  /// then redoes the tick's pass on the CPU, which stops at the fault).
  virtual RowFault advance(const DeviceWind<S>& wind, const ParticleConstants<S>& c, uint32_t* faultBits) = 0;
  /// Particles [first, first + count) of each span in storage order, everything of them (state,
  /// anchors, trample levels), host to device: the cells a level-of-detail window move wrote.
  struct Span {
    int64_t first = 0, count = 0;
  };
  virtual void uploadCells(const ParticleArrays<S>& p, const std::vector<Span>& spans) = 0;
  /// Copies the device's particle state to the host, and the tip displacement of the last pass
  /// where dx, dy, dz are given.
  virtual void download(ParticleArrays<S>& p, std::vector<S>* dx, std::vector<S>* dy, std::vector<S>* dz) = 0;
  /// The patch stage on the device, from the last pass's tip displacement: every patch slot's tip
  /// offset, top and tilt level with the CPU's bits (PatchWriter::writeFast after updatePatchRow),
  /// and a copy for drawing (patchDrawBuffer). False when the device cannot hold this window's
  /// patches (its storage blocks are too small): the host then derives and draws its own.
  virtual bool derivePatches(const DevicePatchInputs<S>& inputs) = 0;
  /// Copies the last derivePatches' tip offsets, tops and tilt levels into `patches` (checks).
  virtual void downloadPatches(PatchArrays<S>& patches) = 0;
  /// A renderer sharing the device's context draws from this buffer (an OpenGL buffer name; 0
  /// when the device has none): per patch slot four floats, top y, tip offset x, tip offset z (m,
  /// each the double of its exact value rounded to float, as the host's scene extraction does)
  /// and the brightness level (the tilt level, 3 where mown) plus 4 x the trample level of the
  /// patch's lower-left particle as the scene shows it (0..255, lround(255 level); 0 without
  /// trampling).
  /// Each derivePatches writes the other of two buffers, so the buffer the one before returned
  /// still holds its state (a renderer interpolating between two ticks reads both).
  virtual uint32_t patchDrawBuffer() const = 0;
  /// Host <-> device copies so far.
  virtual DeviceTraffic traffic() const = 0;
};

/// Makes devices (one per world); implemented where a device API exists (sim/gpu/).
class ParticleDeviceProvider {
 public:
  virtual ~ParticleDeviceProvider() = default;
  /// A device for countX x countZ particles of grass model `model` (`tramples`: the blade model
  /// keeps trample levels), or nullptr with *error set.
  virtual std::unique_ptr<ParticleDevice<Fx32>> makeFx32(int64_t countX, int64_t countZ, GrassModel model,
                                                         bool tramples, std::string* error) = 0;
  virtual std::unique_ptr<ParticleDevice<Fx16>> makeFx16(int64_t countX, int64_t countZ, GrassModel model,
                                                         bool tramples, std::string* error) = 0;
  /// float, as a comparison variant: the device's float operations, with no promise of the CPU's
  /// bits (GLSL leaves division and square roots a little latitude).
  virtual std::unique_ptr<ParticleDevice<float>> makeFloat(int64_t countX, int64_t countZ, GrassModel model,
                                                           bool tramples, std::string* error) = 0;
  /// The device in words ("OpenGL 4.5 compute on llvmpipe (LLVM 15.0.6, 256 bits)").
  virtual std::string describe() const = 0;
};

}  // namespace sg
