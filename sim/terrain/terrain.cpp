#include "sim/terrain/terrain.h"

#include <algorithm>

namespace sg {
namespace {
template <class S>
S exact(const Rational& r) {
  return *ScalarTraits<S>::fromRational(r);  // range validated by validateForScalar
}
}  // namespace

template <class S>
Terrain<S>::Terrain(const Scenario::Terrain& t, const ScenarioConstants& c)
    : flat_(t.flat), flatHeight_(exact<S>(t.flatHeight)) {
  if (flat_) return;
  width_ = t.heightmap.width;
  depth_ = t.heightmap.height;
  cellSize_ = exact<S>(t.cellSize);
  invCellSize_ = exact<S>(c.terrainInvCellSize);
  originX_ = exact<S>(c.terrainOriginX);  // sample (0, 0) sits at centre - cellSize * (n - 1) / 2
  originZ_ = exact<S>(c.terrainOriginZ);
  loX_ = originX_ - mulInt(cellSize_, 2);
  hiX_ = originX_ + mulInt(cellSize_, width_ + 1);
  loZ_ = originZ_ - mulInt(cellSize_, 2);
  hiZ_ = originZ_ + mulInt(cellSize_, depth_ + 1);
  S table[256];
  for (int v = 0; v < 256; ++v) table[v] = exact<S>(c.terrainHeightOfSample[size_t(v)]);
  heights_.resize(t.heightmap.samples.size());
  for (size_t i = 0; i < heights_.size(); ++i) heights_[i] = table[t.heightmap.samples[i]];
}

template <class S>
typename Terrain<S>::Cell Terrain<S>::cellAt(S x, S z) const {
  const S fx = (std::clamp(x, loX_, hiX_) - originX_) * invCellSize_;
  const S fz = (std::clamp(z, loZ_, hiZ_) - originZ_) * invCellSize_;
  Cell c{floorToInt(fx), floorToInt(fz), fractionalPart(fx), fractionalPart(fz)};
  // Clamp outside the map: the edge sample extends (t = 0 at the low edge, t = 1 at the high).
  if (c.ix < 0) {
    c.ix = 0;
    c.tx = S(0);
    c.outsideX = true;
  }
  if (c.iz < 0) {
    c.iz = 0;
    c.tz = S(0);
    c.outsideZ = true;
  }
  if (c.ix > width_ - 2) {
    c.outsideX = c.ix > width_ - 1 || c.tx > S(0);  // exactly on the last sample is still inside
    c.ix = width_ - 2;
    c.tx = S(1);
  }
  if (c.iz > depth_ - 2) {
    c.outsideZ = c.iz > depth_ - 1 || c.tz > S(0);
    c.iz = depth_ - 2;
    c.tz = S(1);
  }
  return c;
}

template <class S>
S Terrain<S>::heightAt(S x, S z) const {
  if (flat_) return flatHeight_;
  const Cell c = cellAt(x, z);
  const S h00 = sample(c.ix, c.iz), h10 = sample(c.ix + 1, c.iz);
  const S h01 = sample(c.ix, c.iz + 1), h11 = sample(c.ix + 1, c.iz + 1);
  // The lower triangle (00, 01, 10) from sample 00, the upper (10, 01, 11) from sample 11: on
  // the diagonal both give the same height (it lies on the edge 10-01 of both).
  if (c.tx + c.tz < S(1)) return h00 + (h10 - h00) * c.tx + (h01 - h00) * c.tz;
  return h11 + (h01 - h11) * (S(1) - c.tx) + (h10 - h11) * (S(1) - c.tz);
}

template <class S>
void Terrain<S>::normalAt(S x, S z, S* nx, S* ny, S* nz) const {
  if (flat_) {
    *nx = S(0);
    *ny = S(1);
    *nz = S(0);
    return;
  }
  const Cell c = cellAt(x, z);
  const S h00 = sample(c.ix, c.iz), h10 = sample(c.ix + 1, c.iz);
  const S h01 = sample(c.ix, c.iz + 1), h11 = sample(c.ix + 1, c.iz + 1);
  // Lower iff tx + tz < 1, as heightAt. Beyond the high edge t = 1, so the upper triangle: its
  // slope along that edge is the edge's own (the lower one's would be the previous column's).
  const bool lower = c.tx + c.tz < S(1);
  // Beyond the map along an axis the edge samples extend, so the height does not change along
  // it: that slope is 0 (the edge cell's slope there tilted the normal of flat ground, and a body
  // resting beyond the edge slid away).
  const S dhdx = c.outsideX ? S(0) : (lower ? h10 - h00 : h11 - h01) * invCellSize_;
  const S dhdz = c.outsideZ ? S(0) : (lower ? h01 - h00 : h11 - h10) * invCellSize_;
  const S len = length3(dhdx, S(1), dhdz);
  *nx = -dhdx / len;
  *ny = S(1) / len;
  *nz = -dhdz / len;
}

template class Terrain<Fx32>;
template class Terrain<Fx16>;
template class Terrain<float>;
template class Terrain<double>;
}  // namespace sg
