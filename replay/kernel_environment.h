// SIMGRASS_KERNEL: the environment's say in which particle kernel new worlds use. Read by the
// tools at start-up (the core reads no environment: sim/particles/particle_kernel.h).
#pragma once

namespace sg {

/// SIMGRASS_KERNEL=scalar makes every world built afterwards run the scalar reference kernels;
/// unset, empty, "auto" or "avx2" keep the default (AVX2 where the CPU has it). Returns false and
/// leaves the default alone for any other value (the caller reports it).
bool applyKernelEnvironment();

}  // namespace sg
