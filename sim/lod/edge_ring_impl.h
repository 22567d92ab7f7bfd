// Implementation of sim/lod/edge_ring.h (header-only: follow() takes the world's cut lookup).
#pragma once

#include "sim/lod/edge_ring.h"
#include "sim/math/scalar_ops.h"

namespace sg {

template <class S>
void EdgeRing<S>::configure(const GrassLattice<S>& grass, int64_t m, int64_t r) {
  spacingMultiple = m;
  rows = r;
  lattice = grass;
  lattice.spacing = mulInt(grass.spacing, m);
  lattice.jitterAmplitude = mulInt(grass.jitterAmplitude, m);
  // Cell (a, b) covers grass patches [a m, a m + m): its tuft stands at the centre patch's point.
  lattice.originX = grass.originX + mulInt(grass.spacing, m / 2);
  lattice.originZ = grass.originZ + mulInt(grass.spacing, m / 2);
  lattice.seed = grass.seed ^ 0x6564676572696e67ull;  // "edgering": its own tufts, not a subset
  lattice.patchesX = (grass.patchesX + m - 1) / m;
  lattice.patchesZ = (grass.patchesZ + m - 1) / m;
  cells.fieldI = lattice.patchesX;
  cells.fieldJ = lattice.patchesZ;
}

template <class S>
template <class IsCut>
void EdgeRing<S>::follow(const LatticeWindow& window, const Terrain<S>& terrain, const FieldMarkings<S>& markings,
                         IsCut&& isCut, bool everything) {
  hole = window;
  if (rows <= 0) return;
  const int64_t m = spacingMultiple;
  const LatticeWindow before = cells;
  // The window's footprint in coarse cells, widened by R on every side (a square annulus: each
  // ring row is two cells longer than the one inside it, the thesis' 45-degree widening).
  cells.originI = window.originI / m - rows;  // window origins are never negative
  cells.originJ = window.originJ / m - rows;
  cells.sizeI = (window.sizeI + m - 1) / m + 1 + 2 * rows;
  cells.sizeJ = (window.sizeJ + m - 1) / m + 1 + 2 * rows;
  if (x.size() != size_t(cells.size())) {
    for (auto* v : {&x, &y, &z}) v->assign(size_t(cells.size()), S(0));
    rotation.assign(size_t(cells.size()), 0);
    variant.assign(size_t(cells.size()), 0);
    cut.assign(size_t(cells.size()), 0);
    everything = true;
  }
  if (!everything && cells.originI == before.originI && cells.originJ == before.originJ) return;
  for (int64_t r = 0; r < cells.sizeJ; ++r)
    forEachEnteringCell(cells, before, everything, r, [&](int64_t a, int64_t b) {
      const size_t q = cells.storageIndex(a, b);
      ++cellsWritten;
      if (!cells.insideField(a, b)) return;  // held but never drawn
      lattice.rootXZ(a, b, &x[q], &z[q]);
      y[q] = terrain.heightAt(x[q], z[q]);
      rotation[q] = lattice.rotation(a, b);
      variant[q] = lattice.variant(a, b);
      if (markings.onLine(lattice.originX + mulInt(lattice.spacing, a), lattice.originZ + mulInt(lattice.spacing, b)))
        variant[q] = uint8_t(lattice.atlasVariants);
      cut[q] = isCut(centrePatchI(a), centrePatchJ(b)) ? 1 : 0;
    });
}

template <class S>
std::vector<size_t> EdgeRing<S>::visibleCells() const {
  std::vector<size_t> out;
  if (rows <= 0) return out;
  for (int64_t b = cells.originJ; b < cells.endJ(); ++b)
    for (int64_t a = cells.originI; a < cells.endI(); ++a)
      if (visible(a, b)) out.push_back(cells.storageIndex(a, b));
  return out;
}

}  // namespace sg
