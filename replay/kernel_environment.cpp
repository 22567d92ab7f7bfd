#include "replay/kernel_environment.h"

#include <cstdlib>
#include <string_view>

#include "sim/particles/particle_kernel.h"

namespace sg {

bool applyKernelEnvironment() {
  const char* env = std::getenv("SIMGRASS_KERNEL");
  const std::string_view value = env ? env : "";
  if (value == "scalar") {
    setDefaultParticleKernel(ParticleKernel::Scalar);
    return true;
  }
  return value.empty() || value == "auto" || value == "avx2";
}

}  // namespace sg
