// Terrain: exact heights at the samples, two planar triangles per cell in between (split along
// the anti-diagonal), analytic normals on a plane, edge clamping, and patch roots on the ground.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <iterator>
#include <type_traits>
#include <utility>

#include "tests/test_support.h"

namespace sg {
namespace {

template <class S>
Terrain<S> terrainOf(const Scenario::Terrain& t) {
  Scenario s;
  s.terrain = t;
  return Terrain<S>(t, deriveConstants(s));
}

Scenario::Terrain rampTerrain(int w, int h) {
  Scenario::Terrain t;
  t.flat = false;
  t.cellSize = Rational{1, 2};
  t.maxHeight = Rational{51, 10};  // 5.1 m: sample value v gives v / 50 m
  t.heightmap.width = w;
  t.heightmap.height = h;
  for (int z = 0; z < h; ++z)
    for (int x = 0; x < w; ++x) t.heightmap.samples.push_back(uint8_t(4 * x + z));
  return t;
}

TEST(Terrain, ExactHeightsAtSamplesFx32) {
  Terrain<Fx32> t = terrainOf<Fx32>(rampTerrain(9, 5));
  // Sample (x, z) sits at ((x - 4) * 0.5, (z - 2) * 0.5): exactly representable.
  for (int z = 0; z < 5; ++z)
    for (int x = 0; x < 9; ++x) {
      const Fx32 wx = Fx32(x - 4) / Fx32(2), wz = Fx32(z - 2) / Fx32(2);
      const Fx32 expected = *ScalarTraits<Fx32>::fromRational(*mul(Rational{51, 10}, *Rational::make(4 * x + z, 255)));
      EXPECT_EQ(t.heightAt(wx, wz), expected) << x << "," << z;
    }
}

// One raised sample in a 3 x 3 map (cell 1 m, centred): the cell [0, 1] x [0, 1] (samples 1..2)
// has samples h00 = 0, h10 = 0, h01 = 0, h11 = 1 m. Split along 10-01, its lower triangle is the
// plane h = 0 and its upper the plane h = tx + tz - 1; a bilinear patch would give tx tz.
TEST(Terrain, EachCellIsTwoPlanarTrianglesDouble) {
  Scenario::Terrain m;
  m.flat = false;
  m.cellSize = Rational{1, 1};
  m.maxHeight = Rational{1, 1};
  m.heightmap.width = m.heightmap.height = 3;
  m.heightmap.samples = {0, 0, 0, 0, 0, 0, 0, 0, 255};
  Terrain<double> t = terrainOf<double>(m);
  for (double tx = 0.05; tx < 1; tx += 0.1)
    for (double tz = 0.05; tz < 1; tz += 0.1) {
      if (std::fabs(tx + tz - 1) < 1e-6) continue;  // on the diagonal: either face's normal
      const double expected = tx + tz < 1 ? 0.0 : tx + tz - 1;
      EXPECT_NEAR(t.heightAt(tx, tz), expected, 1e-12) << tx << "," << tz;
      double nx = 0, ny = 0, nz = 0;
      t.normalAt(tx, tz, &nx, &ny, &nz);
      const double s = tx + tz < 1 ? 0.0 : 1.0;  // the upper triangle rises 1 m per m along x and z
      EXPECT_NEAR(nx, -s / std::sqrt(1 + 2 * s * s), 1e-12);
      EXPECT_NEAR(ny, 1 / std::sqrt(1 + 2 * s * s), 1e-12);
      EXPECT_NEAR(nz, -s / std::sqrt(1 + 2 * s * s), 1e-12);
    }
  // Continuous across the diagonal and the cell edges.
  EXPECT_NEAR(t.heightAt(0.3, 0.7), 0.0, 1e-12);
  EXPECT_NEAR(t.heightAt(1.0, 0.5), 0.5, 1e-12);
  EXPECT_NEAR(t.heightAt(0.5, 1.0), 0.5, 1e-12);
}

TEST(Terrain, PlanarRampIsReproducedBetweenSamplesDouble) {
  Terrain<double> t = terrainOf<double>(rampTerrain(9, 5));
  // The ramp is linear (h = (4x + z) / 50 in sample units): the triangles reproduce it everywhere.
  for (double wx = -1.9; wx < 1.9; wx += 0.173)
    for (double wz = -0.9; wz < 0.9; wz += 0.131) {
      const double x = wx / 0.5 + 4, z = wz / 0.5 + 2;
      EXPECT_NEAR(t.heightAt(wx, wz), (4 * x + z) / 50.0, 1e-13);
    }
}

TEST(Terrain, NormalOfAPlane) {
  Terrain<double> td = terrainOf<double>(rampTerrain(9, 5));
  Terrain<Fx32> tf = terrainOf<Fx32>(rampTerrain(9, 5));
  // dh/dx = 4 / 50 / 0.5 = 0.16, dh/dz = 1 / 50 / 0.5 = 0.04.
  const double n = std::sqrt(0.16 * 0.16 + 1 + 0.04 * 0.04);
  double nx, ny, nz;
  td.normalAt(0.3, -0.2, &nx, &ny, &nz);
  EXPECT_NEAR(nx, -0.16 / n, 1e-14);
  EXPECT_NEAR(ny, 1 / n, 1e-14);
  EXPECT_NEAR(nz, -0.04 / n, 1e-14);
  Fx32 fx, fy, fz;
  tf.normalAt(Fx32::fromDouble(0.3), Fx32::fromDouble(-0.2), &fx, &fy, &fz);
  // A handful of roundings of 2^-33 each, then a division: 1e-8 is ~40 ulp of slack.
  EXPECT_NEAR(fx.toDouble(), -0.16 / n, 1e-8);
  EXPECT_NEAR(fy.toDouble(), 1 / n, 1e-8);
  EXPECT_NEAR(fz.toDouble(), -0.04 / n, 1e-8);
}

TEST(Terrain, EdgeSamplesExtendOutsideTheMap) {
  Terrain<double> t = terrainOf<double>(rampTerrain(9, 5));
  EXPECT_DOUBLE_EQ(t.heightAt(-100, -100), 0.0);
  EXPECT_NEAR(t.heightAt(100, 100), (4 * 8 + 4) / 50.0, 1e-14);
  EXPECT_NEAR(t.heightAt(-100, 0), 2 / 50.0, 1e-14);
}

// Beyond the map the edge samples extend, so the ground there is level along the axis it is
// beyond: the normal has no slope along it (it kept the edge cell's tilt, and a body resting beyond
// the edge slid away, issue 15). Along the edge the slope is kept; inside, nothing changes.
template <class S>
void expectNormalsBeyondTheEdge() {
  Terrain<S> t = terrainOf<S>(rampTerrain(9, 5));  // x in [-2, 2], z in [-1, 1]; dh/dx 0.16, dh/dz 0.04
  auto normal = [&](double x, double z) {
    S nx, ny, nz;
    auto at = [](double v) { return *ScalarTraits<S>::fromRational(*Rational::make(std::llround(v * 10), 10)); };
    t.normalAt(at(x), at(z), &nx, &ny, &nz);
    return std::array<double, 3>{ScalarTraits<S>::toDouble(nx), ScalarTraits<S>::toDouble(ny),
                                 ScalarTraits<S>::toDouble(nz)};
  };
  const double tol = std::is_same_v<S, Fx16> ? 2e-4 : 1e-6;                      // Q16.16: 1.5e-5 per rounding
  for (const auto& [x, z] : {std::pair{3.0, 5.0}, {-7.0, -3.0}, {3.0, -1.5}}) {  // beyond both axes: level
    const auto n = normal(x, z);
    EXPECT_NEAR(n[0], 0, tol) << x << "," << z;
    EXPECT_NEAR(n[1], 1, tol) << x << "," << z;
    EXPECT_NEAR(n[2], 0, tol) << x << "," << z;
  }
  const double along = std::sqrt(1 + 0.04 * 0.04), across = std::sqrt(1 + 0.16 * 0.16);
  const auto beyondX = normal(5.0, 0.3);  // beyond x only: the z slope of the edge row remains
  EXPECT_NEAR(beyondX[0], 0, tol);
  EXPECT_NEAR(beyondX[2], -0.04 / along, tol);
  const auto beyondZ = normal(0.3, -4.0);  // beyond z only: the x slope remains
  EXPECT_NEAR(beyondZ[0], -0.16 / across, tol);
  EXPECT_NEAR(beyondZ[2], 0, tol);
  const auto onLastSample = normal(2.0, 1.0);  // exactly on the last sample: still inside
  const double both = std::sqrt(1 + 0.16 * 0.16 + 0.04 * 0.04);
  EXPECT_NEAR(onLastSample[0], -0.16 / both, tol);
  EXPECT_NEAR(onLastSample[2], -0.04 / both, tol);
}
TEST(Terrain, NormalBeyondTheEdgeIsLevelAlongThatAxisDouble) { expectNormalsBeyondTheEdge<double>(); }
TEST(Terrain, NormalBeyondTheEdgeIsLevelAlongThatAxisFx32) { expectNormalsBeyondTheEdge<Fx32>(); }
TEST(Terrain, NormalBeyondTheEdgeIsLevelAlongThatAxisFx16) { expectNormalsBeyondTheEdge<Fx16>(); }

TEST(Terrain, FlatTerrain) {
  Scenario::Terrain flat;
  flat.flatHeight = Rational{3, 2};
  Terrain<Fx16> t = terrainOf<Fx16>(flat);
  EXPECT_EQ(t.heightAt(Fx16(100), Fx16(-7)), Fx16(3) / Fx16(2));
  Fx16 nx, ny, nz;
  t.normalAt(Fx16(0), Fx16(0), &nx, &ny, &nz);
  EXPECT_EQ(ny, Fx16(1));
}

TEST(Terrain, HillsPngDecodesAndRootsSitOnTheGround) {
  std::ifstream in(test::sourcePath("scenarios/hills.png"), std::ios::binary);
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Heightmap hm;
  std::string error;
  ASSERT_TRUE(decodeHeightmapPng(bytes, &hm, &error)) << error;
  EXPECT_EQ(hm.width, 129);
  EXPECT_EQ(hm.height, 129);

  Scenario s = loadScenarioFile(test::sourcePath("scenarios/hilly-meadow.json"));
  World<Fx32> w(s, 1);
  const auto& p = w.patches();
  double lo = 1e9, hi = -1e9;
  for (size_t i = 0; i < p.rootY.size(); ++i) {
    ASSERT_EQ(p.rootY[i], w.terrain().heightAt(p.rootX[i], p.rootZ[i]));
    lo = std::min(lo, p.rootY[i].toDouble());
    hi = std::max(hi, p.rootY[i].toDouble());
  }
  EXPECT_GT(hi - lo, 1.0) << "the meadow stands on hills";
  // Particles start at rest length above their anchors.
  const auto& q = w.particles();
  EXPECT_EQ(q.py[100] - q.anchorY[100], Fx32(1));
}

TEST(Lattice, PatchAttributesArePureFunctionsOfTheLatticeCoordinates) {
  Scenario s = test::thesisMeadow();
  World<Fx32> a(s, 1);
  GrassLattice<Fx32> lattice = a.lattice();
  // Regenerate patch (37, 91) on its own: identical to the stored one.
  Fx32 x, z;
  lattice.rootXZ(37, 91, &x, &z);
  const size_t q = size_t(91 * 151 + 37);
  EXPECT_EQ(x, a.patches().rootX[q]);
  EXPECT_EQ(z, a.patches().rootZ[q]);
  EXPECT_EQ(lattice.rotation(37, 91), a.patches().rotation[q]);
  EXPECT_EQ(lattice.variant(37, 91), a.patches().variant[q]);
  // Jitter stays inside +-0.3 * spacing and is not constant.
  double minJ = 1, maxJ = -1;
  for (int64_t i = 0; i < 151; ++i) {
    lattice.rootXZ(i, 3, &x, &z);
    const double jitter = x.toDouble() - (lattice.originX.toDouble() + 0.25 * double(i));
    minJ = std::min(minJ, jitter);
    maxJ = std::max(maxJ, jitter);
  }
  EXPECT_GE(minJ, -0.075);
  EXPECT_LE(maxJ, 0.075);
  EXPECT_GT(maxJ - minJ, 0.1);
  // A different seed gives a different meadow.
  s.seed = 2;
  World<Fx32> b(s, 1);
  EXPECT_NE(a.patches().rootX[q], b.patches().rootX[q]);
}

}  // namespace
}  // namespace sg
