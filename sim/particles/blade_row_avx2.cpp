// The blade model's row (blade.h) for Fx32 and Fx16 in AVX2, with the reference's exact bits:
// Fx32 four particles per block, Fx16 eight. The lane arithmetic is avx2_fixed.h's, and the
// contract is particle_row_avx2.cpp's: a block in which any lane cannot be proved exact (an
// overflow, a root or quotient guess that misses, a tip at its root) writes nothing and runs the
// scalar reference, so faults and rare cases get the reference's bits and its fault report.
// Particles are independent, so a row made of vector blocks and reference blocks is the row the
// reference makes.
#include <type_traits>

#include "sim/particles/avx2_fixed.h"
#include "sim/particles/blade.h"

namespace sg {

#if defined(__x86_64__)

namespace {

using avx2::all32;
using avx2::all64;

// ---- Fx32: four particles per block ---------------------------------------------------------
namespace blade32 {

using namespace avx2::q32;  // NOLINT(google-build-using-namespace): the lane arithmetic of this file

struct BladeConstants {
  Multiplier dt, damping, invDt, invRod, stiffnessDt;
  __m256i dvx, dvy, dvz, rod, decay;
  RodDivision division;
};

/// Whether dt and the blade's damping^dt are below 1 (raw < 2^32): their products then need two
/// partial products instead of four, and no check.
inline bool narrowStepConstants(const ParticleConstants<Fx32>& c) {
  return (uint64_t(c.dt.raw()) >> 32) == 0 && (uint64_t(c.bladeDampingPerTick.raw()) >> 32) == 0;
}

/// False when a constant is outside what the kernel handles (the row then runs the reference).
__attribute__((target("avx2"))) bool makeConstants(const ParticleConstants<Fx32>& c, Fx32 dvx, Fx32 dvy, Fx32 dvz,
                                                   BladeConstants& k) {
  const auto fits = [](int64_t v) { return v >= 0 && (uint64_t(v) >> kOperandBits) == 0; };
  const int64_t rod = c.rodLength.raw();
  if (!fits(c.dt.raw()) || !fits(c.bladeDampingPerTick.raw()) || !fits(c.invDt.raw()) || !fits(c.invRodLength.raw()) ||
      !fits(c.bladeStiffnessDt.raw()) || rod <= 0 || !fits(rod))
    return false;
  k.dt = split(all64(c.dt.raw()));
  k.damping = split(all64(c.bladeDampingPerTick.raw()));
  k.invDt = split(all64(c.invDt.raw()));
  k.invRod = split(all64(c.invRodLength.raw()));
  k.stiffnessDt = split(all64(c.bladeStiffnessDt.raw()));
  k.dvx = all64(dvx.raw());
  k.dvy = all64(dvy.raw());
  k.dvz = all64(dvz.raw());
  k.rod = all64(rod);
  k.decay = all64(c.trampleDecayPerTick.raw());
  k.division = rodDivision(rod);
  return true;
}

/// Particles [i, i + 4), step for step as advanceBladeRowScalar. Returns false, having written
/// nothing, when a lane needs the reference.
template <bool Tramples, bool Narrow>
__attribute__((target("avx2"))) bool advanceBlock(ParticleArrays<Fx32>& p, int64_t i, const BladeConstants& k,
                                                  Fx32* outX, Fx32* outY, Fx32* outZ) {
  Flags slow = Flags::none();
  const __m256i px = load(&p.px[i]), py = load(&p.py[i]), pz = load(&p.pz[i]);
  __m256i vx = load(&p.vx[i]), vy = load(&p.vy[i]), vz = load(&p.vz[i]);
  const __m256i ax = load(&p.anchorX[i]), ay = load(&p.anchorY[i]), az = load(&p.anchorZ[i]);
  const __m256i rx = subChecked(px, ax, slow), ry = subChecked(py, ay, slow), rz = subChecked(pz, az, slow);
  // The recovery toward the rest pose, its stiffness softened by the trample level (which decays).
  __m256i gx, gy, gz, trample{};
  const __m256i ryRest = subChecked(ry, k.rod, slow);
  if constexpr (Tramples) {
    trample = load(&p.trample[i]);
    const __m256i stiffness = mul<false>(subChecked(all64(int64_t(1) << 32), trample, slow), k.stiffnessDt, slow);
    gx = subChecked(k.dvx, mulSigned(rx, stiffness, slow), slow);
    gy = subChecked(k.dvy, mulSigned(ryRest, stiffness, slow), slow);
    gz = subChecked(k.dvz, mulSigned(rz, stiffness, slow), slow);
    // trample > decay ? trample - decay : 0 (a difference that overflows only flags the block).
    trample = _mm256_and_si256(_mm256_cmpgt_epi64(trample, k.decay), subChecked(trample, k.decay, slow));
  } else {
    gx = subChecked(k.dvx, mul<false>(rx, k.stiffnessDt, slow), slow);
    gy = subChecked(k.dvy, mul<false>(ryRest, k.stiffnessDt, slow), slow);
    gz = subChecked(k.dvz, mul<false>(rz, k.stiffnessDt, slow), slow);
  }
  // Only across the rod: g -= r ((g . r) / L / L).
  const __m256i dot =
      addChecked(addChecked(mulSigned(gx, rx, slow), mulSigned(gy, ry, slow), slow), mulSigned(gz, rz, slow), slow);
  const __m256i along = mul<false>(mul<false>(dot, k.invRod, slow), k.invRod, slow);
  gx = subChecked(gx, mulSigned(rx, along, slow), slow);
  gy = subChecked(gy, mulSigned(ry, along, slow), slow);
  gz = subChecked(gz, mulSigned(rz, along, slow), slow);
  vx = mul<Narrow>(addChecked(vx, gx, slow), k.damping, slow);
  vy = mul<Narrow>(addChecked(vy, gy, slow), k.damping, slow);
  vz = mul<Narrow>(addChecked(vz, gz, slow), k.damping, slow);
  const __m256i predictedX = addChecked(px, mul<Narrow>(vx, k.dt, slow), slow);
  const __m256i predictedY = addChecked(py, mul<Narrow>(vy, k.dt, slow), slow);
  const __m256i predictedZ = addChecked(pz, mul<Narrow>(vz, k.dt, slow), slow);
  // Above the root (a height below it counts as zero), then back to length L.
  const __m256i ex = subChecked(predictedX, ax, slow), ez = subChecked(predictedZ, az, slow);
  const __m256i ey = _mm256_and_si256(_mm256_cmpgt_epi64(predictedY, ay), subChecked(predictedY, ay, slow));
  const Offsets off = scaleToRod(ex, ey, ez, k.division, slow);  // flags a tip at its root
  (void)addChecked(ay, k.rod, slow);  // the reference forms the upright tip anchor + L first: its overflow faults
  const __m256i nx = addChecked(ax, off.x, slow), ny = addChecked(ay, off.y, slow), nz = addChecked(az, off.z, slow);
  vx = addChecked(vx, mul<false>(subChecked(nx, predictedX, slow), k.invDt, slow), slow);
  vy = addChecked(vy, mul<false>(subChecked(ny, predictedY, slow), k.invDt, slow), slow);
  vz = addChecked(vz, mul<false>(subChecked(nz, predictedZ, slow), k.invDt, slow), slow);
  if (!slow.clear()) return false;

  store(&p.px[i], nx);
  store(&p.py[i], ny);
  store(&p.pz[i], nz);
  store(&p.vx[i], vx);
  store(&p.vy[i], vy);
  store(&p.vz[i], vz);
  if constexpr (Tramples) store(&p.trample[i], trample);
  // Tip displacement p - anchor - (0, L, 0) (patch_state.h): exactly the offset e * scale.
  store(outX + i, off.x);
  store(outY + i, _mm256_sub_epi64(off.y, k.rod));
  store(outZ + i, off.z);
  return true;
}

}  // namespace blade32

// ---- Fx16: eight particles per block --------------------------------------------------------
namespace blade16 {

using namespace avx2::q16;  // NOLINT(google-build-using-namespace): the lane arithmetic of this file

struct BladeConstants {
  __m256i dt, damping, invDt, invRod, stiffnessDt, dvx, dvy, dvz, rod, decay;
  RodDivision division;
};

__attribute__((target("avx2"))) bool makeConstants(const ParticleConstants<Fx16>& c, Fx16 dvx, Fx16 dvy, Fx16 dvz,
                                                   BladeConstants& k) {
  const int32_t rod = c.rodLength.raw();
  if (c.dt.raw() < 0 || c.bladeDampingPerTick.raw() < 0 || c.invDt.raw() < 0 || c.invRodLength.raw() < 0 ||
      c.bladeStiffnessDt.raw() < 0 || rod <= 0)
    return false;
  k = BladeConstants{all32(c.dt.raw()),
                     all32(c.bladeDampingPerTick.raw()),
                     all32(c.invDt.raw()),
                     all32(c.invRodLength.raw()),
                     all32(c.bladeStiffnessDt.raw()),
                     all32(dvx.raw()),
                     all32(dvy.raw()),
                     all32(dvz.raw()),
                     all32(rod),
                     all32(c.trampleDecayPerTick.raw()),
                     rodDivision(rod)};
  return true;
}

/// Particles [i, i + 8), step for step as advanceBladeRowScalar.
template <bool Tramples>
__attribute__((target("avx2"))) bool advanceBlock(ParticleArrays<Fx16>& p, int64_t i, const BladeConstants& k,
                                                  Fx16* outX, Fx16* outY, Fx16* outZ) {
  __m256i slow = _mm256_setzero_si256();  // any set bit: the block needs the reference
  const __m256i px = load(&p.px[i]), py = load(&p.py[i]), pz = load(&p.pz[i]);
  __m256i vx = load(&p.vx[i]), vy = load(&p.vy[i]), vz = load(&p.vz[i]);
  const __m256i ax = load(&p.anchorX[i]), ay = load(&p.anchorY[i]), az = load(&p.anchorZ[i]);
  const __m256i rx = subChecked(px, ax, slow), ry = subChecked(py, ay, slow), rz = subChecked(pz, az, slow);
  __m256i gx, gy, gz, trample{};
  const __m256i ryRest = subChecked(ry, k.rod, slow);
  if constexpr (Tramples) {
    trample = load(&p.trample[i]);
    const __m256i stiffness = mul(subChecked(all32(1 << 16), trample, slow), k.stiffnessDt, slow);
    gx = subChecked(k.dvx, mulSigned(rx, stiffness, slow), slow);
    gy = subChecked(k.dvy, mulSigned(ryRest, stiffness, slow), slow);
    gz = subChecked(k.dvz, mulSigned(rz, stiffness, slow), slow);
    trample = _mm256_and_si256(_mm256_cmpgt_epi32(trample, k.decay), subChecked(trample, k.decay, slow));
  } else {
    gx = subChecked(k.dvx, mul(rx, k.stiffnessDt, slow), slow);
    gy = subChecked(k.dvy, mul(ryRest, k.stiffnessDt, slow), slow);
    gz = subChecked(k.dvz, mul(rz, k.stiffnessDt, slow), slow);
  }
  const __m256i dot =
      addChecked(addChecked(mulSigned(gx, rx, slow), mulSigned(gy, ry, slow), slow), mulSigned(gz, rz, slow), slow);
  const __m256i along = mul(mul(dot, k.invRod, slow), k.invRod, slow);
  gx = subChecked(gx, mulSigned(rx, along, slow), slow);
  gy = subChecked(gy, mulSigned(ry, along, slow), slow);
  gz = subChecked(gz, mulSigned(rz, along, slow), slow);
  vx = mul(addChecked(vx, gx, slow), k.damping, slow);
  vy = mul(addChecked(vy, gy, slow), k.damping, slow);
  vz = mul(addChecked(vz, gz, slow), k.damping, slow);
  const __m256i predictedX = addChecked(px, mul(vx, k.dt, slow), slow);
  const __m256i predictedY = addChecked(py, mul(vy, k.dt, slow), slow);
  const __m256i predictedZ = addChecked(pz, mul(vz, k.dt, slow), slow);
  const __m256i ex = subChecked(predictedX, ax, slow), ez = subChecked(predictedZ, az, slow);
  const __m256i ey = _mm256_and_si256(_mm256_cmpgt_epi32(predictedY, ay), subChecked(predictedY, ay, slow));
  const Offsets off = scaleToRod(ex, ey, ez, k.division, slow);
  (void)addChecked(ay, k.rod, slow);  // as the reference, which forms anchor + L first
  const __m256i nx = addChecked(ax, off.x, slow), ny = addChecked(ay, off.y, slow), nz = addChecked(az, off.z, slow);
  vx = addChecked(vx, mul(subChecked(nx, predictedX, slow), k.invDt, slow), slow);
  vy = addChecked(vy, mul(subChecked(ny, predictedY, slow), k.invDt, slow), slow);
  vz = addChecked(vz, mul(subChecked(nz, predictedZ, slow), k.invDt, slow), slow);
  if (!_mm256_testz_si256(slow, slow)) return false;

  store(&p.px[i], nx);
  store(&p.py[i], ny);
  store(&p.pz[i], nz);
  store(&p.vx[i], vx);
  store(&p.vy[i], vy);
  store(&p.vz[i], vz);
  if constexpr (Tramples) store(&p.trample[i], trample);
  store(outX + i, off.x);
  store(outY + i, _mm256_sub_epi32(off.y, k.rod));  // wraps like unchecked::sub
  store(outZ + i, off.z);
  return true;
}

}  // namespace blade16

template <class S, bool Tramples, bool Narrow>
__attribute__((target("avx2"))) int64_t advanceRow(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy,
                                                   S dvz, const ParticleConstants<S>& c, std::vector<S>& dx,
                                                   std::vector<S>& dy, std::vector<S>& dz) {
  constexpr bool kFx32 = std::is_same_v<S, Fx32>;
  constexpr int64_t kBlock = kFx32 ? 4 : 8;
  std::conditional_t<kFx32, blade32::BladeConstants, blade16::BladeConstants> k;
  bool handled;
  if constexpr (kFx32)
    handled = blade32::makeConstants(c, dvx, dvy, dvz, k);
  else
    handled = blade16::makeConstants(c, dvx, dvy, dvz, k);
  if (ScalarTraits<S>::faultPending() || !handled)
    return advanceBladeRowScalar<S, Tramples>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
  int64_t i = begin;
  for (; i + kBlock <= end; i += kBlock) {
    bool done;
    if constexpr (kFx32)
      done = blade32::advanceBlock<Tramples, Narrow>(p, i, k, dx.data(), dy.data(), dz.data());
    else
      done = blade16::advanceBlock<Tramples>(p, i, k, dx.data(), dy.data(), dz.data());
    if (done) continue;
    // The reference for this block: one loop, so its first fault is the row's.
    if (const int64_t at = advanceBladeRowScalar<S, Tramples>(p, i, i + kBlock, dvx, dvy, dvz, c, dx, dy, dz); at >= 0)
      return at;
  }
  return advanceBladeRowScalar<S, Tramples>(p, i, end, dvx, dvy, dvz, c, dx, dy, dz);
}

}  // namespace

// Not itself target("avx2") (see particle_row_avx2.cpp): it only forwards.
template <class S, bool Tramples>
int64_t advanceBladeRowAvx2(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy, S dvz,
                            const ParticleConstants<S>& c, std::vector<S>& dx, std::vector<S>& dy, std::vector<S>& dz) {
  if constexpr (std::is_same_v<S, Fx32>)
    if (blade32::narrowStepConstants(c))
      return advanceRow<S, Tramples, true>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
  return advanceRow<S, Tramples, false>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
}

#else  // no AVX2 on this architecture: the reference

template <class S, bool Tramples>
int64_t advanceBladeRowAvx2(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy, S dvz,
                            const ParticleConstants<S>& c, std::vector<S>& dx, std::vector<S>& dy, std::vector<S>& dz) {
  return advanceBladeRowScalar<S, Tramples>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
}

#endif

#define SG_INSTANTIATE_BLADE_ROW(S, TRAMPLES)                                                                      \
  template int64_t advanceBladeRowAvx2<S, TRAMPLES>(ParticleArrays<S>&, int64_t, int64_t, S, S, S,                 \
                                                    const ParticleConstants<S>&, std::vector<S>&, std::vector<S>&, \
                                                    std::vector<S>&);
SG_INSTANTIATE_BLADE_ROW(Fx32, false)
SG_INSTANTIATE_BLADE_ROW(Fx32, true)
SG_INSTANTIATE_BLADE_ROW(Fx16, false)
SG_INSTANTIATE_BLADE_ROW(Fx16, true)

}  // namespace sg
