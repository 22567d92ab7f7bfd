// Registers this build's GPU physics (replay/physics_devices.h) with the `simgrass` executable.
// Exactly one definition is linked, chosen by the top-level CMakeLists.txt, like render_hook.h:
//   * replay/cli/gpu_available.cpp when SIMGRASS_BUILD_VIEWER is on (sim/gpu's compute shaders);
//   * replay/cli/gpu_unavailable.cpp when it is off (`--physics gpu` then says the build has none).
#pragma once

namespace sg {
void registerBuildGpuPhysics();
}  // namespace sg
