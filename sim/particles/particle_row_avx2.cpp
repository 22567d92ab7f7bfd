// The fused particle pass (particle_row.h) in AVX2, with the reference's exact bits: Fx32 four
// particles per block (one Q32.32 value per 64-bit lane), Fx16 eight (one Q16.16 value per
// 32-bit lane), float eight and double four (IEEE lanes). The exact fixed-point lane arithmetic
// is avx2_fixed.h's.
//
// How it stays exact (docs/performance.md, "Vector kernels"): every product, sum, root and
// quotient either has Fixed's bits or flags its lane (avx2_fixed.h). A block with any lane
// flagged writes nothing and is recomputed by the scalar reference from the untouched memory, so
// faults, rare rounding cases and anything out of range get the reference's bits and its fault
// report. A guess that is off only costs a block its speed, never its bits. The functions carry
// target("avx2") and are called only when the CPU has AVX2 (particle_row.h picks the kernel).
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <type_traits>

#include "sim/particles/avx2_fixed.h"
#include "sim/particles/avx2_ieee.h"
#include "sim/particles/particle_row.h"

namespace sg {

const char* particleKernelName(ParticleKernel kernel) { return kernel == ParticleKernel::Avx2 ? "avx2" : "scalar"; }
const char* physicsPathName(PhysicsPath path) {
  return path == PhysicsPath::Gpu ? "gpu" : path == PhysicsPath::GpuReadback ? "gpu-readback" : "cpu";
}

#if defined(__x86_64__)

bool avx2KernelAvailable() {
  static const bool available = __builtin_cpu_supports("avx2");
  return available;
}

namespace {

using avx2::all32;
using avx2::all64;
using avx2::ones;

// ---- Fx32: four particles per block ---------------------------------------------------------
namespace q32 {

using namespace avx2::q32;  // NOLINT(google-build-using-namespace)

struct RowConstants {
  Multiplier dt, damping, invDt;
  __m256i dvx, dvy, dvz, rod;
  RodDivision division;
};

/// Whether dt and damping^dt are below 1 (raw < 2^32), as in every scenario so far: their
/// products then need two partial products instead of four, and no check.
inline bool narrowStepConstants(const ParticleConstants<Fx32>& c) {
  return (uint64_t(c.dt.raw()) >> 32) == 0 && (uint64_t(c.dampingPerTick.raw()) >> 32) == 0;
}

/// False when a constant is outside what the kernel handles (the row then runs the reference).
__attribute__((target("avx2"))) bool makeRowConstants(const ParticleConstants<Fx32>& c, Fx32 dvx, Fx32 dvy, Fx32 dvz,
                                                      RowConstants& k) {
  const auto fits = [](int64_t v) { return v >= 0 && (uint64_t(v) >> kOperandBits) == 0; };  // no intrinsics here
  const int64_t rod = c.rodLength.raw();
  if (!fits(c.dt.raw()) || !fits(c.dampingPerTick.raw()) || !fits(c.invDt.raw()) || rod <= 0 || !fits(rod))
    return false;
  k.dt = split(all64(c.dt.raw()));
  k.damping = split(all64(c.dampingPerTick.raw()));
  k.invDt = split(all64(c.invDt.raw()));
  k.dvx = all64(dvx.raw());
  k.dvy = all64(dvy.raw());
  k.dvz = all64(dvz.raw());
  k.rod = all64(rod);
  k.division = rodDivision(rod);
  return true;
}

/// Particles [i, i + 4). Returns false, having written nothing, when a lane needs the reference.
template <bool Pbd, bool Narrow>
__attribute__((target("avx2"))) bool advanceBlock(ParticleArrays<Fx32>& p, int64_t i, const RowConstants& k, Fx32* outX,
                                                  Fx32* outY, Fx32* outZ) {
  Flags slow = Flags::none();
  __m256i px = load(&p.px[i]), py = load(&p.py[i]), pz = load(&p.pz[i]);
  __m256i vx = load(&p.vx[i]), vy = load(&p.vy[i]), vz = load(&p.vz[i]);

  // Integration (integrate.h): thesis order p += v dt; v = (v + dv) damping, or symplectic.
  if constexpr (!Pbd) {
    px = addChecked(px, mul<Narrow>(vx, k.dt, slow), slow);
    py = addChecked(py, mul<Narrow>(vy, k.dt, slow), slow);
    pz = addChecked(pz, mul<Narrow>(vz, k.dt, slow), slow);
  }
  vx = mul<Narrow>(addChecked(vx, k.dvx, slow), k.damping, slow);
  vy = mul<Narrow>(addChecked(vy, k.dvy, slow), k.damping, slow);
  vz = mul<Narrow>(addChecked(vz, k.dvz, slow), k.damping, slow);
  if constexpr (Pbd) {
    px = addChecked(px, mul<Narrow>(vx, k.dt, slow), slow);
    py = addChecked(py, mul<Narrow>(vy, k.dt, slow), slow);
    pz = addChecked(pz, mul<Narrow>(vz, k.dt, slow), slow);
  }

  // Rod projection (rod_constraint.h): d = p - anchor; p = anchor + d (L / |d|).
  const __m256i ax = load(&p.anchorX[i]), ay = load(&p.anchorY[i]), az = load(&p.anchorZ[i]);
  const __m256i dx = subChecked(px, ax, slow), dy = subChecked(py, ay, slow), dz = subChecked(pz, az, slow);
  const Offsets off = scaleToRod(dx, dy, dz, k.division, slow);
  const __m256i nx = addChecked(ax, off.x, slow), ny = addChecked(ay, off.y, slow), nz = addChecked(az, off.z, slow);
  if constexpr (Pbd) {  // v += (p_new - p) / dt
    vx = addChecked(vx, mul<false>(subChecked(nx, px, slow), k.invDt, slow), slow);
    vy = addChecked(vy, mul<false>(subChecked(ny, py, slow), k.invDt, slow), slow);
    vz = addChecked(vz, mul<false>(subChecked(nz, pz, slow), k.invDt, slow), slow);
  }
  if (!slow.clear()) return false;

  store(&p.px[i], nx);
  store(&p.py[i], ny);
  store(&p.pz[i], nz);
  store(&p.vx[i], vx);
  store(&p.vy[i], vy);
  store(&p.vz[i], vz);
  // Tip displacement p - anchor - (0, L, 0) (patch_state.h): exactly the offset d * scale.
  store(outX + i, off.x);
  store(outY + i, _mm256_sub_epi64(off.y, k.rod));
  store(outZ + i, off.z);
  return true;
}

}  // namespace q32

// ---- Fx16: eight particles per block --------------------------------------------------------
namespace q16 {

using namespace avx2::q16;  // NOLINT(google-build-using-namespace)

struct RowConstants {
  __m256i dt, damping, invDt, dvx, dvy, dvz, rod;
  RodDivision division;
};

__attribute__((target("avx2"))) bool makeRowConstants(const ParticleConstants<Fx16>& c, Fx16 dvx, Fx16 dvy, Fx16 dvz,
                                                      RowConstants& k) {
  const int32_t rod = c.rodLength.raw();
  if (c.dt.raw() < 0 || c.dampingPerTick.raw() < 0 || c.invDt.raw() < 0 || rod <= 0) return false;
  k = RowConstants{all32(c.dt.raw()),    all32(c.dampingPerTick.raw()),
                   all32(c.invDt.raw()), all32(dvx.raw()),
                   all32(dvy.raw()),     all32(dvz.raw()),
                   all32(rod),           rodDivision(rod)};
  return true;
}

/// Particles [i, i + 8). Returns false, having written nothing, when a lane needs the reference.
template <bool Pbd>
__attribute__((target("avx2"))) bool advanceBlock(ParticleArrays<Fx16>& p, int64_t i, const RowConstants& k, Fx16* outX,
                                                  Fx16* outY, Fx16* outZ) {
  __m256i slow = _mm256_setzero_si256();  // any set bit: the block needs the reference
  __m256i px = load(&p.px[i]), py = load(&p.py[i]), pz = load(&p.pz[i]);
  __m256i vx = load(&p.vx[i]), vy = load(&p.vy[i]), vz = load(&p.vz[i]);

  if constexpr (!Pbd) {
    px = addChecked(px, mul(vx, k.dt, slow), slow);
    py = addChecked(py, mul(vy, k.dt, slow), slow);
    pz = addChecked(pz, mul(vz, k.dt, slow), slow);
  }
  vx = mul(addChecked(vx, k.dvx, slow), k.damping, slow);
  vy = mul(addChecked(vy, k.dvy, slow), k.damping, slow);
  vz = mul(addChecked(vz, k.dvz, slow), k.damping, slow);
  if constexpr (Pbd) {
    px = addChecked(px, mul(vx, k.dt, slow), slow);
    py = addChecked(py, mul(vy, k.dt, slow), slow);
    pz = addChecked(pz, mul(vz, k.dt, slow), slow);
  }

  const __m256i ax = load(&p.anchorX[i]), ay = load(&p.anchorY[i]), az = load(&p.anchorZ[i]);
  const __m256i dx = subChecked(px, ax, slow), dy = subChecked(py, ay, slow), dz = subChecked(pz, az, slow);
  const Offsets off = scaleToRod(dx, dy, dz, k.division, slow);
  const __m256i nx = addChecked(ax, off.x, slow), ny = addChecked(ay, off.y, slow), nz = addChecked(az, off.z, slow);
  if constexpr (Pbd) {
    vx = addChecked(vx, mul(subChecked(nx, px, slow), k.invDt, slow), slow);
    vy = addChecked(vy, mul(subChecked(ny, py, slow), k.invDt, slow), slow);
    vz = addChecked(vz, mul(subChecked(nz, pz, slow), k.invDt, slow), slow);
  }
  if (!_mm256_testz_si256(slow, slow)) return false;

  store(&p.px[i], nx);
  store(&p.py[i], ny);
  store(&p.pz[i], nz);
  store(&p.vx[i], vx);
  store(&p.vy[i], vy);
  store(&p.vz[i], vz);
  store(outX + i, off.x);
  store(outY + i, _mm256_sub_epi32(off.y, k.rod));  // wraps like unchecked::sub
  store(outZ + i, off.z);
  return true;
}

}  // namespace q16

// ---- float and double: eight or four particles per block ----------------------------------
// The blocks compute the reference's operations in its order in IEEE lanes (avx2_ieee.h), so
// they give its bits; MXCSR (rounding, denormals) is shared by scalar and vector instructions. A block
// with a value out of a saved state's range (|x| > 2^48, an infinity or a NaN) after the
// projection (which every integration fault and every tip at its anchor lead to) runs the
// reference, which reports the fault or stands the tip upright.
namespace ieee {

template <class F>
using Simd = avx2::IeeeLanes<F>;

template <class F>
struct RowConstants {
  typename Simd<F>::V dt, damping, invDt, dvx, dvy, dvz, rod;
};

template <class F>
__attribute__((target("avx2"))) bool makeRowConstants(const ParticleConstants<F>& c, F dvx, F dvy, F dvz,
                                                      RowConstants<F>& k) {
  using W = Simd<F>;
  k = {W::all(c.dt), W::all(c.dampingPerTick), W::all(c.invDt), W::all(dvx), W::all(dvy),
       W::all(dvz),  W::all(c.rodLength)};
  return true;
}

/// Particles [i, i + lanes), the reference's operations in its order (integrate.h,
/// rod_constraint.h, patch_state.h's particleDisplacement). Returns false, having written
/// nothing, when the block needs the reference.
template <class F, bool Pbd>
__attribute__((target("avx2"))) bool advanceBlock(ParticleArrays<F>& p, int64_t i, const RowConstants<F>& k, F* outX,
                                                  F* outY, F* outZ) {
  using W = Simd<F>;
  using V = typename W::V;
  V px = W::load(&p.px[i]), py = W::load(&p.py[i]), pz = W::load(&p.pz[i]);
  V vx = W::load(&p.vx[i]), vy = W::load(&p.vy[i]), vz = W::load(&p.vz[i]);
  if constexpr (!Pbd) {
    px = W::add(px, W::mul(vx, k.dt));
    py = W::add(py, W::mul(vy, k.dt));
    pz = W::add(pz, W::mul(vz, k.dt));
  }
  vx = W::mul(W::add(vx, k.dvx), k.damping);
  vy = W::mul(W::add(vy, k.dvy), k.damping);
  vz = W::mul(W::add(vz, k.dvz), k.damping);
  if constexpr (Pbd) {
    px = W::add(px, W::mul(vx, k.dt));
    py = W::add(py, W::mul(vy, k.dt));
    pz = W::add(pz, W::mul(vz, k.dt));
  }
  const V ax = W::load(&p.anchorX[i]), ay = W::load(&p.anchorY[i]), az = W::load(&p.anchorZ[i]);
  const V dx = W::sub(px, ax), dy = W::sub(py, ay), dz = W::sub(pz, az);
  const V len = W::sqrt(W::add(W::add(W::mul(dx, dx), W::mul(dy, dy)), W::mul(dz, dz)));  // length3
  const V scale = W::div(k.rod, len);
  const V nx = W::add(ax, W::mul(dx, scale)), ny = W::add(ay, W::mul(dy, scale)), nz = W::add(az, W::mul(dz, scale));
  if constexpr (Pbd) {  // v += (p_new - p) / dt
    vx = W::add(vx, W::mul(W::sub(nx, px), k.invDt));
    vy = W::add(vy, W::mul(W::sub(ny, py), k.invDt));
    vz = W::add(vz, W::mul(W::sub(nz, pz), k.invDt));
  }
  // One check covers every case the reference handles apart: a non-finite value after
  // integration stays non-finite through the projection (an infinite d gives inf * 0 = NaN; the
  // velocity is kept or grows), and a tip at its anchor (length 0, which the reference stands
  // upright) gives 0 * (L / 0) = NaN. Removing the check makes the tests fail; the early checks
  // it replaces were each removed in turn and no test could tell. The range is a saved state's,
  // |x| <= 2^48, as the reference checks at the end of the particle's step (rod_constraint.h);
  // its integration checks only that values are finite: a finite value beyond 2^48 that the
  // projection puts back in range (the tip back on its rod; pbd's velocity corrected) is no fault
  // on either path, as no state that holds it is ever saved.
  if (!avx2::inStateRange<W>(nx, ny, nz) || !avx2::inStateRange<W>(vx, vy, vz)) return false;
  W::store(&p.px[i], nx);
  W::store(&p.py[i], ny);
  W::store(&p.pz[i], nz);
  W::store(&p.vx[i], vx);
  W::store(&p.vy[i], vy);
  W::store(&p.vz[i], vz);
  // Tip displacement p - anchor - (0, L, 0), in the reference's order ((p - a) - L).
  W::store(outX + i, W::sub(nx, ax));
  W::store(outY + i, W::sub(W::sub(ny, ay), k.rod));
  W::store(outZ + i, W::sub(nz, az));
  return true;
}

}  // namespace ieee

// ---- one row ----------------------------------------------------------------------------------

template <class S>
struct Lanes;
template <>
struct Lanes<Fx32> {
  static constexpr int kBlock = 4;
  using Constants = q32::RowConstants;
};
template <>
struct Lanes<Fx16> {
  static constexpr int kBlock = 8;
  using Constants = q16::RowConstants;
};
template <class F>
requires std::is_floating_point_v<F>
struct Lanes<F> {
  static constexpr int kBlock = ieee::Simd<F>::kCount;
  using Constants = ieee::RowConstants<F>;
};

template <class S, bool Pbd, bool Narrow>
__attribute__((target("avx2"))) RowFault advanceRow(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy,
                                                    S dvz, const ParticleConstants<S>& c, std::vector<S>& dx,
                                                    std::vector<S>& dy, std::vector<S>& dz) {
  constexpr int kBlock = Lanes<S>::kBlock;
  typename Lanes<S>::Constants k;
  bool handled;
  if constexpr (std::is_same_v<S, Fx32>)
    handled = q32::makeRowConstants(c, dvx, dvy, dvz, k);
  else if constexpr (std::is_same_v<S, Fx16>)
    handled = q16::makeRowConstants(c, dvx, dvy, dvz, k);
  else
    handled = ieee::makeRowConstants<S>(c, dvx, dvy, dvz, k);
  if (ScalarTraits<S>::faultPending() || !handled)
    return advanceParticleRowScalar<S, Pbd>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
  int64_t i = begin;
  for (; i + kBlock <= end; i += kBlock) {
    bool done;
    if constexpr (std::is_same_v<S, Fx32>)
      done = q32::advanceBlock<Pbd, Narrow>(p, i, k, dx.data(), dy.data(), dz.data());
    else if constexpr (std::is_same_v<S, Fx16>)
      done = q16::advanceBlock<Pbd>(p, i, k, dx.data(), dy.data(), dz.data());
    else
      done = ieee::advanceBlock<S, Pbd>(p, i, k, dx.data(), dy.data(), dz.data());
    if (done) continue;
    // The reference for this block. Particles are independent, so the state is the same as if
    // the whole row ran the reference; only a fault needs care: the reference integrates the
    // whole row before projecting any of it, so a projection fault here is reported only if
    // no later particle of the row faults in integration.
    const RowFault fault = advanceParticleRowScalar<S, Pbd>(p, i, i + kBlock, dvx, dvy, dvz, c, dx, dy, dz);
    if (fault.particle < 0) continue;
    if (fault.stage == Stage::Constraints) {
      // The reference would have stopped there with only that particle's fault bits.
      const uint32_t projectionFaults = takeFixedFaults();
      if (const int64_t at = integrateParticleRow<S, Pbd>(p, i + kBlock, end, dvx, dvy, dvz, c); at >= 0)
        return {at, Stage::Integrate};
      detail::raiseFixedFault(projectionFaults);
    }
    return fault;
  }
  return advanceParticleRowScalar<S, Pbd>(p, i, end, dvx, dvy, dvz, c, dx, dy, dz);
}

}  // namespace

// Not itself target("avx2"): GCC would take a differently targeted definition of a declared
// function for a multiversioned one. It only forwards.
template <class S, bool Pbd>
RowFault advanceParticleRowAvx2(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy, S dvz,
                                const ParticleConstants<S>& c, std::vector<S>& dx, std::vector<S>& dy,
                                std::vector<S>& dz) {
  if constexpr (std::is_same_v<S, Fx32>)
    if (q32::narrowStepConstants(c)) return advanceRow<S, Pbd, true>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
  return advanceRow<S, Pbd, false>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
}

#else  // no AVX2 on this architecture: the reference

bool avx2KernelAvailable() { return false; }

template <class S, bool Pbd>
RowFault advanceParticleRowAvx2(ParticleArrays<S>& p, int64_t begin, int64_t end, S dvx, S dvy, S dvz,
                                const ParticleConstants<S>& c, std::vector<S>& dx, std::vector<S>& dy,
                                std::vector<S>& dz) {
  return advanceParticleRowScalar<S, Pbd>(p, begin, end, dvx, dvy, dvz, c, dx, dy, dz);
}

#endif

namespace {
// Process-wide choice for worlds built from now on (setDefaultParticleKernel); relaxed is enough:
// it is read when a world is built, and a world's kernel is fixed from then on.
std::atomic<uint8_t> gDefaultKernel{uint8_t(ParticleKernel::Avx2)};
}  // namespace

ParticleKernel defaultParticleKernel() {
  const auto wanted = ParticleKernel(gDefaultKernel.load(std::memory_order_relaxed));
  return wanted == ParticleKernel::Avx2 && avx2KernelAvailable() ? ParticleKernel::Avx2 : ParticleKernel::Scalar;
}

void setDefaultParticleKernel(ParticleKernel kernel) {
  gDefaultKernel.store(uint8_t(kernel), std::memory_order_relaxed);
}

#define SG_INSTANTIATE_AVX2_ROW(S, PBD)                                                                           \
  template RowFault advanceParticleRowAvx2<S, PBD>(ParticleArrays<S>&, int64_t, int64_t, S, S, S,                 \
                                                   const ParticleConstants<S>&, std::vector<S>&, std::vector<S>&, \
                                                   std::vector<S>&);
SG_INSTANTIATE_AVX2_ROW(Fx32, false)
SG_INSTANTIATE_AVX2_ROW(Fx32, true)
SG_INSTANTIATE_AVX2_ROW(Fx16, false)
SG_INSTANTIATE_AVX2_ROW(Fx16, true)
SG_INSTANTIATE_AVX2_ROW(float, false)
SG_INSTANTIATE_AVX2_ROW(float, true)
SG_INSTANTIATE_AVX2_ROW(double, false)
SG_INSTANTIATE_AVX2_ROW(double, true)

}  // namespace sg
