// The GPU physics path (docs/gpu-physics.md): the grass stages as OpenGL 4.3 compute shaders,
// bit-identical to the CPU's fixed point. Its own library (simgrass_gpu), built when GL is
// present; the core library never sees GL, only sim/particles/particle_device.h.
#pragma once

#include <memory>
#include <string>

#include "sim/particles/particle_device.h"

namespace sg::gpu {

/// A provider of compute-shader devices on its own headless OpenGL 4.5 core context (OSMesa:
/// llvmpipe, a CPU rasteriser with compute shaders, 64-bit integers and doubles; on a machine
/// with a GPU, the same code runs on it through that vendor's driver once given its context).
/// Returns nullptr with *error set when no such context can be made. The context is made current
/// on the calling thread for every device call: use a world's device from one thread at a time.
std::unique_ptr<ParticleDeviceProvider> makeOsmesaPhysicsProvider(std::string* error);

}  // namespace sg::gpu
