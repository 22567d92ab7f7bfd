#include "replay/cli/gpu_hook.h"

namespace sg {
void registerBuildGpuPhysics() {}  // no factory: `--physics gpu` reports that this build has none
}  // namespace sg
