// Level-of-detail level 1: the edge-grass ring (thesis §3). Static tufts on a lattice `m` times
// coarser than the grass, `rows` cells deep around the simulated window, so the meadow does not
// end where the simulation does. Beyond it lies level 2, the bare terrain.
//
// The thesis stored four sides of row lists and rebuilt them in four steps on every shift. Here
// the ring is one toroidal window of coarse cells (sim/lod/lattice_window.h) around the
// simulation window's footprint: a shift rewrites only the coarse row or column that enters, so
// its cost is one ring row, whatever the number of rows already there. The hole (cells whose
// centre lies in the simulated window) is not stored but tested, so it moves for free.
// Plain data for the renderer: no GL here. Not part of the state (a function of the window).
#pragma once

#include <cstdint>
#include <vector>

#include "sim/field/grass_field.h"
#include "sim/field/markings.h"
#include "sim/lod/lattice_window.h"
#include "sim/terrain/terrain.h"

namespace sg {

template <class S>
struct EdgeRing {
  int64_t spacingMultiple = 4;  ///< m: coarse cell = m x m grass patches
  int64_t rows = 30;            ///< R: coarse cells around the window's footprint
  GrassLattice<S> lattice;      ///< the coarse lattice (its own seed; tuft at the cell centre)
  LatticeWindow cells;          ///< coarse cells held; fieldI/J: coarse cells over the field
  LatticeWindow hole;           ///< the simulated patch window (fine lattice)
  // Per held cell, in the toroidal storage order of `cells`:
  std::vector<S> x, y, z;          ///< tuft root (m)
  std::vector<uint16_t> rotation;  ///< fraction of a turn, /65536
  std::vector<uint8_t> variant;    ///< atlas tuft variant (== atlasVariants: marking tuft)
  std::vector<uint8_t> cut;        ///< 1 where the grass patch at the cell centre was mown when the cell entered
  int64_t cellsWritten = 0;        ///< cells (re)generated since construction (benchmarks, tests)

  /// Sets the coarse lattice from the grass lattice; `rows` = 0 disables the ring.
  void configure(const GrassLattice<S>& grass, int64_t spacingMultiple, int64_t rows);
  /// Follows the simulation window `window` (fine patches): regenerates the cells that enter.
  template <class IsCut>
  void follow(const LatticeWindow& window, const Terrain<S>& terrain, const FieldMarkings<S>& markings, IsCut&& isCut,
              bool everything);
  /// The grass patch at the centre of coarse cell (a, b).
  int64_t centrePatchI(int64_t a) const { return a * spacingMultiple + spacingMultiple / 2; }
  int64_t centrePatchJ(int64_t b) const { return b * spacingMultiple + spacingMultiple / 2; }
  /// Drawn: inside the field and not covered by the simulated window.
  bool visible(int64_t a, int64_t b) const {
    return cells.insideField(a, b) && !hole.contains(centrePatchI(a), centrePatchJ(b)) &&
           centrePatchI(a) < hole.fieldI && centrePatchJ(b) < hole.fieldJ;
  }
  /// Storage indices of the visible cells, row by row (for renderers and tests).
  std::vector<size_t> visibleCells() const;
};

}  // namespace sg

#include "sim/lod/edge_ring_impl.h"
