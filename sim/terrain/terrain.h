// Ground height and normal: flat, or bilinear over an 8-bit heightmap. Deterministic in every
// scalar: positions map to cells by multiplying with the precomputed 1/cellSize, heights are the
// exact rounding of maxHeight * sample / 255. Outside the heightmap the edge samples extend.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "sim/math/scalar_ops.h"
#include "sim/scenario/derived.h"

namespace sg {

template <class S>
class Terrain {
 public:
  Terrain() = default;
  Terrain(const Scenario::Terrain& t, const ScenarioConstants& c);

  bool flat() const { return flat_; }
  /// Height (m) at world (x, z).
  S heightAt(S x, S z) const;
  /// Unit normal at world (x, z): the normalised (-dh/dx, 1, -dh/dz) of the bilinear patch.
  void normalAt(S x, S z, S* nx, S* ny, S* nz) const;
  /// World (x, z) of the heightmap samples within `radius` of (x, z) on both axes, row by row
  /// (none for a flat terrain).
  void samplesInside(S x, S z, S radius, std::vector<std::pair<S, S>>& out) const;

 private:
  struct Cell {
    int64_t ix, iz;                           // lower sample indices
    S tx, tz;                                 // in [0, 1]
    bool outsideX = false, outsideZ = false;  // beyond the map along that axis: the height is constant along it
  };
  Cell cellAt(S x, S z) const;
  S sample(int64_t ix, int64_t iz) const { return heights_[size_t(iz) * size_t(width_) + size_t(ix)]; }

  bool flat_ = true;
  S flatHeight_{};
  int64_t width_ = 0, depth_ = 0;
  S cellSize_{}, invCellSize_{}, originX_{}, originZ_{};
  /// Two cells beyond the map on each side: coordinates are clamped into [lo, hi] before they are
  /// scaled to cells, so the cell coordinate fits the scalar (in Q16.16 a point 16,000 m from a
  /// 0.25 m map's origin is 64,000 cells away, beyond its range) and beyond-the-edge stays so.
  S loX_{}, hiX_{}, loZ_{}, hiZ_{};
  std::vector<S> heights_;
};

}  // namespace sg
