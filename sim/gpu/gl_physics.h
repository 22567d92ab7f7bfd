// The GPU physics path (docs/gpu-physics.md): the grass stages as OpenGL 4.3 compute shaders,
// bit-identical to the CPU's fixed point. Its own library (simgrass_gpu), built when GL is
// present; the core library never sees GL, only sim/particles/particle_device.h.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "sim/particles/particle_device.h"

namespace sg::gpu {

/// How a provider reaches its OpenGL context: made current before every device call (none: the
/// context current on the calling thread is used as it is), destroyed with the provider.
struct GlContextHooks {
  std::function<void()> makeCurrent, destroy;
};

/// A provider of compute-shader devices in the context `hooks` reach (current when this is
/// called; GL loaded through GLEW), or nullptr with *error set when the context lacks compute
/// shaders, 64-bit integers, doubles or direct state access. `whose` ends its description.
std::unique_ptr<ParticleDeviceProvider> makeGlPhysicsProvider(GlContextHooks hooks, const std::string& whose,
                                                              std::string* error);

/// A provider of compute-shader devices on its own headless OpenGL 4.5 core context (OSMesa:
/// llvmpipe, a CPU rasteriser with compute shaders, 64-bit integers and doubles; on a machine
/// with a GPU, the same code runs on it through that vendor's driver once given its context).
/// Returns nullptr with *error set when no such context can be made. The context is made current
/// on the calling thread for every device call: use a world's device from one thread at a time.
/// (osmesa_physics.cpp, library simgrass_gpu_osmesa.)
std::unique_ptr<ParticleDeviceProvider> makeOsmesaPhysicsProvider(std::string* error);

/// A provider of the same devices in the OpenGL context current on the calling thread (GL
/// loaded through GLEW; 4.3 or later with 64-bit integers and doubles): a renderer's context,
/// which can then draw from the devices' buffers (ParticleDevice::patchDrawBuffer) without
/// copying them back. Use its devices only while that context is current.
std::unique_ptr<ParticleDeviceProvider> makeCurrentContextPhysicsProvider(std::string* error);

}  // namespace sg::gpu
