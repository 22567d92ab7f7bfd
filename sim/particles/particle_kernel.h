// Which implementation runs the hot loops of the step. Part of the public API (a tool may pin the
// reference); the kernels themselves live in particle_row.h and patches/patch_row_avx2.cpp.
#pragma once

#include <cstdint>

namespace sg {

/// Which implementation of the hot loops a world runs: the fused particle pass
/// (particles/particle_row.h, blade.h) and the patch stage's loops (patches/patch_row_avx2.cpp).
/// Both give bit-identical state and the same fault reports. Avx2, on CPUs that have it, covers
/// the thesis and pbd particle pass in every scalar, and the blade row and the patch stage in the
/// fixed-point scalars (float and double run their scalar references there).
enum class ParticleKernel : uint8_t { Scalar = 0, Avx2 = 1 };

/// "scalar" or "avx2".
const char* particleKernelName(ParticleKernel kernel);
/// Whether this CPU runs the AVX2 kernel.
bool avx2KernelAvailable();
/// The kernel a new world uses: AVX2 where the CPU has it, unless setDefaultParticleKernel chose
/// the reference. The core reads no environment: tools map SIMGRASS_KERNEL onto this
/// (replay/kernel_environment.h).
ParticleKernel defaultParticleKernel();
/// Sets what defaultParticleKernel() returns for worlds built afterwards (a process-wide choice,
/// read only when a world is built, never inside the step). Avx2 where the CPU lacks it means
/// Scalar.
void setDefaultParticleKernel(ParticleKernel kernel);

/// Where the grass stages run (`--physics`; docs/gpu-physics.md). Every path gives the CPU's bits.
enum class PhysicsPath : uint8_t {
  Cpu = 0,          ///< the CPU kernels above
  Gpu = 1,          ///< a device holds the particles; copied back only when hashed, saved or read
  GpuReadback = 2,  ///< the thesis' design: the device steps, the state is copied back every tick
};
/// "cpu", "gpu" or "gpu-readback".
const char* physicsPathName(PhysicsPath path);

/// Bytes copied between the host and a world's device since the device was made: the cost the
/// GPU path's design keeps low (docs/gpu-physics.md) and `--hash-every` makes visible.
struct DeviceTraffic {
  int64_t toDevice = 0, toHost = 0;
};

}  // namespace sg
