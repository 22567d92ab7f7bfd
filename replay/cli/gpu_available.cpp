#include "replay/cli/gpu_hook.h"
#include "replay/physics_devices.h"
#include "sim/gpu/gl_physics.h"

namespace sg {
void registerBuildGpuPhysics() { registerGpuPhysics(&gpu::makeOsmesaPhysicsProvider); }
}  // namespace sg
