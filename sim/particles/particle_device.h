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

#include "sim/math/scalar.h"
#include "sim/particles/particle_kernel.h"
#include "sim/particles/particle_row.h"
#include "sim/particles/particles.h"

namespace sg {

/// One device's copy of a world's particles (countX x countZ, storage order).
template <class S>
class ParticleDevice {
 public:
  virtual ~ParticleDevice() = default;
  /// Copies the host's particle state and anchors to the device (the host is the truth).
  virtual void upload(const ParticleArrays<S>& p) = 0;
  /// One fused pass over every particle; storage row r moves under (dvx[r], dvy[r], dvz[r]),
  /// its (a + F/m) dt. Returns the fault the CPU reference reports (the first faulting row's;
  /// within it the integration's first faulting particle before any projection fault), with
  /// the fixed-point fault bits in *faultBits. A pass that faults keeps the device's state as it
  /// was before the pass (the world then redoes the tick on the CPU, which stops at the fault).
  virtual RowFault advance(const std::vector<S>& dvx, const std::vector<S>& dvy, const std::vector<S>& dvz,
                           const ParticleConstants<S>& c, uint32_t* faultBits) = 0;
  /// Copies the device's particle state to the host, and the tip displacement of the last pass
  /// where dx, dy, dz are given.
  virtual void download(ParticleArrays<S>& p, std::vector<S>* dx, std::vector<S>* dy, std::vector<S>* dz) = 0;
};

/// Makes devices (one per world); implemented where a device API exists (sim/gpu/).
class ParticleDeviceProvider {
 public:
  virtual ~ParticleDeviceProvider() = default;
  /// A device for countX x countZ particles of the rod model (`pbd`: the pbd constraint mode),
  /// or nullptr with *error set.
  virtual std::unique_ptr<ParticleDevice<Fx32>> makeFx32(int64_t countX, int64_t countZ, bool pbd,
                                                         std::string* error) = 0;
  virtual std::unique_ptr<ParticleDevice<Fx16>> makeFx16(int64_t countX, int64_t countZ, bool pbd,
                                                         std::string* error) = 0;
  /// The device in words ("OpenGL 4.5 compute on llvmpipe (LLVM 15.0.6, 256 bits)").
  virtual std::string describe() const = 0;
};

}  // namespace sg
