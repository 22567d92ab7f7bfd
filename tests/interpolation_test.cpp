// Interpolation (one particle per k x k patches): owners match their particle exactly, the others
// equal the bilinear blend of the four particles around them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>

#include "tests/test_support.h"

namespace sg {
namespace {

template <class S>
double d(S v) {
  return ScalarTraits<S>::toDouble(v);
}

template <class S>
void checkInterpolation(int k, int64_t nx, int64_t nz, double tolerance) {
  Scenario s = test::thesisMeadow();
  s.field.patchesX = nx;
  s.field.patchesZ = nz;
  s.particles.interpolation = k;
  s.wind.travelSpeed = Rational{1, 2};  // slow gust: neighbouring rows differ a lot
  s.scalar = ScalarTraits<S>::kind;
  World<S> w(s, 1);
  for (int t = 0; t < 90; ++t) ASSERT_TRUE(w.step(TickInput{}).ok);
  const auto& p = w.particles();
  const auto& patches = w.patches();
  const ParticleGrid& g = w.particleGrid();
  EXPECT_EQ(g.countX, (nx - 1 + k - 1) / k + 1);
  const S rod = w.particleConstants().rodLength;
  auto disp = [&](int64_t a, int64_t b, int c) {
    const size_t q = size_t(b * g.countX + a);
    if (c == 0) return d(p.px[q] - p.anchorX[q]);
    if (c == 1) return d(p.py[q] - p.anchorY[q] - rod);
    return d(p.pz[q] - p.anchorZ[q]);
  };
  int owners = 0, blended = 0;
  double moved = 0;
  for (int64_t j = 0; j < nz; ++j) {
    for (int64_t i = 0; i < nx; ++i) {
      const size_t q = size_t(j * nx + i);
      const int64_t a = i / k, b = j / k;
      if (i % k == 0 && j % k == 0) {
        // Exactly the particle's displacement, not merely close.
        const size_t pi = size_t(b * g.countX + a);
        EXPECT_EQ(patches.tipOffsetX[q], p.px[pi] - p.anchorX[pi]) << i << "," << j;
        EXPECT_EQ(patches.tipOffsetZ[q], p.pz[pi] - p.anchorZ[pi]) << i << "," << j;
        ++owners;
        continue;
      }
      const double tx = double(i % k) / k, tz = double(j % k) / k;
      for (int c : {0, 2}) {
        const double v00 = disp(a, b, c), v10 = tx > 0 ? disp(a + 1, b, c) : v00;
        const double v01 = tz > 0 ? disp(a, b + 1, c) : v00;
        const double v11 = tx > 0 && tz > 0 ? disp(a + 1, b + 1, c) : (tx > 0 ? v10 : v01);
        const double expected = (1 - tx) * (1 - tz) * v00 + tx * (1 - tz) * v10 + (1 - tx) * tz * v01 + tx * tz * v11;
        const double got = d(c == 0 ? patches.tipOffsetX[q] : patches.tipOffsetZ[q]);
        EXPECT_NEAR(got, expected, tolerance) << "patch " << i << "," << j << " component " << c;
        moved = std::max(moved, std::fabs(expected));
      }
      ++blended;
    }
  }
  EXPECT_GT(owners, 0);
  if (k == 1) {
    EXPECT_EQ(owners, nx * nz) << "with k = 1 every patch owns its particle";
    return;
  }
  EXPECT_GT(blended, 0);
  EXPECT_GT(moved, 0.05) << "the wind must have bent the tufts for this test to mean anything";
}

// Tolerances: the blend is two lerps (z then x), each a subtraction, a product rounded once and
// an addition; weights t/k are exact for k = 2, 4 and rounded (1/2 ulp) for k = 3. Displacements
// are below 1 m, so the error stays within a few ulp: 8 ulp allowed.
TEST(Interpolation, K2Fx32) { checkInterpolation<Fx32>(2, 21, 17, 8.0 / 4294967296.0); }
TEST(Interpolation, K3Fx32) { checkInterpolation<Fx32>(3, 22, 20, 8.0 / 4294967296.0); }
TEST(Interpolation, K4Fx32) { checkInterpolation<Fx32>(4, 25, 19, 8.0 / 4294967296.0); }
TEST(Interpolation, K2Fx16) { checkInterpolation<Fx16>(2, 21, 17, 8.0 / 65536.0); }
TEST(Interpolation, K3Double) { checkInterpolation<double>(3, 22, 20, 1e-14); }
TEST(Interpolation, K1IsIdentity) { checkInterpolation<Fx32>(1, 9, 9, 0.0); }

TEST(PatchState, SmallerCapAndTiltLevelsFollowTheThesis) {
  Scenario s = test::thesisMeadow();
  s.field.patchesX = 5;
  s.field.patchesZ = 1;
  s.wind.schedule.clear();
  World<double> w(s, 1);
  auto& p = w.mutableParticles();
  // Sink the tips by 0.1, 0.25, 0.35, 0.45 and 0.9 m (moving x keeps the rod length irrelevant
  // here: patch state reads positions, not lengths).
  const double sink[5] = {0.1, 0.25, 0.35, 0.45, 0.9};
  for (int i = 0; i < 5; ++i) p.py[size_t(i)] = p.anchorY[size_t(i)] + 1.0 - sink[i];
  w.updatePatchState();
  const int expectedTilt[5] = {0, 1, 2, 3, 3};
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(w.patches().tiltLevel[size_t(i)], expectedTilt[i]) << "sink " << sink[i];
    const double smaller = std::min(sink[i], 0.5);  // capped at L / 2
    EXPECT_NEAR(w.patches().topY[size_t(i)], w.patches().rootY[size_t(i)] + 1.0 - smaller, 1e-15);
  }
}

}  // namespace
}  // namespace sg

namespace sg {
namespace {

// The patch stage runs k = 2 and 4 with compile-time weights (sim/patches/patch_state.h): it
// must give the same bits as the generic row with runtime weights, in every scalar and in a
// wrapped level-of-detail window (rows and columns stored toroidally).
// `window` = false: the same check on the whole field (no toroidal wrap), for every k.
template <class S>
void checkConstantWeightRowsMatchGeneric(int k, bool window = true) {
  Scenario s = test::thesisMeadow();
  s.field.patchesX = window ? 161 : 401;
  s.field.patchesZ = window ? 145 : 401;
  s.particles.interpolation = k;
  s.wind.travelSpeed = Rational{1, 2};
  s.scalar = ScalarTraits<S>::kind;
  s.lod.mode = window ? LodMode::Window : LodMode::Off;
  s.lod.windowX = 15;  // particles
  s.lod.windowZ = 13;
  World<S> w(s, 1);
  TickInput in;
  in.hasCamera = true;
  for (int t = 0; t < 60; ++t) {
    in.camera = InputVec3{int64_t(t % 30) << 30, 0, int64_t(t % 25) << 29};  // drags the window around
    ASSERT_TRUE(w.step(in).ok);
  }
  if (window) {
    ASSERT_TRUE(w.patchWindow().originI != 0 || w.patchWindow().originJ != 0) << "the window must have moved";
  }
  // Inputs of the row function, as the world's patch stage sees them.
  const auto& p = w.particles();
  const ParticleGrid& g = w.particleGrid();
  const S rod = w.particleConstants().rodLength;
  std::vector<S> dx(size_t(g.size())), dy(dx), dz(dx);
  particleDisplacement(p, 0, g.size(), rod, dx, dy, dz);
  PatchStateConstants<S> c;
  c.k = k;
  for (int t = 0; t < k; ++t) c.weight.push_back(*ScalarTraits<S>::fromRational(*Rational::make(t, k)));
  c.rodLength = rod;
  c.halfRod = rod / S(2);
  c.scaleY = S(1);
  c.minimumTop = S(0);
  const bool constantWeights = k == 2 || k == 4;
  ASSERT_EQ(rowWeightsAreExact(c), constantWeights);
  const LatticeWindow& pw = w.patchWindow();
  PatchArrays<S> generic = w.patches(), constant = w.patches();
  std::vector<S> scratch(size_t(3 * (g.countX + pw.sizeI)));
  int64_t compared = 0;
  if (k == 1) {  // patches are particles: the checked writer straight over them
    const PatchWriter<S> out(generic, c);
    for (int64_t q = 0; q < g.size(); ++q) out.write(size_t(q), dx[size_t(q)], dy[size_t(q)], dz[size_t(q)]);
    constant = generic;
    compared = g.size();
  }
  for (int64_t j = pw.originJ; k > 1 && j < pw.originJ + pw.sizeJ; ++j) {
    updatePatchRow<S>(generic, pw, j, g.window, dx, dy, dz, c, scratch.data());
    if (k == 2)
      updatePatchRow<S, 2>(constant, pw, j, g.window, dx, dy, dz, c, scratch.data());
    else if (k == 4)
      updatePatchRow<S, 4>(constant, pw, j, g.window, dx, dy, dz, c, scratch.data());
    else
      updatePatchRow<S>(constant, pw, j, g.window, dx, dy, dz, c, scratch.data());
    compared += pw.sizeI;
  }
  EXPECT_EQ(compared, pw.sizeI * pw.sizeJ);
  EXPECT_TRUE(generic.tipOffsetX == constant.tipOffsetX);
  EXPECT_TRUE(generic.tipOffsetZ == constant.tipOffsetZ);
  EXPECT_TRUE(generic.topY == constant.topY);
  EXPECT_TRUE(generic.tiltLevel == constant.tiltLevel);
  // And the world's own patch stage produced the same tips (it picks the constant path).
  EXPECT_TRUE(generic.tipOffsetX == w.patches().tipOffsetX);
  EXPECT_TRUE(generic.tipOffsetZ == w.patches().tipOffsetZ);
}

TEST(PatchState, ConstantWeightRowsGiveTheGenericBitsK2Fx32) { checkConstantWeightRowsMatchGeneric<Fx32>(2); }
TEST(PatchState, ConstantWeightRowsGiveTheGenericBitsK4Fx32) { checkConstantWeightRowsMatchGeneric<Fx32>(4); }
TEST(PatchState, ConstantWeightRowsGiveTheGenericBitsK2Fx16) { checkConstantWeightRowsMatchGeneric<Fx16>(2); }
TEST(PatchState, ConstantWeightRowsGiveTheGenericBitsK4Double) { checkConstantWeightRowsMatchGeneric<double>(4); }
TEST(PatchState, ConstantWeightRowsGiveTheGenericBitsK2Float) { checkConstantWeightRowsMatchGeneric<float>(2); }
TEST(PatchState, WholeFieldPatchRowsGiveTheGenericBitsForEveryK) {
  for (int k : {1, 2, 3, 4}) checkConstantWeightRowsMatchGeneric<Fx32>(k, false);
  checkConstantWeightRowsMatchGeneric<Fx16>(2, false);
  checkConstantWeightRowsMatchGeneric<double>(3, false);
}

}  // namespace
}  // namespace sg

namespace sg {
namespace {

// The patch stage's unchecked arithmetic must give Fixed's bits for every input, including the
// ones that overflow (Fixed wraps them too; the patch stage never reports faults).
template <class S, int K>
void checkUncheckedLerp() {
  using Raw = typename S::RawType;
  std::vector<Raw> values = {0,
                             1,
                             -1,
                             2,
                             -2,
                             3,
                             -3,
                             5,
                             -5,
                             std::numeric_limits<Raw>::max(),
                             std::numeric_limits<Raw>::min(),
                             Raw(std::numeric_limits<Raw>::max() - 1),
                             Raw(std::numeric_limits<Raw>::min() + 1),
                             S::kOneRaw,
                             Raw(-S::kOneRaw),
                             Raw(S::kOneRaw / 2 + 1),
                             Raw(-(S::kOneRaw / 2) - 1)};
  uint64_t x = 0x9E3779B97F4A7C15ull;  // splitmix64: a fixed, reproducible set of random values
  for (int i = 0; i < 4000; ++i) {
    x += 0x9E3779B97F4A7C15ull;
    uint64_t z = x;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    values.push_back(Raw(z >> (i % 3 == 0 ? 0 : (i % 3 == 1 ? 20 : 40)) % (uint64_t(1) << (sizeof(Raw) * 8 - 1))) *
                     (i % 2 ? Raw(-1) : Raw(1)));
  }
  int64_t checked = 0;
  for (size_t i = 0; i < values.size(); ++i) {
    const S a = S::fromRaw(values[i]);
    const S b = S::fromRaw(values[(i * 7 + 3) % values.size()]);
    for (int t = 1; t < K; ++t) {
      const S reference = lerp(a, b, powerOfTwoWeight<S, K>(t));
      const S fast = unchecked::lerpByFraction<S, K>(a, b, t);
      ASSERT_EQ(fast.raw(), reference.raw()) << "a " << a.raw() << " b " << b.raw() << " t " << t << "/" << K;
      ++checked;
    }
  }
  takeFixedFaults();  // the reference raised overflow faults on the extreme values, as it should
  EXPECT_GT(checked, 4000);
}

TEST(PatchState, UncheckedLerpIsFixedLerpBitForBit) {
  checkUncheckedLerp<Fx32, 2>();
  checkUncheckedLerp<Fx32, 4>();
  checkUncheckedLerp<Fx16, 2>();
  checkUncheckedLerp<Fx16, 4>();
}

template <class S>
void checkUncheckedWriter() {
  using Raw = typename S::RawType;
  PatchArrays<S> a, b;
  const size_t n = 600;
  for (PatchArrays<S>* p : {&a, &b}) {
    for (auto* v : {&p->tipOffsetX, &p->tipOffsetZ, &p->topY, &p->rootY}) v->assign(n, S(0));
    p->tiltLevel.assign(n, 0);
    p->cut.assign(n, 0);
  }
  PatchStateConstants<S> c;
  c.halfRod = S::fromRaw(S::kOneRaw / 2);
  c.scaleY = S(1);
  c.cutReduction = S::fromRaw(S::kOneRaw / 5);
  c.minimumTop = S::fromRaw(S::kOneRaw / 10);
  c.drop[0] = S::fromRaw(S::kOneRaw / 5);
  c.drop[1] = S::fromRaw(S::kOneRaw * 3 / 10);
  c.drop[2] = S::fromRaw(S::kOneRaw * 2 / 5);
  const Raw extremes[] = {std::numeric_limits<Raw>::max(), std::numeric_limits<Raw>::min(), 0, 1, -1};
  for (size_t q = 0; q < n; ++q) {
    const Raw root = q % 50 == 0 ? extremes[(q / 50) % 5] : Raw((int64_t(q) - 300) * (S::kOneRaw / 97));
    a.rootY[q] = b.rootY[q] = S::fromRaw(root);
    a.cut[q] = b.cut[q] = uint8_t(q % 3 == 0);
  }
  const PatchWriter<S> wa(a, c), wb(b, c);
  for (size_t q = 0; q < n; ++q) {
    // Sweep the sink through every tilt band and the clamps, with extremes mixed in.
    const Raw dy = q % 37 == 0 ? extremes[(q / 37) % 5] : Raw((int64_t(q) - 400) * (S::kOneRaw / 300));
    const S ddx = S::fromRaw(Raw(q)), ddz = S::fromRaw(Raw(-Raw(q)));
    wa.write(q, ddx, S::fromRaw(dy), ddz);
    wb.writeFast(q, ddx, S::fromRaw(dy), ddz);
  }
  takeFixedFaults();
  EXPECT_TRUE(a.topY == b.topY);
  EXPECT_TRUE(a.tiltLevel == b.tiltLevel);
  EXPECT_TRUE(a.tipOffsetX == b.tipOffsetX && a.tipOffsetZ == b.tipOffsetZ);
  std::set<uint8_t> levels(a.tiltLevel.begin(), a.tiltLevel.end());
  EXPECT_EQ(levels.size(), 4u) << "the sweep must reach every tilt level";
}

TEST(PatchState, UncheckedWriterIsTheCheckedWriterBitForBit) {
  checkUncheckedWriter<Fx32>();
  checkUncheckedWriter<Fx16>();
}

}  // namespace
}  // namespace sg
