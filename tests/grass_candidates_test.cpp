// The grass push's height marks (sim/collision/grass_candidates.h) are a filter only: the AVX2
// marks equal the reference's, and pushing with marks gives the same particles, the same push
// counts and the same fault report as testing every candidate, in Fx32 and Fx16, for random
// bodies lying in random grass (pushes that carry a particle into a later body's band included),
// and for bodies and particles beyond a quarter of the range (where the reference's y difference
// may overflow).
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <vector>

#include "sim/collision/body_particles.h"
#include "sim/collision/grass_candidates.h"
#include "tests/test_support.h"

namespace sg {
namespace {

using test::r3;

/// A raw height: near the band's edges, near the bound, at the extremes, or anywhere.
template <class S>
S pickHeight(const HeightBand<S>& band) {
  using Raw = typename HeightBand<S>::Raw;
  const Raw bound = HeightBand<S>::kBound;
  const std::vector<Raw> edges = {
      band.bottom, band.top, bound, Raw(-bound), std::numeric_limits<Raw>::max(), std::numeric_limits<Raw>::min(), 0};
  const int kind = *rc::gen::inRange(0, 3);
  if (kind == 0) return S::fromRaw(*rc::gen::arbitrary<Raw>());
  const Raw edge = *rc::gen::elementOf(edges);
  const int offset = *rc::gen::inRange(-2, 3);
  Raw out;
  if (__builtin_add_overflow(edge, Raw(offset), &out)) out = edge;
  return S::fromRaw(out);
}

template <class S>
void marksEqualTheReference() {
  using Raw = typename HeightBand<S>::Raw;
  HeightBand<S> band;
  const int parts = *rc::gen::inRange(1, 4);
  for (int k = 0; k < parts; ++k) {
    const bool far = *rc::gen::inRange(0, 10) == 0;
    const Raw cy = far ? *rc::gen::arbitrary<Raw>() : *rc::gen::inRange<Raw>(-(Raw(1) << 20), Raw(1) << 20);
    const Raw reach = far ? *rc::gen::arbitrary<Raw>() : *rc::gen::inRange<Raw>(1, Raw(1) << 18);
    band.add(S::fromRaw(cy), S::fromRaw(reach));
  }
  const int n = *rc::gen::inRange(0, 300);
  std::vector<S> py(static_cast<size_t>(n));
  for (S& y : py) y = pickHeight(band);
  std::vector<uint64_t> vector(size_t((n + 63) / 64) + 1, 0xAAAA), scalar = vector;
  markHeightBand(py.data(), n, band, ParticleKernel::Avx2, vector.data());
  markHeightBand(py.data(), n, band, ParticleKernel::Scalar, scalar.data());
  for (int k = 0; k < n; ++k) {
    const bool expected = band.marks(py[size_t(k)]);
    RC_ASSERT(((vector[size_t(k / 64)] >> (k % 64)) & 1) == uint64_t(expected));
    RC_ASSERT(((scalar[size_t(k / 64)] >> (k % 64)) & 1) == uint64_t(expected));
  }
  RC_ASSERT(vector.back() == uint64_t(0xAAAA));  // nothing written past the row's words
  if (!band.everything) {
    // The open band holds exactly the heights strictly between its ends (within the bound).
    RC_ASSERT(band.marks(S::fromRaw(band.bottom + 1)) == (band.bottom + 1 < band.top));
    RC_ASSERT(!band.marks(S::fromRaw(band.bottom)) || band.bottom < -HeightBand<S>::kBound);
  }
}

RC_GTEST_PROP(GrassCandidates, Fx32MarksEqualTheReference, ()) { marksEqualTheReference<Fx32>(); }
RC_GTEST_PROP(GrassCandidates, Fx16MarksEqualTheReference, ()) { marksEqualTheReference<Fx16>(); }

template <class S>
void reachMaskIsTheReference() {
  using Raw = typename HeightBand<S>::Raw;
  // Coordinates near a centre (small raw offsets: every comparison's edge), or anywhere (overflow).
  // (RapidCheck sizes arbitrary integers small; a full-range raw value comes from its bytes.)
  const auto anyRaw = [] {
    return Raw(*rc::gen::inRange<int64_t>(std::numeric_limits<Raw>::min(), std::numeric_limits<Raw>::max()));
  };
  const auto coordinate = [&](Raw centre) {
    if (*rc::gen::inRange(0, 16) == 0) return S::fromRaw(anyRaw());
    Raw out;
    if (__builtin_add_overflow(centre, *rc::gen::inRange<Raw>(-40, 40), &out)) out = centre;
    return S::fromRaw(out);
  };
  const Raw cx = anyRaw() / 2, cy = anyRaw() / 2, cz = anyRaw() / 2;
  const S reach = S::fromRaw(*rc::gen::inRange<Raw>(0, 45));
  const int n = *rc::gen::inRange(0, 65);
  std::vector<S> px, py, pz;
  for (int k = 0; k < n; ++k) {
    px.push_back(coordinate(cx));
    py.push_back(coordinate(cy));
    pz.push_back(coordinate(cz));
  }
  const Vec3<S> c(S::fromRaw(cx), S::fromRaw(cy), S::fromRaw(cz));
  uint64_t mask = 0x5A5A;
  takeFixedFaults();
  const bool answered = withinReachMask(px.data(), py.data(), pz.data(), n, c, reach, &mask);
  RC_ASSERT(takeFixedFaults() == 0u);  // the kernel never raises a fault itself
  RC_TAG(answered ? "answered" : "declined");
  if (!answered) {
    RC_ASSERT(mask == uint64_t(0x5A5A));
    return;
  }
  for (int k = 0; k < n; ++k) {
    const size_t i = size_t(k);
    const bool expected = withinReach(px[i], py[i], pz[i], c.x(), c.y(), c.z(), reach);
    RC_ASSERT(takeFixedFaults() == 0u);  // answered: the reference raises no fault either
    RC_ASSERT(((mask >> k) & 1) == uint64_t(expected));
  }
  // Decided before RC_ASSERT: its expression capture evaluates both sides of ||, and a shift by
  // 64 is undefined (UBSan caught it on a seed with n = 64).
  const bool nothingAbove = n == 64 || (mask >> n) == 0;
  RC_ASSERT(nothingAbove);
}

RC_GTEST_PROP(GrassCandidates, Fx32ReachMaskIsTheReference, ()) { reachMaskIsTheReference<Fx32>(); }
RC_GTEST_PROP(GrassCandidates, Fx16ReachMaskIsTheReference, ()) { reachMaskIsTheReference<Fx16>(); }

// The push's surface test without the square root (fixed.h length3AtLeast) is length3 >= r: on
// points within a few raw units of the sphere (where the rounding decides) and anywhere within a
// quarter of the range.
template <class S>
void lengthTestIsTheReference() {
  using Raw = typename HeightBand<S>::Raw;
  const Raw quarter = HeightBand<S>::kBound;
  const bool small = *rc::gen::arbitrary<bool>();
  const Raw r = *rc::gen::inRange<Raw>(1, small ? 4096 : quarter);
  const auto any = [&] { return *rc::gen::inRange<Raw>(-r, r + 1); };
  const Raw x = any(), y = any();
  const double rest = double(r) * double(r) - double(r) - double(x) * double(x) - double(y) * double(y);
  Raw z = rest > 0 ? Raw(std::sqrt(rest)) : 0;
  const Raw jitter = *rc::gen::inRange<Raw>(-3, 4);
  z = *rc::gen::inRange(0, 4) == 0 ? any() : (z > quarter - 3 ? z : z + jitter);
  const S sx = S::fromRaw(x), sy = S::fromRaw(y), sz = S::fromRaw(z), sr = S::fromRaw(r);
  takeFixedFaults();
  const bool reference = length3(sx, sy, sz) >= sr;
  RC_ASSERT(takeFixedFaults() == 0u);
  RC_ASSERT(length3AtLeast(sx, sy, sz, sr) == reference);
  RC_TAG(reference ? "outside" : "inside");
}

RC_GTEST_PROP(GrassCandidates, Fx32SurfaceTestIsLength3, ()) { lengthTestIsTheReference<Fx32>(); }
RC_GTEST_PROP(GrassCandidates, Fx16SurfaceTestIsLength3, ()) { lengthTestIsTheReference<Fx16>(); }

// Every point of the cube around small radii (raw units), where sums of squares land exactly on
// r^2 - r, the edge the rounding decides.
TEST(GrassCandidates, SurfaceTestIsLength3AtEverySmallPoint) {
  int64_t onTheEdge = 0;
  for (int32_t r = 1; r <= 16; ++r)
    for (int32_t x = -r; x <= r; ++x)
      for (int32_t y = -r; y <= r; ++y)
        for (int32_t z = -r; z <= r; ++z) {
          const Fx32 a = Fx32::fromRaw(x), b = Fx32::fromRaw(y), c = Fx32::fromRaw(z), radius = Fx32::fromRaw(r);
          const Fx16 a16 = Fx16::fromRaw(x), b16 = Fx16::fromRaw(y), c16 = Fx16::fromRaw(z), r16 = Fx16::fromRaw(r);
          ASSERT_EQ(length3AtLeast(a, b, c, radius), length3(a, b, c) >= radius)
              << r << " " << x << " " << y << " " << z;
          ASSERT_EQ(length3AtLeast(a16, b16, c16, r16), length3(a16, b16, c16) >= r16);
          onTheEdge += x * x + y * y + z * z == r * r - r;
        }
  EXPECT_GT(onTheEdge, 100) << "the sweep reaches the rounding edge";
}

/// A 24 x 24-tuft meadow with four bodies (two spheres, two boxes) whose poses each case sets.
Scenario smallMeadowWithBodies() {
  Scenario s = test::thesisMeadow();
  s.field.patchesX = s.field.patchesZ = 24;
  s.wind.schedule.clear();
  for (int k = 0; k < 4; ++k) {
    BodySpec b;
    b.name = "body";
    b.name += std::to_string(k);
    ShapeSpec p;
    p.type = k % 2 == 0 ? ShapeType::Sphere : ShapeType::Box;
    p.radius = Rational{3, 10};
    p.halfExtents = r3(3, 2, 4, 10);
    b.parts = {p};
    b.position = r3(k - 2, 1, 0, 1);
    b.mass = Rational{k < 2 ? 1000 : 1, 1};  // heavy ones push a tip their whole depth on
    s.bodies.list.push_back(b);
  }
  return s;
}

struct PushResult {
  std::vector<uint8_t> bytes;  // px, py, pz as raw bytes
  std::vector<int64_t> pushed;
  int64_t fault = 0;
  uint32_t faults = 0;
};

template <class S>
PushResult pushOnce(const World<S>& world, std::vector<RigidBody<S>> bodies, ParticleArrays<S> particles, bool marks,
                    ParticleKernel kernel, ParticleBroadphase broadphase = ParticleBroadphase::Grid) {
  BodyParticleSettings<S> settings;
  settings.broadphase = broadphase;
  settings.particleInvMass = S(1);
  S largest(0);
  for (const RigidBody<S>& b : bodies) largest = b.boundingRadius > largest ? b.boundingRadius : largest;
  settings.margin = world.particleConstants().rodLength + world.lattice().jitterAmplitude + largest;
  settings.pushAllowance = largest;
  settings.anchorOriginX = world.lattice().originX;
  settings.anchorOriginZ = world.lattice().originZ;
  settings.invParticleSpacing = S(1) / world.lattice().spacing;
  settings.heightMarks = marks;
  const ParticleGrid& grid = world.particleGrid();
  const GrassPushers<S> pushers = prepareGrassPushers(bodies, grid, settings);
  PushResult out;
  out.pushed.assign(bodies.size(), 0);
  takeFixedFaults();
  out.fault = pushParticlesOutOfBodies(particles, grid, pushers, settings, 0, grid.countZ, out.pushed.data(), kernel);
  out.faults = takeFixedFaults();
  for (const std::vector<S>* v : {&particles.px, &particles.py, &particles.pz}) {
    const auto* b = reinterpret_cast<const uint8_t*>(v->data());
    out.bytes.insert(out.bytes.end(), b, b + v->size() * sizeof(S));
  }
  return out;
}

template <class S>
void marksChangeNothing(const World<S>& world, int centreX = 0, int centreZ = 0) {
  using Raw = typename HeightBand<S>::Raw;
  const auto metres = [](int64_t mm) { return S(int(mm)) / S(1000); };
  // Bodies low in the grass, overlapping in the same rows at different heights; rarely one or three
  // quarters of the range up or down, and rarely a tuft tip beyond a quarter, a half or seven
  // eighths of it: there the reference's y difference may overflow, and the marks must raise the same fault.
  std::vector<RigidBody<S>> bodies = world.bodies();
  for (RigidBody<S>& b : bodies) {
    b.position = Vec3<S>(metres(centreX * 1000 + *rc::gen::inRange(-3000, 3000)), metres(*rc::gen::inRange(-300, 1500)),
                         metres(centreZ * 1000 + *rc::gen::inRange(-3000, 3000)));
    if (*rc::gen::inRange(0, 12) == 0)
      b.position.y() =
          S::fromRaw(Raw(*rc::gen::element<int>(1, -1)) *
                     (*rc::gen::element<Raw>(1, 3) * HeightBand<S>::kBound + *rc::gen::inRange<Raw>(-4, 4)));
    const Quat<S> q(metres(*rc::gen::inRange(-1000, 1000)), metres(*rc::gen::inRange(-1000, 1000)),
                    metres(*rc::gen::inRange(-1000, 1000)), metres(*rc::gen::inRange(-1000, 1000)));
    if (q.coeffs() != Quat<S>::Coefficients::Zero()) b.orientation = normalizedQuat(q);
    b.updateDerived();
  }
  // Tuft tips anywhere within a rod of their anchors, a few far out.
  ParticleArrays<S> particles = world.particles();
  for (size_t i = 0; i < particles.px.size(); ++i) {
    particles.px[i] = particles.anchorX[i] + metres(*rc::gen::inRange(-1000, 1000));
    particles.py[i] = particles.anchorY[i] + metres(*rc::gen::inRange(-300, 1200));
    particles.pz[i] = particles.anchorZ[i] + metres(*rc::gen::inRange(-1000, 1000));
    if (*rc::gen::inRange(0, 500) == 0) {
      const Raw q = HeightBand<S>::kBound;
      particles.py[i] =
          S::fromRaw(Raw(*rc::gen::element<int>(1, -1)) * *rc::gen::element<Raw>(q + 1, 2 * q + 1, 3 * q + q / 2));
    }
  }
  const PushResult reference = pushOnce(world, bodies, particles, false, ParticleKernel::Scalar);
  for (ParticleKernel kernel : {ParticleKernel::Scalar, ParticleKernel::Avx2}) {
    const PushResult marked = pushOnce(world, bodies, particles, true, kernel);
    RC_ASSERT(marked.bytes == reference.bytes);
    RC_ASSERT(marked.pushed == reference.pushed);
    RC_ASSERT(marked.fault == reference.fault);
    RC_ASSERT(marked.faults == reference.faults);
  }
  // Brute force tests every particle against every part, so it may meet overflows the ranges
  // skip; where neither faults, the lattice ranges push exactly what it pushes.
  const PushResult brute = pushOnce(world, bodies, particles, false, ParticleKernel::Scalar, ParticleBroadphase::Brute);
  if (brute.faults == 0 && reference.faults == 0) {
    RC_ASSERT(brute.bytes == reference.bytes);
    RC_ASSERT(brute.pushed == reference.pushed);
  }
  int64_t total = 0;
  for (int64_t n : reference.pushed) total += n;
  RC_TAG(total > 0 ? "pushed some" : "pushed none", reference.faults != 0 ? "a fault" : "no fault");
}

TEST(GrassCandidates, HeightMarksChangeNoBitsAndNoFault) {
  const auto fx32 = test::makeTyped<Fx32>(smallMeadowWithBodies());
  const auto fx16 = test::makeTyped<Fx16>(smallMeadowWithBodies());
  EXPECT_TRUE(rc::check("fx32", [&] { marksChangeNothing(*fx32); }));
  EXPECT_TRUE(rc::check("fx16", [&] { marksChangeNothing(*fx16); }));
}

// The level of detail's window is stored toroidally: once it has moved, a part's columns (and
// brute force's whole row) wrap around the storage's end. The same checks there, with the bodies
// around the seam.
TEST(GrassCandidates, HeightMarksChangeNoBitsInAMovedWindow) {
  Scenario s = loadScenarioFile(test::sourcePath("scenarios/lod-crossing.json"));
  s.field.patchesX = s.field.patchesZ = 201;  // 50 m, column 0 at x = -25
  s.lod.windowX = s.lod.windowZ = 41;         // 10 m
  s.lod.centerGiven = true;
  s.lod.centerX = s.lod.centerZ = Rational{-18, 1};
  s.script.clear();
  s.camera.clear();
  const auto check = [&]<class S>(const char* name) {
    auto world = test::makeTyped<S>(s);
    const int64_t storageOrigin = world->particleGrid().window.storageColumn(world->particleGrid().window.originI);
    TickInput in;
    in.hasCamera = true;
    in.camera = InputVec3{toInputRaw(Rational{-14, 1}), toInputRaw(Rational{2, 1}), toInputRaw(Rational{-15, 1})};
    ASSERT_TRUE(world->step(in).ok);
    const ParticleGrid& grid = world->particleGrid();
    ASSERT_NE(grid.window.storageColumn(grid.window.originI), storageOrigin) << "the window moved along x";
    ASSERT_NE(grid.window.storageRow(grid.window.originJ), 0) << "and along z";
    // The seam: the lattice column stored in column 0, in metres.
    const int64_t seam = grid.window.latticeColumn(0);
    const int seamX =
        int(std::lround(world->lattice().originX.toDouble() + double(seam) * world->lattice().spacing.toDouble()));
    EXPECT_TRUE(rc::check(name, [&] { marksChangeNothing(*world, seamX, -15); }));
  };
  check.operator()<Fx32>("fx32");
  check.operator()<Fx16>("fx16");
}

// Bodies piled in a line pass a tuft tip on: each pushes it out of its far side, into the next.
// The lattice ranges allow for one push (margin = rod + jitter + the largest radius); a chain of
// four heavy spheres carries the tip two radii further, to a sphere whose range does not hold
// its anchor. Every broad phase must still push it exactly as brute force does.
// Along x the chain stays in the tip's row; along z it runs through parts bucketed in other rows,
// which only the escape's walk over every later part reaches.
TEST(GrassCandidates, ChainedPushesReachTheSameBodiesInEveryBroadPhase) {
  Scenario scenario = test::thesisMeadow();
  scenario.field.patchesX = scenario.field.patchesZ = 40;
  scenario.wind.schedule.clear();
  for (int k = 0; k < 4; ++k) {
    BodySpec b = test::sphere("link", Rational{1, 2}, r3(0, 5, 0));
    b.name += std::to_string(k);
    b.mass = Rational{1000, 1};
    scenario.bodies.list.push_back(b);
  }
  const auto check = [&]<class S>(bool alongZ) {
    const auto world = test::makeTyped<S>(scenario);
    ParticleArrays<S> particles = world->particles();
    const size_t tip = particles.px.size() / 2 + 7;
    for (size_t i = 0; i < particles.px.size(); ++i) particles.py[i] = particles.anchorY[i] + S(1);  // upright
    const S ax = particles.anchorX[tip], ay = particles.anchorY[tip], az = particles.anchorZ[tip];
    const auto cm = [](int v) { return S(v) / S(100); };
    // The tip lies almost flat (0.99 m out, 0.14 m up: within its 1 m rod), 1 cm past the
    // first sphere's centre; each next sphere sits 1 cm short of where the last one leaves it.
    const auto along = [&](int centimetres) {
      return alongZ ? Vec3<S>(ax, ay + cm(14), az + cm(centimetres)) : Vec3<S>(ax + cm(centimetres), ay + cm(14), az);
    };
    const Vec3<S> start = along(99);
    particles.px[tip] = start.x();
    particles.py[tip] = start.y();
    particles.pz[tip] = start.z();
    std::vector<RigidBody<S>> bodies = world->bodies();
    for (size_t k = 0; k < bodies.size(); ++k) bodies[k].position = along(98 + 49 * int(k));
    const PushResult brute =
        pushOnce(*world, bodies, particles, true, ParticleKernel::Scalar, ParticleBroadphase::Brute);
    ASSERT_EQ(brute.pushed, std::vector<int64_t>(4, 1)) << "the chain passes the tip through all four";
    for (ParticleKernel kernel : {ParticleKernel::Scalar, ParticleKernel::Avx2})
      for (bool marks : {false, true}) {
        const PushResult grid = pushOnce(*world, bodies, particles, marks, kernel, ParticleBroadphase::Grid);
        EXPECT_EQ(grid.pushed, brute.pushed) << marks;
        EXPECT_TRUE(grid.bytes == brute.bytes) << marks;
      }
  };
  for (bool alongZ : {false, true}) {
    check.operator()<Fx32>(alongZ);
    check.operator()<Fx16>(alongZ);
  }
}

// A box's pre-test reach (its bounding radius with a slack for the rotation's rounding) holds
// every point the exact box test calls inside: points just inside the corners of boxes turned
// every way, in Fx16 (the coarsest rotation) and Fx32.
template <class S>
void boxReachHoldsTheBox() {
  const auto unit = [] { return S(*rc::gen::inRange(-1000, 1001)) / S(1000); };
  RigidBody<S> body;
  BodyPart<S> part;
  part.type = ShapeType::Box;
  part.halfExtents = Vec3<S>(S(*rc::gen::inRange(1, 3000)) / S(1000), S(*rc::gen::inRange(1, 3000)) / S(1000),
                             S(*rc::gen::inRange(1, 3000)) / S(1000));
  part.boundingRadius = length3(part.halfExtents.x(), part.halfExtents.y(), part.halfExtents.z());
  body.parts = {part};
  body.position = Vec3<S>(unit() * S(5), unit(), unit() * S(5));
  const Quat<S> q(unit(), unit(), unit(), unit());
  if (q.coeffs() != Quat<S>::Coefficients::Zero()) body.orientation = normalizedQuat(q);
  body.updateDerived();
  ParticleGrid grid;
  grid.countX = grid.countZ = 1;
  grid.window = LatticeWindow{0, 0, 1, 1, 1, 1};
  BodyParticleSettings<S> settings;
  settings.broadphase = ParticleBroadphase::Brute;
  const GrassPushers<S> pushers = prepareGrassPushers(std::vector<RigidBody<S>>{body}, grid, settings);
  const GrassPusher<S>& pusher = pushers.parts.at(0);
  // A corner (each sign), pulled in by up to 3 raw units per axis, and turned into the world.
  const Vec3<S>& h = part.halfExtents;
  Vec3<S> local;
  for (int axis = 0; axis < 3; ++axis) {
    const S pullIn = S::fromRaw(*rc::gen::inRange(1, 4));
    local[axis] = *rc::gen::arbitrary<bool>() ? S(h[axis] - pullIn) : S(pullIn - h[axis]);
  }
  const Vec3<S> p = pusher.pose.toWorld(local);
  const Vec3<S> back = pusher.pose.toLocal(p);
  const bool inside = abs(back.x()) < h.x() && abs(back.y()) < h.y() && abs(back.z()) < h.z();
  RC_TAG(inside ? "inside" : "rounded outside");
  if (!inside) return;
  const Vec3<S>& c = pusher.pose.position;
  RC_ASSERT(withinReach(p.x(), p.y(), p.z(), c.x(), c.y(), c.z(), pusher.candidateReach));
}

RC_GTEST_PROP(GrassCandidates, Fx16BoxReachHoldsTheBox, ()) { boxReachHoldsTheBox<Fx16>(); }
RC_GTEST_PROP(GrassCandidates, Fx32BoxReachHoldsTheBox, ()) { boxReachHoldsTheBox<Fx32>(); }

}  // namespace
}  // namespace sg
