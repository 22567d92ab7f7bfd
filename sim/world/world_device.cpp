// World<S> on a device (docs/gpu-physics.md): which worlds may move their grass stages off the
// CPU, the particle pass there, and copying the particles back where the host reads them.
#include <algorithm>

#include "sim/world/world.h"
#include "sim/world/world_rows.h"

namespace sg {

template <class S>
std::string World<S>::deviceLimitation() const {
  // fx32 and fx16 with the CPU's bits; float as a comparison variant without that promise.
  if constexpr (std::is_same_v<S, double>)
    return "the device path runs fx32 and fx16 (the CPU's bits) and float (a comparison variant); this world is "
           "double";
  else
    return "";
}

template <class S>
std::string World<S>::setPhysicsPath(PhysicsPath path, ParticleDeviceProvider* provider) {
  if (path == PhysicsPath::Cpu) {
    syncFromDevice();
    device_.reset();
    physicsPath_ = path;
    return "";
  }
  if (std::string why = deviceLimitation(); !why.empty()) return why;
  if (!provider) return "no device: this build has no GPU physics";
  if constexpr (!std::is_same_v<S, double>) {
    std::string error;
    std::unique_ptr<ParticleDevice<S>> device;
    const bool tramples = !particles_.trample.empty();
    if constexpr (std::is_same_v<S, Fx32>)
      device = provider->makeFx32(grid_.countX, grid_.countZ, model_, tramples, &error);
    else if constexpr (std::is_same_v<S, Fx16>)
      device = provider->makeFx16(grid_.countX, grid_.countZ, model_, tramples, &error);
    else
      device = provider->makeFloat(grid_.countX, grid_.countZ, model_, tramples, &error);
    if (!device) return error.empty() ? "the device could not be set up" : error;
    syncFromDevice();  // from an old device, if any: the host is the truth again
    device_ = std::move(device);
    physicsPath_ = path;
    hostAhead_ = true;  // uploaded before the next pass
    deviceDisplacementCurrent_ = false;
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
  // The wind as runs of columns, row by row (a few values per row; computed here on the host as
  // the CPU pass computes it). Without a window, storage rows and columns are lattice ones.
  DeviceWind<S>& wind = deviceWind_;
  wind.rowFirstRun.clear();
  wind.runBegin.clear();
  wind.dvx.clear();
  wind.dvy.clear();
  wind.dvz.clear();
  const bool rowUniform = windSchedule_.rowUniform();
  const LatticeWindow& window = grid_.window;
  thread_local std::vector<WindRun<S>> runs;
  thread_local std::vector<WindPiece> pieces;
  for (int64_t r = 0; r < grid_.countZ; ++r) {
    wind.rowFirstRun.push_back(int32_t(wind.runBegin.size()));
    const int64_t latticeRow = window.latticeRow(r);
    const auto addRun = [&](int64_t begin, const WindRun<S>& run) {
      wind.runBegin.push_back(int32_t(begin));
      wind.dvx.push_back(run.dvx);
      wind.dvy.push_back(run.dvy);
      wind.dvz.push_back(run.dvz);
    };
    if (rowUniform) {
      const size_t l = size_t(latticeRow);
      addRun(0, WindRun<S>{0, grid_.countX, rowAccel_.x[l], rowAccel_.y[l], rowAccel_.z[l]});
      continue;
    }
    // As the CPU pass cuts a row (world_rows.h): its pieces in storage order.
    computeRowWind(windSchedule_, windConsts_, tick_, latticeRow, window.originI, window.endI(), &runs);
    windPiecesInStorageOrder(window, grid_.countX, runs, &pieces);
    for (const WindPiece& piece : pieces) addRun(piece.begin, runs[piece.run]);
  }
  wind.rowFirstRun.push_back(int32_t(wind.runBegin.size()));
  // A fault anywhere in the pass (or in the wind above, which the CPU pass meets inside its rows)
  // hands the tick back: the device kept the tick's input, and the CPU reference redoes the tick
  // from it, so a failed world holds the CPU's state too (the CPU stops the faulting row where it
  // faulted) and its fault report is the reference's own. The host is the truth until the next
  // upload.
  if (pendingFixedFaults() != 0) return handDeviceTickBack();
  uint32_t faultBits = 0;
  const RowFault fault = device_->advance(wind, particleConsts_, &faultBits);
  if (fault.particle >= 0) return handDeviceTickBack();
  deviceAhead_ = true;
  deviceDisplacementCurrent_ = physicsPath_ == PhysicsPath::Gpu;
  devicePatchesCurrent_ = false;
  if (physicsPath_ == PhysicsPath::GpuReadback) {
    // The thesis' design: the state comes back every tick, and the patch stage runs on the host.
    device_->download(particles_, &dispX_, &dispY_, &dispZ_);
    deviceAhead_ = false;
  }
  return true;
}

template <class S>
bool World<S>::handDeviceTickBack() {
  takeFixedFaults();
  device_->download(particles_, nullptr, nullptr, nullptr);
  deviceAhead_ = false;
  hostAhead_ = true;
  deviceDisplacementCurrent_ = false;
  return false;
}

template <class S>
bool World<S>::devicePush(const GrassPushers<S>& pushers, std::vector<int64_t>* pushedPerBody) {
  if (hostAhead_) {
    device_->upload(particles_);
    hostAhead_ = false;
  }
  // No fault is pending here: respondToContacts took (and reported) those of the mowing and the
  // pushers' set-up just before.
  DevicePush<S> push;
  push.pushers = &pushers;
  push.settings = &bodyParticle_;
  push.window = &grid_.window;
  push.bodyCount = bodies_.size();
  if (grassDragDt_ > S(0)) {  // each body's pushed tufts come back only where they drag it
    pushedPerBody->assign(bodies_.size(), 0);
    push.pushedPerBody = pushedPerBody;
  }
  if (!device_->push(push)) return handDeviceTickBack();
  // The pushed state is the device's; its tip displacement is still the last pass's, as the
  // host's is until its pass (a tick that stops here, at the grass drag, keeps both).
  deviceAhead_ = true;
  return true;
}

template <class S>
bool World<S>::deriveDevicePatches() const {
  if (!device_ || !deviceDisplacementCurrent_) return false;
  if (!devicePatchesCurrent_)
    devicePatchesCurrent_ = device_->derivePatches(DevicePatchInputs<S>{
        grid_.window, patchWindow_, &patchConsts_, &patches_.rootY, &patches_.cut, patchInputsRevision_});
  return devicePatchesCurrent_;
}

template <class S>
bool World<S>::downloadDevicePatches(PatchArrays<S>* out) const {
  if (!deriveDevicePatches()) return false;
  *out = patches_;  // the static fields (roots, rotations, variants, cuts) are the host's
  device_->downloadPatches(*out);
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
  template bool World<S>::handDeviceTickBack();                                        \
  template bool World<S>::devicePush(const GrassPushers<S>&, std::vector<int64_t>*);   \
  template bool World<S>::downloadDevicePatches(PatchArrays<S>*) const;                \
  template bool World<S>::deriveDevicePatches() const;                                 \
  template void World<S>::syncFromDevice() const;

SG_FOR_EACH_SCALAR(SG_INSTANTIATE_DEVICE)

}  // namespace sg
