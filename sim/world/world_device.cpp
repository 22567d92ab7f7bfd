// World<S> on a device (docs/gpu-physics.md): which worlds may move their grass stages off the
// CPU, the particle pass there, and copying the particles back where the host reads them.
#include "sim/world/world.h"

namespace sg {

template <class S>
std::string World<S>::deviceLimitation() const {
  if constexpr (!ScalarTraits<S>::isFixed) {
    return std::string("the device path runs fx32 and fx16 (this world is ") + scalarName(ScalarTraits<S>::kind) + ")";
  } else {
    if (model_ == GrassModel::Blade) return "the device path runs the rod models (thesis, pbd), not model 'blade' yet";
    if (!initialBodies_.empty() || !bodies_.empty())
      return "the device path has no body-grass stage yet (this scenario has bodies)";
    if (lodWindow_) return "the device path has no level-of-detail window yet (lod.mode 'window')";
    if (!windSchedule_.rowUniform())
      return "the device path runs row-uniform wind only (this schedule has swept gust fronts, wind.schedule[].front)";
    return "";
  }
}

template <class S>
std::string World<S>::setPhysicsPath(PhysicsPath path, ParticleDeviceProvider* provider) {
  if (path == PhysicsPath::Cpu) {
    syncFromDevice();
    device_.reset();
    physicsPath_ = path;
    return "";
  }
  if (const std::string why = deviceLimitation(); !why.empty()) return why;
  if (!provider) return "no device: this build has no GPU physics";
  if constexpr (ScalarTraits<S>::isFixed) {
    std::string error;
    std::unique_ptr<ParticleDevice<S>> device;
    const bool pbd = model_ == GrassModel::Pbd;
    if constexpr (std::is_same_v<S, Fx32>)
      device = provider->makeFx32(grid_.countX, grid_.countZ, pbd, &error);
    else
      device = provider->makeFx16(grid_.countX, grid_.countZ, pbd, &error);
    if (!device) return error.empty() ? "the device could not be set up" : error;
    syncFromDevice();  // from an old device, if any: the host is the truth again
    device_ = std::move(device);
    physicsPath_ = path;
    hostAhead_ = true;  // uploaded before the next pass
    return "";
  } else {
    return "";  // unreachable: deviceLimitation() refused
  }
}

template <class S>
bool World<S>::deviceParticlePass() {
  if (hostAhead_) {
    device_->upload(particles_);
    hostAhead_ = false;
  }
  uint32_t faultBits = 0;
  // The wind stage computed every row's increment on the host (a few values per row); the
  // device reads them by storage row, which is the lattice row without a window.
  const RowFault fault = device_->advance(rowAccel_.x, rowAccel_.y, rowAccel_.z, particleConsts_, &faultBits);
  if (fault.particle >= 0) {
    // The device kept the tick's input: the CPU reference redoes the tick from it, so a failed
    // world holds the CPU's state too (the CPU stops the faulting row where it faulted) and its
    // fault report is the reference's own. The host is the truth until the next upload.
    device_->download(particles_, nullptr, nullptr, nullptr);
    deviceAhead_ = false;
    hostAhead_ = true;
    return false;
  }
  deviceAhead_ = true;
  if (physicsPath_ == PhysicsPath::GpuReadback) {
    // The thesis' design: the state comes back every tick, and the patch stage runs on the host.
    device_->download(particles_, &dispX_, &dispY_, &dispZ_);
    deviceAhead_ = false;
  }
  return true;
}

template <class S>
void World<S>::syncFromDevice() const {
  if (!deviceAhead_) return;
  // Worlds are never const objects (makeWorld builds them on the heap): const here means "the
  // state does not change", which holds; only where it is held does.
  auto* self = const_cast<World<S>*>(this);
  self->device_->download(self->particles_, &self->dispX_, &self->dispY_, &self->dispZ_);
  self->deviceAhead_ = false;
  self->updatePatchesFromDisplacement();  // the patch stage the device path left to here
}

#define SG_INSTANTIATE_DEVICE(S)                                                       \
  template std::string World<S>::deviceLimitation() const;                             \
  template std::string World<S>::setPhysicsPath(PhysicsPath, ParticleDeviceProvider*); \
  template bool World<S>::deviceParticlePass();                                        \
  template void World<S>::syncFromDevice() const;

SG_FOR_EACH_SCALAR(SG_INSTANTIATE_DEVICE)

}  // namespace sg
