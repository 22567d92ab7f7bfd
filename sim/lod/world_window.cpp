// The level-of-detail window of World<S> (docs/level-of-detail.md): which part of the infinite
// lattice the particles and patches hold (a toroidal window, sim/lod/lattice_window.h), filling
// what enters it from the lattice hash and the persistent cuts, and following the camera.
#include "sim/world/input_conversion.h"
#include "sim/world/world.h"

namespace sg {

template <class S>
int64_t World<S>::nearestParticleColumn(S coordinate, S fieldOrigin) const {
  return floorToInt((coordinate - fieldOrigin) * bodyParticle_.invParticleSpacing + S(1) / S(2));
}

template <class S>
int64_t World<S>::clampWindowOrigin(int64_t origin, bool alongX) const {
  const LatticeWindow& w = grid_.window;
  // The last origin keeps every held patch inside the field: k (origin + size - 1) <= patches - 1.
  const int64_t last = alongX ? (patchWindow_.fieldI - 1) / grid_.k - (w.sizeI - 1)
                              : (patchWindow_.fieldJ - 1) / grid_.k - (w.sizeJ - 1);
  return std::clamp<int64_t>(origin, 0, std::max<int64_t>(0, last));
}

template <class S>
void World<S>::initParticle(int64_t I, int64_t J, bool initialVelocity) {
  const size_t q = grid_.window.storageIndex(I, J);
  S x, z;
  lattice_.rootXZ(I * grid_.k, J * grid_.k, &x, &z);
  const S y = terrain_.heightAt(x, z);
  particles_.anchorX[q] = x;
  particles_.anchorY[q] = y;
  particles_.anchorZ[q] = z;
  particles_.px[q] = x;
  particles_.py[q] = y + particleConsts_.rodLength;
  particles_.pz[q] = z;
  // Particles entering a moving window start at rest; the scenario's initial velocity is the
  // thesis' start-up kick for the first window only.
  const Vec3<S> v = initialVelocity ? initialVelocity_ : Vec3<S>::Zero();
  particles_.vx[q] = v.x();
  particles_.vy[q] = v.y();
  particles_.vz[q] = v.z();
  if (!particles_.trample.empty()) particles_.trample[q] = S(0);
}

template <class S>
void World<S>::initPatch(int64_t i, int64_t j) {
  const size_t p = patchWindow_.storageIndex(i, j);
  lattice_.rootXZ(i, j, &patches_.rootX[p], &patches_.rootZ[p]);
  patches_.rootY[p] = terrain_.heightAt(patches_.rootX[p], patches_.rootZ[p]);
  patches_.rotation[p] = lattice_.rotation(i, j);
  patches_.variant[p] = lattice_.variant(i, j);
  // Markings use the un-jittered lattice point: straight lines despite the jitter.
  if (markings_.onLine(lattice_.originX + mulInt(lattice_.spacing, i), lattice_.originZ + mulInt(lattice_.spacing, j)))
    patches_.variant[p] = uint8_t(lattice_.atlasVariants);
  // Mown tufts stay mown: the cut lives in the persistent world data, not in the window.
  patches_.cut[p] = cuts_.count({i, j}) ? 1 : 0;
  ++patchInputsRevision_;  // a device's patch stage copies the roots and cuts again
}

template <class S>
void World<S>::fillWindow(int64_t originI, int64_t originJ, bool initialVelocity) {
  moveWindowTo(originI, originJ, initialVelocity, true);
}

template <class S>
void World<S>::moveWindowTo(int64_t originI, int64_t originJ, bool initialVelocity, bool everything) {
  // On a device (world_device.cpp) nothing comes back: the host writes the entering cells into its
  // arrays (each a function of its lattice coordinates alone) and sends up just those, whether
  // the rest of the host's arrays is current or not. (`everything`, or a host already ahead,
  // sends the whole state before the next pass.)
  const bool cellsOnly = device_ && !hostAhead_ && !everything;
  if (device_ && !cellsOnly) {
    syncFromDevice();
    hostAhead_ = true;
  }
  if (device_) deviceDisplacementCurrent_ = false;  // the next pass's, for the new window
  const LatticeWindow oldParticles = grid_.window, oldPatches = patchWindow_;
  grid_.window.originI = originI;
  grid_.window.originJ = originJ;
  patchWindow_.originI = originI * grid_.k;
  patchWindow_.originJ = originJ * grid_.k;
  // Only what enters is written: rows new to the window entirely, other rows only in the
  // columns new to it. Each cell depends on its lattice coordinates alone, so the result is the
  // same whatever the path and the thread count.
  auto fill = [&](const LatticeWindow& now, const LatticeWindow& before, auto&& init) {
    pool_->run(now.sizeJ, [&](int64_t r, int) { forEachEnteringCell(now, before, everything, r, init); });
  };
  fill(grid_.window, oldParticles, [&](int64_t I, int64_t J) { initParticle(I, J, initialVelocity); });
  if (cellsOnly) {
    thread_local std::vector<typename ParticleDevice<S>::Span> spans;
    spans.clear();
    forEachEnteringSpan(grid_.window, oldParticles, [&](int64_t first, int64_t count) {
      spans.push_back({first, count});
    });
    device_->uploadCells(particles_, spans);
  }
  fill(patchWindow_, oldPatches, [&](int64_t i, int64_t j) { initPatch(i, j); });
  if (lodWindow_)
    edgeRing_.follow(
        patchWindow_, terrain_, markings_,
        [&](int64_t i, int64_t j) {
          return cuts_.count({i, j}) > 0;
        },
        everything);
}

template <class S>
void World<S>::followCamera(const InputVec3& camera) {
  // The window's centre follows the camera's nearest particle column and row with a dead zone of
  // one particle spacing: a camera that stops, or wobbles across a cell border, moves nothing.
  // (The thesis accumulated projected camera motion per side; this is a function of the camera
  // position and the window alone, so it cannot drift.)
  const int64_t camI = nearestParticleColumn(inputScalar<S>(camera.x), lattice_.originX);
  const int64_t camJ = nearestParticleColumn(inputScalar<S>(camera.z), lattice_.originZ);
  auto follow = [](int64_t origin, int64_t size, int64_t cam) {
    const int64_t centre = origin + (size - 1) / 2;
    if (cam > centre + 1) return origin + (cam - 1 - centre);
    if (cam < centre - 1) return origin - (centre - 1 - cam);
    return origin;
  };
  const int64_t I0 = clampWindowOrigin(follow(grid_.window.originI, grid_.window.sizeI, camI), true);
  const int64_t J0 = clampWindowOrigin(follow(grid_.window.originJ, grid_.window.sizeJ, camJ), false);
  if (I0 != grid_.window.originI || J0 != grid_.window.originJ) moveWindowTo(I0, J0, false, false);
}

#define SG_INSTANTIATE_WINDOW(S)                                      \
  template int64_t World<S>::nearestParticleColumn(S, S) const;       \
  template int64_t World<S>::clampWindowOrigin(int64_t, bool) const;  \
  template void World<S>::initParticle(int64_t, int64_t, bool);       \
  template void World<S>::initPatch(int64_t, int64_t);                \
  template void World<S>::fillWindow(int64_t, int64_t, bool);         \
  template void World<S>::moveWindowTo(int64_t, int64_t, bool, bool); \
  template void World<S>::followCamera(const InputVec3&);

SG_FOR_EACH_SCALAR(SG_INSTANTIATE_WINDOW)

}  // namespace sg
