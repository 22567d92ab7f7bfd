#include "sim/scenario/fingerprint.h"

#include <algorithm>
#include <initializer_list>

#include "sim/state/state_sink.h"

namespace sg {

namespace {
/// An exact value as its numerator and denominator, each as two 64-bit halves (low first).
void putRational(HashSink& h, const Rational& r) {
  for (const auto& v : {r.num, r.den}) {
    h.put(low64(v));
    h.put(high64(v));
  }
}

void putInts(HashSink& h, std::initializer_list<int64_t> values) {
  for (const int64_t v : values) h.put(v);
}
}  // namespace

uint64_t scenarioFingerprint(const Scenario& s) {
  HashSink h;
  const auto& f = s.field;
  const auto& p = s.particles;
  putInts(h, {f.patchesX, f.patchesZ, f.atlasVariants, p.interpolation, int64_t(p.model), int64_t(s.wind.travel),
              int64_t(s.scalar), s.terrain.flat ? 1 : 0, int64_t(s.terrain.heightmap.width),
              int64_t(s.terrain.heightmap.height)});
  h.put(s.seed);
  for (const Rational* r : {&s.timeStep, &f.spacing, &f.jitter, &f.centerX, &f.centerZ, &f.scaleY, &f.scaleXZ,
                            &p.constraintLength, &p.mass, &p.damping, &s.wind.travelSpeed, &s.terrain.flatHeight,
                            &s.terrain.cellSize, &s.terrain.maxHeight, &s.terrain.centerX, &s.terrain.centerZ})
    putRational(h, *r);
  for (int c = 0; c < 3; ++c) {
    putRational(h, p.initialVelocity[size_t(c)]);
    putRational(h, p.acceleration[size_t(c)]);
    putRational(h, p.tiltDrop[size_t(c)]);
  }
  h.put(uint64_t(s.wind.schedule.size()));  // counts first: lists cannot run into what follows
  for (const WindGust& g : s.wind.schedule) {
    for (const Rational& r : g.force) putRational(h, r);
    putRational(h, g.duration);
    if (g.front) {                 // behind a tag: gusts written before fronts existed keep their fingerprint
      putInts(h, {0x66726f6e74});  // "front"
      for (const Rational& r : *g.front) putRational(h, r);
    }
  }
  h.write(s.terrain.heightmap.samples.data(), s.terrain.heightmap.samples.size());  // bytes
  if (p.model == GrassModel::Blade) {  // behind a tag, as the other optional parts
    putInts(h, {0x626c616465});        // "blade"
    for (const Rational* r : {&p.blade.frequency, &p.blade.dampingRatio, &p.blade.trampleSeconds}) putRational(h, *r);
  }
  if (s.lod.mode == LodMode::Window) {
    putInts(h, {1, s.lod.windowX, s.lod.windowZ, s.lod.edgeSpacing, s.lod.edgeRows, s.lod.centerGiven ? 1 : 0});
    putRational(h, s.lod.centerX);
    putRational(h, s.lod.centerZ);
  }
  if (!s.bodies.list.empty()) {
    const auto& b = s.bodies;
    // Not the broad phases: they are promised to give the same state, so they must not change it.
    putInts(h, {b.substeps, b.velocityIterations, b.positionIterations, int64_t(b.boxParticleNormal),
                int64_t(b.list.size())});
    for (const Rational& g : b.gravity) putRational(h, g);
    putRational(h, b.grassDrag);
    // The sweeps an island of touching bodies gets (World: at least velocityIterations), behind a
    // tag, only when they differ from a lone body's: before the key existed every island had
    // velocityIterations, so a scenario that asks for that keeps its old fingerprint (and its old
    // bits), and one that does not (the default, 6) is told apart from a recording made then.
    const int islandSweeps = std::max(b.velocityIterations, b.islandVelocityIterations);
    if (islandSweeps != b.velocityIterations) putInts(h, {0x69736c616e64, islandSweeps});  // "island"
    if (!(b.contactHertz == Rational{60, 1})) {
      putInts(h, {0x636f6e7461637448});  // "contactH"
      putRational(h, b.contactHertz);
    }
    if (b.tipContact == TipContact::Hold && s.particles.model != GrassModel::Blade)  // the blade always holds
      putInts(h, {0x746970486f6c64});                                                // "tipHold"
    putRational(h, b.mowerCutHeight);
    for (const BodySpec& body : b.list) {
      h.put(uint64_t(body.name.size()));  // length first: names cannot run into what follows
      h.write(body.name.data(), body.name.size());
      h.put(uint64_t(body.parts.size()));
      for (const ShapeSpec& part : body.parts) {
        h.put(int64_t(part.type));
        putRational(h, part.radius);
        for (const Rational& r : part.halfExtents) putRational(h, r);
        for (const Rational& r : part.offset) putRational(h, r);
      }
      for (const Rational* r :
           {&body.mass, &body.linearDamping, &body.angularDamping, &body.restitution, &body.friction})
        putRational(h, *r);
      h.put(int64_t((body.mower ? 1 : 0) | (body.canSleep ? 2 : 0)));
    }
  }
  return h.digest();
}

}  // namespace sg
