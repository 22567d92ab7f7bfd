#include "replay/physics_devices.h"

namespace sg {
namespace {
GpuPhysicsFactory gFactory = nullptr;
// Made once and never destroyed: the context lives as long as the process. Destroying it from a
// static destructor at exit raced Mesa's own teardown (OSMesaMakeCurrent crashed in about one
// exit in twenty when stdout was a pipe).
ParticleDeviceProvider* gProvider = nullptr;
std::string gProviderError;
bool gTried = false;
}  // namespace

void registerGpuPhysics(GpuPhysicsFactory factory) {
  gFactory = factory;
  if (!gProvider) gTried = false;  // a failure of the previous factory is not this one's
}

ParticleDeviceProvider* gpuPhysicsProvider(std::string* error) {
  if (!gFactory) {
    *error = "this build has no GPU physics (it was built without OpenGL: SIMGRASS_BUILD_VIEWER=OFF)";
    return nullptr;
  }
  if (!gTried) {  // one context per process, kept for its lifetime
    gTried = true;
    gProvider = gFactory(&gProviderError).release();
  }
  if (!gProvider) *error = gProviderError;
  return gProvider;
}

std::optional<PhysicsPath> parsePhysicsPath(const std::string& text) {
  if (text == "cpu") return PhysicsPath::Cpu;
  if (text == "gpu") return PhysicsPath::Gpu;
  if (text == "gpu-readback") return PhysicsPath::GpuReadback;
  return std::nullopt;
}

std::string applyPhysicsPath(SimWorld& world, PhysicsPath path) {
  if (path == PhysicsPath::Cpu) return world.setPhysicsPath(path, nullptr);
  std::string error;
  ParticleDeviceProvider* provider = gpuPhysicsProvider(&error);
  if (!provider) return error;
  return world.setPhysicsPath(path, provider);
}

std::string describePhysics(const SimWorld& world) {
  const PhysicsPath path = world.physicsPath();
  if (path == PhysicsPath::Cpu || !gProvider) return physicsPathName(path);
  return std::string(physicsPathName(path)) + " (" + gProvider->describe() + ")";
}

}  // namespace sg
