// The step of World<S>: one fixed tick as a sequence of stages in the thesis order (runPhysics,
// thesis section 9.2). Each stage is timed through the observer (begin and end always paired) and
// a fault is attributed to the stage that raised it.
#include "sim/bodies/sleep_islands.h"
#include "sim/particles/blade.h"
#include "sim/state/state_hash.h"
#include "sim/world/settings.h"
#include "sim/world/world.h"
#include "sim/world/world_rows.h"

namespace sg {

template <class S>
void World<S>::updatePatchState() {
  syncFromDevice();
  const S rod = particleConsts_.rodLength;
  pool_->run((grid_.countZ + rowsPerChunk_ - 1) / rowsPerChunk_, [&](int64_t c, int) {
    const int64_t b1 = std::min(grid_.countZ, (c + 1) * rowsPerChunk_);
    particleDisplacement(particles_, c * rowsPerChunk_ * grid_.countX, b1 * grid_.countX, rod, dispX_, dispY_, dispZ_);
  });
  updatePatchesFromDisplacement();
}

template <class S>
void World<S>::updatePatchesFromDisplacement() {
  if (grid_.k == 1) {  // patch and particle windows coincide: storage index for storage index
    const PatchWriter<S> out(patches_, patchConsts_);
    const S *dx = dispX_.data(), *dy = dispY_.data(), *dz = dispZ_.data();
    pool_->run((grid_.countZ + rowsPerChunk_ - 1) / rowsPerChunk_, [&](int64_t c, int) {
      const int64_t q0 = c * rowsPerChunk_ * grid_.countX;
      const int64_t q1 = std::min(grid_.countZ, (c + 1) * rowsPerChunk_) * grid_.countX;
      if (particleKernel_ == ParticleKernel::Avx2)
        return writePatchesAvx2(out, size_t(q0), dx + q0, dy + q0, dz + q0, q1 - q0);
      for (int64_t q = q0; q < q1; ++q)
        out.writeFast(size_t(q), dx[q], dy[q], dz[q]);  // same bits as write(): patch_state.h
    });
    return;
  }
  const bool vector = particleKernel_ == ParticleKernel::Avx2;
  const LatticeWindow& pw = patchWindow_;
  const int64_t patchRowsPerChunk = std::max<int64_t>(1, settings::kTargetChunkElements / pw.sizeI);
  pool_->run((pw.sizeJ + patchRowsPerChunk - 1) / patchRowsPerChunk, [&](int64_t c, int worker) {
    S* scratch = rowScratch_.data() + size_t(worker) * size_t(3 * (grid_.countX + pw.sizeI));
    const int64_t j1 = pw.originJ + std::min(pw.sizeJ, (c + 1) * patchRowsPerChunk);
    for (int64_t j = pw.originJ + c * patchRowsPerChunk; j < j1; ++j)
      exactRowWeights_&& grid_.k == 2
          ? updatePatchRow<S, 2>(patches_, pw, j, grid_.window, dispX_, dispY_, dispZ_, patchConsts_, scratch, vector)
      : exactRowWeights_&& grid_.k == 4
          ? updatePatchRow<S, 4>(patches_, pw, j, grid_.window, dispX_, dispY_, dispZ_, patchConsts_, scratch, vector)
          : updatePatchRow<S>(patches_, pw, j, grid_.window, dispX_, dispY_, dispZ_, patchConsts_, scratch);
  });
}

template <class S>
StepResult World<S>::step(const TickInput& input, StageObserver* observer) {
  if (failed_) return {false, failure_};
  takeFixedFaults();  // faults raised outside the step (tools, tests) are not this tick's
  digestRowsThisStep_ = digestRowsInNextStep_;
  digestRowsInNextStep_ = false;
  rowDigestsCurrent_ = false;  // the particles are about to move
  // One stage: timed through the observer (begin and end always paired); a stage that fails has
  // recorded its fault in failure_ and the tick stops there.
  auto stage = [&](Stage st, auto&& run) {
    if (observer) observer->stageBegin(st);
    const bool ok = run();
    if (observer) observer->stageEnd(st);
    return ok;
  };
  // A scenario without bodies pays nothing for the body stages, one without the level of detail
  // nothing for the window.
  const bool bodies = !bodies_.empty();
  const bool ok = (!lodWindow_ || stage(Stage::Window, [&] { return windowStage(input); })) &&
                  (!bodies || stage(Stage::Input, [&] { return inputStage(input); })) &&
                  stage(Stage::Wind, [&] { return windStage(); }) &&
                  (!bodies || stage(Stage::Collision, [&] { return collisionStage(); })) &&
                  (!bodies || stage(Stage::Response, [&] { return respondToContacts(); })) &&
                  stage(Stage::Integrate, [&] { return integrateStage(); }) &&
                  stage(Stage::PatchState, [&] { return patchStage(); });
  if (!ok) return {false, failure_};
  ++tick_;
  return {};
}

template <class S>
bool World<S>::failWith(Stage stage, uint32_t faults) {
  failed_ = true;
  failure_ = SimError{};
  failure_.tick = tick_;
  failure_.stage = stage;
  failure_.what = fixedFaultName(faults);
  return false;
}

template <class S>
bool World<S>::windowStage(const TickInput& input) {
  if (input.hasCamera) followCamera(input.camera);
  // Entering cells are filled in parallel from the lattice and the terrain, whose values the
  // scenario validation keeps in range; fault bits would be seen only on this thread, so reading
  // them would make the result depend on the thread count. Cleared, never reported.
  takeFixedFaults();
  return true;
}

template <class S>
bool World<S>::inputStage(const TickInput& input) {
  applyCommands(input);
  return !bodiesFaulted(Stage::Input);
}

template <class S>
bool World<S>::windStage() {
  // The window's rows only (with the level of detail off, the window is the field).
  computeRowAcceleration(windSchedule_, windConsts_, tick_, &rowAccel_, grid_.window.originJ, grid_.window.endJ());
  const uint32_t faults = takeFixedFaults();
  return faults == 0 || failWith(Stage::Wind, faults);
}

template <class S>
bool World<S>::collisionStage() {
  detectContacts();
  if (failed_) return false;  // too many contacts (failWithTooManyContacts)
  return !bodiesFaulted(Stage::Collision);
}

template <class S>
bool World<S>::integrateStage() {
  const ParticleConstants<S>& c = particleConsts_;
  const bool pbd = model_ == GrassModel::Pbd, blade = model_ == GrassModel::Blade;
  const bool tramples = !particles_.trample.empty();
  // Integration, the rod constraint and the tip displacement run as one pass, row by row
  // (sim/particles/particle_row.h, blade.h): bit-identical to three passes, a third of the memory
  // traffic. Its time is reported under Stage::Integrate; Stage::Constraints names a projection
  // fault.
  // One run of a row's particles [b, e) under one wind increment.
  const auto advance = [&](int64_t b, int64_t e, S dvx, S dvy, S dvz) -> RowFault {
    const ParticleKernel kernel = particleKernel_;
    if (blade) {  // the blade kernel is one loop (blade.h): a fault is the integration's
      const int64_t at =
          tramples ? advanceBladeRow<S, true>(kernel, particles_, b, e, dvx, dvy, dvz, c, dispX_, dispY_, dispZ_)
                   : advanceBladeRow<S, false>(kernel, particles_, b, e, dvx, dvy, dvz, c, dispX_, dispY_, dispZ_);
      return {at, Stage::Integrate};
    }
    return pbd ? advanceParticleRow<S, true>(kernel, particles_, b, e, dvx, dvy, dvz, c, dispX_, dispY_, dispZ_)
               : advanceParticleRow<S, false>(kernel, particles_, b, e, dvx, dvy, dvz, c, dispX_, dispY_, dispZ_);
  };
  // On a device (world_device.cpp), unless the pass faulted: then the reference below redoes the
  // tick and reports the fault.
  const bool onDevice = device_ && deviceParticlePass();
  const bool rowUniform = windSchedule_.rowUniform();
  const LatticeWindow& window = grid_.window;
  const auto advanceRow = [&](int64_t row, int64_t b, int64_t e) -> RowFault {
    const int64_t latticeRow = window.latticeRow(row);
    if (rowUniform) {  // the wind acts per lattice row
      const size_t r = size_t(latticeRow);
      return advance(b, e, rowAccel_.x[r], rowAccel_.y[r], rowAccel_.z[r]);
    }
    // Gust fronts crossing the rows: runs of columns under the same wind (sim/wind/wind.h), each
    // advanced as a row would be, in storage order (a window wraps its columns at most once).
    thread_local std::vector<WindRun<S>> runs;
    thread_local std::vector<WindPiece> pieces;
    computeRowWind(windSchedule_, windConsts_, tick_, latticeRow, window.originI, window.endI(), &runs);
    windPiecesInStorageOrder(window, grid_.countX, runs, &pieces);
    for (const WindPiece& piece : pieces) {
      const WindRun<S>& run = runs[piece.run];
      const RowFault fault = advance(b + piece.begin, b + piece.end, run.dvx, run.dvy, run.dvz);
      if (fault.particle >= 0) return fault;
    }
    (void)e;
    return {};
  };
  // A requested state hash takes each row group's digests right after the group moved: a group is
  // one chunk of this pass, moved by one thread in row order (state_hash.h). Should the chunks ever
  // differ from the groups, the digests are left to stateHash() instead (a group split between two
  // threads would be hashed while the other still moves it).
  const int64_t rowsPerGroup = stateHashRowsPerGroup(grid_.countX);
  const bool digest = digestRowsThisStep_ && !onDevice && rowsPerChunk_ == rowsPerGroup;
  if (digest) rowDigests_.resize(size_t(particles_.trample.empty() ? 6 : 7) * size_t(particleGroups()));
  const bool moved = onDevice || runParticleRows(Stage::Integrate, [&](int64_t row, int64_t b, int64_t e) -> RowFault {
                       const RowFault fault = advanceRow(row, b, e);
                       if (digest && fault.particle < 0 && ((row + 1) % rowsPerGroup == 0 || row + 1 == grid_.countZ))
                         digestParticleGroup(row / rowsPerGroup, rowDigests_.data());
                       return fault;
                     });
  rowDigestsCurrent_ = digest && moved;
  if (!moved || bodies_.empty()) return moved;
  // The bodies moved in the response stage (the soft step integrates their positions in every
  // sub-step); here they may fall asleep, by islands.
  updateSleep(bodies_, contacts_, sleepLinear_, sleepAngular_, ticksToSleep_);
  return !bodiesFaulted(Stage::Integrate);
}

template <class S>
bool World<S>::patchStage() {
  // The patch stage is derived data only (never fed back into the state) and runs unchecked
  // arithmetic with Fixed's exact bits (patches/patch_state.h); like the window, its bits are
  // cleared so they cannot be blamed on a later stage. With the particles on a device, the patch
  // stage is derived where it is read, from the tip displacements the pass left there: on the
  // device when a renderer in its context asks for its buffer (deriveDevicePatches, once per
  // drawn frame), on the host when the host next reads the particles (syncFromDevice: copying
  // the patches back would move more bytes than the displacement it derives them from).
  if (deviceAhead_) return true;
  updatePatchesFromDisplacement();
  takeFixedFaults();
  return true;
}

#define SG_INSTANTIATE_STEP(S)                                          \
  template StepResult World<S>::step(const TickInput&, StageObserver*); \
  template void World<S>::updatePatchState();                           \
  template void World<S>::updatePatchesFromDisplacement();              \
  template bool World<S>::failWith(Stage, uint32_t);                    \
  template bool World<S>::windowStage(const TickInput&);                \
  template bool World<S>::inputStage(const TickInput&);                 \
  template bool World<S>::windStage();                                  \
  template bool World<S>::collisionStage();                             \
  template bool World<S>::integrateStage();                             \
  template bool World<S>::patchStage();

SG_FOR_EACH_SCALAR(SG_INSTANTIATE_STEP)

}  // namespace sg
