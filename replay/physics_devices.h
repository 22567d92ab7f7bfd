// `--physics cpu|gpu|gpu-readback` for every tool (docs/gpu-physics.md): which device runs a
// world's grass stages. The GPU devices live in sim/gpu/ (GL), which this layer never links: the
// executable that has them registers their factory (replay/cli/gpu_hook.h), and a build without
// GL says so in one line.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "sim/particles/particle_device.h"
#include "sim/world/sim_world.h"

namespace sg {

/// Makes the process's GPU device provider, or nullptr with *error set.
using GpuPhysicsFactory = std::unique_ptr<ParticleDeviceProvider> (*)(std::string* error);
/// Registers the factory. A provider already made stays the process's; until one is made, the
/// last factory registered makes it (the viewer registers its window's context once GL is up).
void registerGpuPhysics(GpuPhysicsFactory factory);
/// The process's provider, made on first use; nullptr with *error set when the build has no GPU
/// path or no context can be made.
ParticleDeviceProvider* gpuPhysicsProvider(std::string* error);

/// "cpu", "gpu", "gpu-readback" -> the path (nullopt for anything else).
std::optional<PhysicsPath> parsePhysicsPath(const std::string& text);
/// Puts `world` on `path`; "" on success, else why not (one line, naming the device or the
/// scenario feature the path lacks; the caller names the option).
std::string applyPhysicsPath(SimWorld& world, PhysicsPath path);
/// What runs the grass stages of `world`: "cpu", or "gpu (OpenGL ... on llvmpipe ...)".
std::string describePhysics(const SimWorld& world);

}  // namespace sg
