// Ground height and normal: flat, or triangles over an 8-bit heightmap. Each cell between four
// samples is split along its anti-diagonal, from sample (ix + 1, iz) to (ix, iz + 1) (the
// diagonal the viewer's ground mesh uses), so the ground is piecewise planar: a heightmap whose
// samples lie on a plane is that plane exactly, and every point has one face normal (no interior
// ghost normals; a bilinear patch is curved inside each cell). Deterministic in every scalar:
// positions map to cells by multiplying with the precomputed 1/cellSize, heights are the exact
// rounding of maxHeight * sample / 255. Outside the heightmap the edge samples extend.
#pragma once

#include <algorithm>
#include <cstdint>
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
  /// Unit normal at world (x, z): the normalised (-dh/dx, 1, -dh/dz) of the triangle there.
  void normalAt(S x, S z, S* nx, S* ny, S* nz) const;

  // Sample-index access for the narrow phase (sim/collision/terrain_contacts.cpp). Indices may
  // lie beyond the map: there the nearest edge sample's height extends, so the grid of vertices
  // (ix, iz) -> (sampleX(ix), heightOfSample(ix, iz), sampleZ(iz)) describes the whole ground.
  S cellSize() const { return cellSize_; }
  S invCellSize() const { return invCellSize_; }
  S sampleX(int64_t ix) const { return originX_ + mulInt(cellSize_, ix); }
  S sampleZ(int64_t iz) const { return originZ_ + mulInt(cellSize_, iz); }
  S heightOfSample(int64_t ix, int64_t iz) const {
    return sample(std::clamp<int64_t>(ix, 0, width_ - 1), std::clamp<int64_t>(iz, 0, depth_ - 1));
  }
  /// The cell column holding world x, for x within [lowX(), highX()] (the map and two cells around).
  int64_t cellX(S x) const { return floorToInt((x - originX_) * invCellSize_); }
  int64_t cellZ(S z) const { return floorToInt((z - originZ_) * invCellSize_); }
  /// The triangle holding world (x, z), by the rule heightAt uses (no clamping: for points within
  /// a few cells of [lowX(), highX()] x [lowZ(), highZ()]).
  void triangleAt(S x, S z, int64_t* ix, int64_t* iz, bool* lower) const {
    const S fx = (x - originX_) * invCellSize_, fz = (z - originZ_) * invCellSize_;
    *ix = floorToInt(fx);
    *iz = floorToInt(fz);
    *lower = fractionalPart(fx) + fractionalPart(fz) < S(1);
  }
  S lowX() const { return loX_; }
  S highX() const { return hiX_; }
  S lowZ() const { return loZ_; }
  S highZ() const { return hiZ_; }

 private:
  struct Cell {
    int64_t ix, iz;                           // lower sample indices
    S tx, tz;                                 // in [0, 1]; tx + tz <= 1: the lower triangle
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
