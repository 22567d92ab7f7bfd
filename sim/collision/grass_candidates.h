// The grass push's candidate filter (body_particles.cpp). The lattice broad phase gives each body
// part the particles whose anchors lie within its reach plus a rod: about 170 per 0.2 m sphere on
// the thesis meadow, of which most are tuft tips far above or below it. Before the parts of a row
// run, one pass over the row marks the particles whose height lies inside the band the row's parts
// span; a part then tests only the marked particles of its columns (the stage costs a pass per
// busy row plus the particles near the parts, not parts x candidates).
//
// The band is a filter only: a marked particle still goes through withinReach and the exact push,
// and every particle withinReach would pass is marked (in exact integer arithmetic: fixed-point
// only; float and double test every candidate). The band is the union of the row's parts, so an
// unmarked particle is out of every part's reach and no push moves it: the marks taken before the
// row's first push hold for all of them. Particles whose height is beyond a quarter of the range, or rows with a part
// beyond it, are always marked: there the reference's y difference might overflow, and only
// testing them raises that fault as the reference does. So kernels and the filter change no bits
// and no fault report.
#pragma once

#include <cstdint>
#include <limits>

#include "sim/math/eigen_support.h"
#include "sim/math/scalar.h"
#include "sim/particles/particle_kernel.h"

namespace sg {

/// Reference pre-test of one particle: false where it misses the cube of half-side `reach` (m)
/// around (cx, cy, cz). y first: most misses are tuft tips above a body lying in the grass.
template <class S>
inline bool withinReach(S px, S py, S pz, S cx, S cy, S cz, S reach) {
  return !(abs(S(py - cy)) >= reach || abs(S(px - cx)) >= reach || abs(S(pz - cz)) >= reach);
}

/// The open height band (bottom, top) of a row's parts, in raw fixed-point units, and the bound
/// beyond which a height is always marked.
template <class S>
struct HeightBand {
  using Raw = decltype(S().raw());
  static constexpr Raw kBound = std::numeric_limits<Raw>::max() / 4;  ///< a quarter of the range
  Raw bottom = std::numeric_limits<Raw>::max(), top = std::numeric_limits<Raw>::min();
  bool everything = false;  ///< a part beyond the bound: mark every particle

  /// Widens the band to (cy - reach, cy + reach).
  void add(S cy, S reach) {
    if (cy.raw() > kBound || cy.raw() < -kBound || reach.raw() > kBound || reach.raw() < 0) everything = true;
    if (everything) return;
    bottom = std::min<Raw>(bottom, cy.raw() - reach.raw());
    top = std::max<Raw>(top, cy.raw() + reach.raw());
  }
  bool marks(S py) const {
    const Raw y = py.raw();
    return everything || y > kBound || y < -kBound || (y > bottom && y < top);
  }
};

/// Sets bit k of marks (word k / 64) for each particle k of py[0 .. n) that band.marks; clears the
/// others. marks holds (n + 63) / 64 words. AVX2 where kernel says so and the CPU has it.
template <class S>
void markHeightBand(const S* py, int64_t n, const HeightBand<S>& band, ParticleKernel kernel, uint64_t* marks);

/// AVX2 withinReach of particles [0, n), n <= 64, around c: bit k of *mask for particle k.
/// Returns false (and leaves *mask as it was) where a difference would overflow or the CPU has
/// no AVX2: then run withinReach in order, which raises the fault as the reference does.
/// Fx32 and Fx16.
template <class S>
bool withinReachMask(const S* px, const S* py, const S* pz, int n, const Vec3<S>& c, S reach, uint64_t* mask);

}  // namespace sg
