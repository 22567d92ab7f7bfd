// The grass lattice: patch (i, j) of the field stands at
//     x = originX + i * spacing + jitterX(i, j),   z = originZ + j * spacing + jitterZ(i, j)
// with jitter, rotation and atlas variant pure functions of (i, j, seed) (lattice_hash.h).
// Rotation is an integer fraction of a turn (rotation / 65536 * 360 degrees): the core needs no
// trigonometry; the renderer turns it into cos/sin.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/field/lattice_hash.h"
#include "sim/math/scalar_ops.h"

namespace sg {

template <class S>
struct GrassLattice {
  int64_t patchesX = 0, patchesZ = 0;
  S spacing{};
  S jitterAmplitude{};     ///< m: jitter is uniform in [-amplitude, +amplitude]
  S originX{}, originZ{};  ///< m: un-jittered position of patch (0, 0)
  uint64_t seed = 0;
  int atlasVariants = 4;

  void rootXZ(int64_t i, int64_t j, S* x, S* z) const {
    const uint64_t h = latticeHash(i, j, seed, LatticeSalt::Jitter);
    const S ux = unitFromBits<S>(uint32_t(h >> 32)), uz = unitFromBits<S>(uint32_t(h));
    *x = originX + mulInt(spacing, i) + jitterAmplitude * (ux + ux - S(1));
    *z = originZ + mulInt(spacing, j) + jitterAmplitude * (uz + uz - S(1));
  }
  uint16_t rotation(int64_t i, int64_t j) const { return uint16_t(latticeHash(i, j, seed, LatticeSalt::Appearance)); }
  uint8_t variant(int64_t i, int64_t j) const {
    return uint8_t((latticeHash(i, j, seed, LatticeSalt::Appearance) >> 16) % uint64_t(atlasVariants));
  }
};

/// Per-patch arrays (row-major, patchesX per row). Static attributes are generated once; the
/// derived state is rewritten by the patch-state stage every tick.
template <class S>
struct PatchArrays {
  // static
  std::vector<S> rootX, rootY, rootZ;  ///< tuft root on the ground (m)
  std::vector<uint16_t> rotation;      ///< fraction of a turn, /65536
  std::vector<uint8_t> variant;        ///< atlas tuft variant; == atlasVariants: the white marking tuft
  std::vector<uint8_t> cut;            ///< 1 once a mower has cut the tuft (persistent world state)
  // derived (thesis §9.2.6)
  std::vector<S> tipOffsetX, tipOffsetZ;  ///< top-vertex x/z shift from the root (m)
  std::vector<S> topY;                    ///< top-vertex height: root + scaleY - smaller (m)
  std::vector<uint8_t> tiltLevel;         ///< 0..3: atlas brightness step (+4 per level)
};

}  // namespace sg
