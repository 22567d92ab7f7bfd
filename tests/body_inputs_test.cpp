// Body inputs for the viewer (issue 6): Reset, Spawn, MowerOn and MowerOff are recorded inputs
// like the others, so they must be exact, part of the saved state, and replay bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "replay/format/sgr_reader.h"
#include "replay/player.h"
#include "replay/recorder.h"
#include "sim/state/byte_order.h"
#include "tests/cli_support.h"
#include "tests/state_sections.h"
#include "tests/test_support.h"

namespace sg {
namespace {

using test::emptyWorld;
using test::makeTyped;
using test::r3;
using test::sphere;

/// Q32.32 input vector of integers / den (exact).
InputVec3 at(int64_t x, int64_t y, int64_t z, int64_t den = 1) {
  const Rational3 v = r3(x, y, z, den);
  return InputVec3{toInputRaw(v[0]), toInputRaw(v[1]), toInputRaw(v[2])};
}

TickInput command(int32_t body, BodyCommandKind kind, InputVec3 value = {}) {
  TickInput in;
  in.bodies.push_back(BodyCommand{body, kind, value});
  return in;
}

template <class S>
void stepN(World<S>& w, int64_t ticks, const TickInput& input = {}) {
  for (int64_t t = 0; t < ticks; ++t) ASSERT_TRUE(w.step(input).ok) << "tick " << w.tick();
}

/// Every piece of a body's dynamic state, bit for bit.
template <class S>
void expectSameBody(const RigidBody<S>& a, const RigidBody<S>& b) {
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(a.position[k], b.position[k]) << "position " << k;
    EXPECT_EQ(a.velocity[k], b.velocity[k]) << "velocity " << k;
    EXPECT_EQ(a.angularVelocity[k], b.angularVelocity[k]) << "angular velocity " << k;
  }
  EXPECT_EQ(a.orientation.w(), b.orientation.w());
  EXPECT_EQ(a.orientation.x(), b.orientation.x());
  EXPECT_EQ(a.orientation.y(), b.orientation.y());
  EXPECT_EQ(a.orientation.z(), b.orientation.z());
  EXPECT_EQ(a.stillTicks, b.stillTicks);
  EXPECT_EQ(a.asleep, b.asleep);
}

/// A tilted box resting on the empty ground (its contacts fill the warm-start cache).
Scenario restingBox() {
  Scenario s = emptyWorld();
  BodySpec box;
  box.name = "box";
  ShapeSpec part;
  part.type = ShapeType::Box;
  box.parts = {part};  // half extents 1/2
  box.position = r3(0, 1, 0, 2);
  box.orientation = {Rational{3, 5}, Rational{0, 1}, Rational{4, 5}, Rational{0, 1}};  // about y
  s.bodies.list = {box};
  return s;
}

// ---- Reset --------------------------------------------------------------------------------------

TEST(BodyInputs, ResetReturnsExactlyTheScenarioStartState) {
  const Scenario s = restingBox();
  auto w = makeTyped<Fx32>(s);
  ASSERT_TRUE(w->step(command(0, BodyCommandKind::AddVelocity, at(2, 0, 1))).ok);
  stepN(*w, 90);  // slides, stops, falls asleep with cached contact impulses
  ASSERT_TRUE(w->bodies()[0].asleep) << "the set-up should leave the box asleep";
  ASSERT_NE(w->bodies()[0].position.x(), Fx32(0));
  ASSERT_TRUE(w->step(command(0, BodyCommandKind::Reset, at(7, 7, 7))).ok);  // the value is ignored
  stepN(*w, 30);
  // A fresh world's box after the same 31 ticks: the reset box must be indistinguishable (same
  // pose, at rest, awake, no warm-start impulses left from before).
  auto fresh = makeTyped<Fx32>(s);
  stepN(*fresh, 31);
  expectSameBody(w->bodies()[0], fresh->bodies()[0]);
  // And right after the reset the pose is the scenario's: one tick back from a Reset equals a
  // fresh world's first tick.
  ASSERT_TRUE(w->step(command(0, BodyCommandKind::Reset)).ok);
  auto once = makeTyped<Fx32>(s);
  stepN(*once, 1);
  expectSameBody(w->bodies()[0], once->bodies()[0]);
}

TEST(BodyInputs, ResetOfASpawnedBodyReturnsItToItsSpawnPoint) {
  Scenario s = emptyWorld();
  s.bodies.list = {sphere("ball", Rational{1, 2}, r3(-10, 3, 0))};
  // A: spawn at tick 0, push it around, reset it at tick 20. B: spawn at tick 20 at the same point.
  auto a = makeTyped<Fx32>(s), b = makeTyped<Fx32>(s);
  ASSERT_TRUE(a->step(command(0, BodyCommandKind::Spawn, at(4, 2, 1))).ok);
  stepN(*a, 2);
  ASSERT_TRUE(a->step(command(1, BodyCommandKind::AddVelocity, at(3, 5, -1))).ok);
  stepN(*a, 16);
  ASSERT_NE(a->bodies()[1].position.x(), Fx32(4));
  ASSERT_TRUE(a->step(command(1, BodyCommandKind::Reset)).ok);
  stepN(*b, 20);
  ASSERT_TRUE(b->step(command(0, BodyCommandKind::Spawn, at(4, 2, 1))).ok);
  stepN(*a, 40);
  stepN(*b, 40);
  ASSERT_EQ(a->bodies().size(), 2u);
  expectSameBody(a->bodies()[1], b->bodies()[1]);
}

// ---- Spawn --------------------------------------------------------------------------------------

TEST(BodyInputs, SpawnedBodyFallsAndRestsLikeItsTemplateBuiltThere) {
  // On flat empty ground a sphere's motion does not depend on where it is: a copy spawned at P at
  // tick 20 must follow, tick for tick, the trajectory of a scenario body that starts at rest at
  // P at tick 0 (computed in a world of its own).
  Scenario s = emptyWorld();
  s.bodies.list = {sphere("ball", Rational{1, 2}, r3(0, 3, 0))};
  s.bodies.list[0].velocity = r3(1, 0, 0);  // the template's initial velocity is not copied
  auto w = makeTyped<Fx32>(s);
  stepN(*w, 20);
  ASSERT_TRUE(w->step(command(0, BodyCommandKind::Spawn, at(6, 5, -2))).ok);
  EXPECT_EQ(w->counts().bodies, 2);
  EXPECT_EQ(w->bodyTemplate(1), 0);
  EXPECT_EQ(w->bodyTemplate(2), -1);
  Scenario there = s;
  there.bodies.list[0].position = r3(6, 5, -2);
  there.bodies.list[0].velocity = r3(0, 0, 0);
  auto ref = makeTyped<Fx32>(there);
  ASSERT_TRUE(ref->step(TickInput{}).ok);
  expectSameBody(w->bodies()[1], ref->bodies()[0]);
  for (int t = 0; t < 180; ++t) {
    ASSERT_TRUE(w->step(TickInput{}).ok);
    ASSERT_TRUE(ref->step(TickInput{}).ok);
    ASSERT_EQ(w->bodies()[1].position.y(), ref->bodies()[0].position.y()) << "tick " << t;
  }
  expectSameBody(w->bodies()[1], ref->bodies()[0]);
  // It rests on the ground: centre one radius up, within the solver's 0.5 mm slop (+ one tick of
  // gravity, g dt^2 = 2.7 mm, that the next contact removes).
  EXPECT_NEAR(w->bodies()[1].position.y().toDouble(), 0.5, 0.0005 + 9.81 / 3600);
  EXPECT_NEAR(w->bodies()[1].position.x().toDouble(), 6.0, 1e-6) << "it fell straight down";
  // The observation lists it too.
  Observation o;
  w->observe(o);
  ASSERT_EQ(o.bodyPosition.size(), 6u);
  EXPECT_NEAR(o.bodyPosition[3], 6.0, 1e-6);
}

TEST(BodyInputs, SpawnedBodyPushesGrassLikeItsTemplate) {
  // A template far from the meadow; its copy dropped onto the grass at tick 0 must move the grass
  // and itself exactly as a scenario body built at that point does (grass state included).
  Scenario s = test::thesisMeadow();
  s.field.patchesX = s.field.patchesZ = 21;  // 5 m x 5 m around the origin
  s.wind.schedule.clear();
  s.bodies.list = {sphere("ball", Rational{1, 2}, r3(-60, 1, 0))};
  Scenario there = s;
  there.bodies.list[0].position = r3(1, 1, 0);
  auto w = makeTyped<Fx32>(s), ref = makeTyped<Fx32>(there);
  ASSERT_TRUE(w->step(command(0, BodyCommandKind::Spawn, at(1, 1, 0))).ok);
  ASSERT_TRUE(ref->step(TickInput{}).ok);
  stepN(*w, 90);
  stepN(*ref, 90);
  expectSameBody(w->bodies()[1], ref->bodies()[0]);
  EXPECT_EQ(w->particles().px, ref->particles().px);
  EXPECT_EQ(w->particles().py, ref->particles().py);
  EXPECT_EQ(w->particles().vz, ref->particles().vz);
  // (The ball did touch the grass: particles under it are not where a ball-free meadow has them.)
  Scenario none = s;
  none.bodies.list.clear();
  auto bare = makeTyped<Fx32>(none);
  stepN(*bare, 91);
  EXPECT_NE(w->particles().py, bare->particles().py);
}

TEST(BodyInputs, SpawnedBodyCanBeDriven) {
  Scenario s = emptyWorld();
  s.bodies.list = {sphere("ball", Rational{1, 2}, r3(-10, 1, 0, 2))};
  s.bodies.list[0].friction = Rational{0, 1};  // slides: x(t) is exact
  auto w = makeTyped<Fx32>(s);
  ASSERT_TRUE(w->step(command(0, BodyCommandKind::Spawn, at(0, 1, 0, 2))).ok);
  stepN(*w, 10);
  ASSERT_TRUE(w->step(command(1, BodyCommandKind::AddVelocity, at(3, 0, 0))).ok);
  stepN(*w, 59);
  // 60 ticks at 3 m/s: 3 m (position integrated with the new velocity from the command's tick on;
  // Q32.32 rounding of dt and of each step is below 1e-7 m here).
  EXPECT_NEAR(w->bodies()[1].position.x().toDouble(), 3.0, 1e-6);
  EXPECT_EQ(w->bodies()[0].position.x().toDouble(), -5.0) << "the template is not driven";
  ASSERT_TRUE(w->step(command(1, BodyCommandKind::Teleport, at(20, 3, 0))).ok);
  // From rest, n sub-steps of h = dt / n fall g h^2 n (n + 1) / 2 = g dt^2 (n + 1) / (2 n).
  const int n = s.bodies.substeps;
  EXPECT_NEAR(w->bodies()[1].position.y().toDouble(), 3.0 - 9.81 / 3600 * (n + 1) / (2 * n), 1e-6);
}

TEST(BodyInputs, SpawnsBeyondTheCapOrFromMissingBodiesAreIgnored) {
  Scenario s = emptyWorld();
  s.bodies.list = {sphere("ball", Rational{1, 2}, r3(0, 3, 0))};
  TickInput many, capped;
  for (int i = 0; i < 80; ++i) {
    const BodyCommand c{0, BodyCommandKind::Spawn, at(2 * (i + 1), 3, 0)};
    many.bodies.push_back(c);
    if (i < kMaxBodies - 1) capped.bodies.push_back(c);
  }
  many.bodies.push_back(BodyCommand{500, BodyCommandKind::Spawn, at(0, 9, 0)});
  many.bodies.push_back(BodyCommand{-1, BodyCommandKind::Spawn, at(0, 9, 0)});
  many.bodies.push_back(BodyCommand{70, BodyCommandKind::AddVelocity, at(1, 0, 0)});
  auto a = makeTyped<Fx32>(s), b = makeTyped<Fx32>(s);
  ASSERT_TRUE(a->step(many).ok);
  ASSERT_TRUE(b->step(capped).ok);
  EXPECT_EQ(a->counts().bodies, kMaxBodies);
  EXPECT_EQ(a->stateHash(), b->stateHash());
  stepN(*a, 3);
  stepN(*b, 3);
  EXPECT_EQ(a->stateHash(), b->stateHash());
}

// ---- MowerOn / MowerOff --------------------------------------------------------------------------

/// A 10 m x 10 m meadow, a far-away ball, and a box mower whose blade (0.2 m) is inside its deck
/// (0 .. 0.3 m), sliding frictionless along +x at 1 m/s from x = -3 once pushed.
const char* kMowerScenario = R"JSON({
  "format": "simgrass-scenario/1",
  "name": "body-inputs",
  "field": {"patchesX": 41, "patchesZ": 41, "spacing": 0.25, "center": [0, 0]},
  "particles": {"constraintLength": 0.5},
  "wind": {"schedule": []},
  "bodies": {
    "mowerCutHeight": 0.2,
    "list": [
      {"name": "ball", "position": [-50, 2, 0], "shape": {"type": "sphere", "radius": 0.25}, "mesh": "meshes/ball.obj"},
      {"name": "mower", "mass": 30, "position": [-3, 0.15, 0], "friction": 0, "restitution": 0, "mower": true,
       "canSleep": false, "shape": {"type": "box", "halfExtents": [0.5, 0.15, 0.4]}}
    ]
  }
})JSON";

Scenario mowerScenario() { return parseScenario(kMowerScenario, "body-inputs.json", {}); }

TEST(BodyInputs, MowerOffStopsCuttingAndMowerOnResumes) {
  const Scenario s = mowerScenario();
  auto off = makeTyped<Fx32>(s), on = makeTyped<Fx32>(s);
  TickInput start = command(1, BodyCommandKind::AddVelocity, at(1, 0, 0));
  ASSERT_TRUE(on->step(start).ok);
  start.bodies.insert(start.bodies.begin(), BodyCommand{1, BodyCommandKind::MowerOff, {}});
  ASSERT_TRUE(off->step(start).ok);
  EXPECT_FALSE(off->bladeOn(1));
  EXPECT_TRUE(on->bladeOn(1));
  EXPECT_FALSE(on->bladeOn(0)) << "not a mower";
  for (int t = 1; t < 90; ++t) {
    ASSERT_TRUE(off->step(TickInput{}).ok);
    ASSERT_TRUE(on->step(TickInput{}).ok);
    ASSERT_TRUE(off->cuts().empty()) << "tick " << t;
  }
  ASSERT_GT(on->cuts().size(), 20u) << "the same drive with the blade on cuts (the test can fail)";
  // Off, it still collides: the grass and the mower move exactly as with the blade on.
  expectSameBody(off->bodies()[1], on->bodies()[1]);
  EXPECT_EQ(off->particles().py, on->particles().py);
  EXPECT_NE(off->stateHash(), on->stateHash()) << "the blade state (and the cuts) are state";

  // Back on: it cuts again, only where it is from now on.
  const double xOn = off->bodies()[1].position.x().toDouble();
  ASSERT_TRUE(off->step(command(1, BodyCommandKind::MowerOn)).ok);
  EXPECT_TRUE(off->bladeOn(1));
  stepN(*off, 90);
  ASSERT_GT(off->cuts().size(), 20u);
  const auto& lattice = off->lattice();
  for (const auto& [ij, value] : off->cuts()) {
    Fx32 x, z;
    lattice.rootXZ(ij.first, ij.second, &x, &z);
    // A tuft is cut when its blade point (on its own jittered root) is inside the deck: behind
    // the deck's rear edge at switch-on (x - 0.5) nothing is cut (1 mm for solver wobble).
    EXPECT_GT(x.toDouble(), xOn - 0.5 - 1e-3) << ij.first << "," << ij.second;
  }
  // Every tuft it cut with the blade on was cut by the always-on mower too.
  stepN(*on, 91);
  for (const auto& [ij, value] : off->cuts()) EXPECT_TRUE(on->cuts().count(ij)) << ij.first << "," << ij.second;
}

TEST(BodyInputs, BladeSwitchesOnOtherBodiesChangeNothing) {
  const Scenario s = mowerScenario();
  auto a = makeTyped<Fx32>(s), b = makeTyped<Fx32>(s);
  TickInput in;
  in.bodies = {BodyCommand{0, BodyCommandKind::MowerOff, {}}, BodyCommand{1, BodyCommandKind::MowerOn, {}},
               BodyCommand{9, BodyCommandKind::MowerOff, {}}};
  ASSERT_TRUE(a->step(in).ok);
  ASSERT_TRUE(b->step(TickInput{}).ok);
  EXPECT_EQ(a->stateHash(), b->stateHash()) << "a ball has no blade; mowers start on; body 9 does not exist";
}

// ---- state: save, restore, damaged bytes ---------------------------------------------------------

TickInput spawnAndSwitch(int64_t tick) {
  TickInput in;
  if (tick == 5)
    in.bodies = {BodyCommand{1, BodyCommandKind::Spawn, at(2, 1, 1)},
                 BodyCommand{0, BodyCommandKind::Spawn, at(-2, 2, -1)}};
  if (tick == 8)
    in.bodies = {BodyCommand{2, BodyCommandKind::MowerOff, {}},
                 BodyCommand{1, BodyCommandKind::AddVelocity, at(1, 0, 0)}};
  if (tick == 12) in.bodies = {BodyCommand{3, BodyCommandKind::AddVelocity, at(0, 2, 0)}};
  if (tick == 30)
    in.bodies = {BodyCommand{2, BodyCommandKind::MowerOn, {}}, BodyCommand{1, BodyCommandKind::Reset, {}}};
  return in;
}

TEST(BodyInputs, SaveAfterSpawnRestoreIntoAFreshWorldContinuesBitIdentically) {
  const Scenario s = mowerScenario();
  auto a = makeTyped<Fx32>(s);
  for (int64_t t = 0; t < 20; ++t) ASSERT_TRUE(a->step(spawnAndSwitch(t)).ok);
  ASSERT_EQ(a->counts().bodies, 4);
  ASSERT_FALSE(a->bladeOn(2));
  const std::vector<uint8_t> saved = a->saveState();
  // Into a fresh world, and into one that has spawned other bodies and switched blades itself.
  auto fresh = makeTyped<Fx32>(s), busy = makeTyped<Fx32>(s);
  TickInput other;
  for (int i = 0; i < 5; ++i) other.bodies.push_back(BodyCommand{0, BodyCommandKind::Spawn, at(3 * i, 4, 3)});
  other.bodies.push_back(BodyCommand{1, BodyCommandKind::MowerOff, {}});
  ASSERT_TRUE(busy->step(other).ok);
  fresh->restoreState(saved);
  busy->restoreState(saved);
  for (SimWorld* w : {static_cast<SimWorld*>(fresh.get()), static_cast<SimWorld*>(busy.get())}) {
    EXPECT_EQ(w->stateHash(), a->stateHash());
    EXPECT_EQ(w->counts().bodies, 4);
    EXPECT_EQ(w->bodyTemplate(2), 1);
    EXPECT_EQ(w->bodyTemplate(3), 0);
    EXPECT_FALSE(w->bladeOn(2));
    EXPECT_TRUE(w->bladeOn(1));
  }
  for (int64_t t = 20; t < 50; ++t) {
    ASSERT_TRUE(a->step(spawnAndSwitch(t)).ok);
    ASSERT_TRUE(fresh->step(spawnAndSwitch(t)).ok);
    ASSERT_TRUE(busy->step(spawnAndSwitch(t)).ok);
    ASSERT_EQ(fresh->stateHash(), a->stateHash()) << "tick " << t;
    ASSERT_EQ(busy->stateHash(), a->stateHash()) << "tick " << t;
  }
  // A state without spawns restored over one with them: back to the scenario's bodies.
  auto plain = makeTyped<Fx32>(s);
  busy->restoreState(plain->saveState());
  EXPECT_EQ(busy->counts().bodies, 2);
  EXPECT_EQ(busy->stateHash(), plain->stateHash());
  EXPECT_TRUE(busy->bladeOn(1));
}

TEST(BodyInputs, BladeSwitchesAndSpawnsLiveInTheirSections) {
  // A switched-off blade is a flag of its body's record, a spawn a SPWN entry: the state's size
  // changes only with the number of bodies.
  const Scenario s = mowerScenario();
  auto w = makeTyped<Fx32>(s);
  stepN(*w, 5, command(1, BodyCommandKind::MowerOn));
  const std::vector<uint8_t> on = w->saveState();
  const test::StateSection spawns = test::findSection(on, "SPWN");
  EXPECT_EQ(spawns.length, 4u);
  EXPECT_EQ(loadLE<uint32_t>(on.data() + spawns.payloadAt), 0u);
  const test::StateSection bodies = test::findSection(on, "BODY");
  const size_t record = 13 * sizeof(Fx32) + 8;
  ASSERT_EQ(bodies.length, 2 * record);
  const size_t mowerFlags = bodies.payloadAt + record + 13 * sizeof(Fx32) + 4;
  EXPECT_EQ(on[mowerFlags] & 2, 0);
  ASSERT_TRUE(w->step(command(1, BodyCommandKind::MowerOff)).ok);
  const std::vector<uint8_t> off = w->saveState();
  EXPECT_EQ(off.size(), on.size());
  EXPECT_EQ(off[mowerFlags] & 2, 2) << "the mower's record says its blade is off";
  ASSERT_TRUE(w->step(spawnAndSwitch(0)).ok);
  const std::vector<uint8_t> spawned = w->saveState();
  EXPECT_EQ(loadLE<uint32_t>(spawned.data() + test::findSection(spawned, "SPWN").payloadAt),
            uint32_t(w->counts().bodies - 2));
}

TEST(BodyInputs, DamagedBodyInputsGiveAStateErrorNeverACrash) {
  const Scenario s = mowerScenario();
  auto w = makeTyped<Fx32>(s);
  for (int64_t t = 0; t < 10; ++t) ASSERT_TRUE(w->step(spawnAndSwitch(t)).ok);
  const std::vector<uint8_t> good = w->saveState();
  auto target = makeTyped<Fx32>(s);
  const uint64_t before = target->stateHash();
  auto expectError = [&](const std::vector<uint8_t>& bad, const std::string& fragment) {
    try {
      target->restoreState(bad);
      ADD_FAILURE() << "accepted a damaged state (" << fragment << ")";
    } catch (const StateError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
      EXPECT_LE(e.offset(), bad.size());
    }
    EXPECT_EQ(target->stateHash(), before) << "a failed restore changes nothing";
  };
  ASSERT_EQ(w->counts().bodies, 4);
  const test::StateSection spawns = test::findSection(good, "SPWN");
  const test::StateSection bodies = test::findSection(good, "BODY");
  ASSERT_EQ(loadLE<uint32_t>(good.data() + spawns.payloadAt), 2u);
  auto bad = good;
  bad[spawns.payloadAt] = 3;
  expectError(bad, "2 spawned bodies");
  bad = good;
  bad[spawns.payloadAt + 4] = 7;  // template 7 of 2
  expectError(bad, "spawn template between 0 and 1");
  bad = good;
  bad[bodies.payloadAt + 13 * sizeof(Fx32) + 4] |= 2;  // body 0 is a ball, not a mower
  expectError(bad, "no mower");
  bad = good;
  bad[52] = 70;  // header body count
  expectError(bad, "2 to 64 bodies, got 70");
  bad = good;
  bad[52] = 2;  // two bodies, but a body section and spawns for four
  expectError(bad, "");
  for (size_t cut = 1; cut <= 200; ++cut) expectError({good.begin(), good.end() - ptrdiff_t(cut)}, "");
  // Every single-byte change of the body and spawn sections is either refused or a state that
  // steps, or fails its step with a reported fault (a flipped pose bit can overflow): never a crash.
  for (size_t i = bodies.tagAt; i < spawns.payloadAt + spawns.length; ++i) {
    bad = good;
    bad[i] ^= 0x5a;
    try {
      auto probe = makeTyped<Fx32>(s);
      probe->restoreState(bad);
      const StepResult r = probe->step(TickInput{});
      if (!r.ok) {
        EXPECT_NE(r.error.message().find("simulation error at tick"), std::string::npos);
      }
    } catch (const StateError&) {
    }
  }
  target->restoreState(good);
  EXPECT_EQ(target->stateHash(), w->stateHash());
}

// ---- scenario and input-track JSON -----------------------------------------------------------------

TEST(BodyInputs, ScriptsAndTracksNameTheNewCommands) {
  const Scenario s = mowerScenario();
  EXPECT_EQ(s.bodies.list[0].mesh, "meshes/ball.obj");
  EXPECT_EQ(s.bodies.list[1].mesh, "");
  const InputTrack track = parseInputTrack(R"({"format": "simgrass-input-track/1", "commands": [
      {"tick": 1, "body": "ball", "command": "spawn", "value": [1, 2, 3]},
      {"tick": 2, "body": 2, "command": "reset"},
      {"tick": 3, "body": "mower", "command": "mowerOff"},
      {"tick": 4, "body": "mower", "command": "mowerOn", "value": [0, 0, 0]}]})",
                                           "track.json", s);
  ASSERT_EQ(track.commands.size(), 4u);
  EXPECT_EQ(track.commands[0].kind, BodyCommandKind::Spawn);
  EXPECT_EQ(track.commands[0].body, 0);
  EXPECT_EQ(track.commands[1].kind, BodyCommandKind::Reset);
  EXPECT_EQ(track.commands[1].body, 2) << "an index: the first spawned body";
  EXPECT_EQ(track.commands[2].kind, BodyCommandKind::MowerOff);
  EXPECT_EQ(track.commands[3].kind, BodyCommandKind::MowerOn);
  auto error = [&](const std::string& json) {
    try {
      parseInputTrack(json, "track.json", s);
    } catch (const ScenarioError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string head = R"({"format": "simgrass-input-track/1", )";
  EXPECT_NE(
      error(head + R"("commands": [{"tick": 1, "body": "ball", "command": "spawn"}]})").find("$.commands[0].value"),
      std::string::npos);
  EXPECT_NE(error(head + R"("commands": [{"tick": 1, "body": 64, "command": "reset"}]})").find("$.commands[0].body"),
            std::string::npos);
  EXPECT_NE(error(head + R"("commands": [{"tick": 1, "body": "ball", "command": "mow"}]})").find("mowerOff"),
            std::string::npos);
  std::string text = kMowerScenario;
  const std::string mesh = "\"meshes/ball.obj\"";
  text.replace(text.find(mesh), mesh.size(), "3");
  try {
    parseScenario(text, "body-inputs.json", {});
    ADD_FAILURE() << "a numeric mesh was accepted";
  } catch (const ScenarioError& e) {
    EXPECT_EQ(e.path(), "$.bodies.list[0].mesh");
    EXPECT_NE(std::string(e.what()).find("a string"), std::string::npos) << e.what();
  }
  // The mesh is looks only: it does not change the world.
  std::string noMesh = kMowerScenario;
  const std::string key = ", \"mesh\": " + mesh;
  noMesh.replace(noMesh.find(key), key.size(), "");
  EXPECT_EQ(World<Fx32>(parseScenario(noMesh, "a.json", {}), 1).stateHash(), World<Fx32>(s, 1).stateHash());
}

// ---- record and replay ---------------------------------------------------------------------------------

TEST(BodyInputs, RecordingWithBodyInputsVerifiesAndSeeksPastTheSpawn) {
  const Scenario s = mowerScenario();
  std::unique_ptr<SimWorld> world = makeWorld(s, 1);
  TempDir dir;
  const std::string path = dir.file("inputs.sgr");
  std::vector<uint64_t> hashes;
  RecordSettings settings;
  settings.snapshotEvery = 10;
  {
    Recorder recorder(path, s, {}, *world, settings);
    for (int64_t t = 0; t < 45; ++t) {
      const StepResult r = recorder.step(spawnAndSwitch(t));
      ASSERT_TRUE(r.ok) << r.error.message();
      hashes.push_back(world->stateHash());
    }
    recorder.finish();
  }
  ASSERT_EQ(world->counts().bodies, 4);
  const sgr::Recording r = sgr::readRecording(path);
  ASSERT_EQ(r.inputAt(5).bodies.size(), 2u);
  EXPECT_EQ(r.inputAt(5).bodies[0].kind, BodyCommandKind::Spawn);
  Player player(r);
  const VerifyReport v = player.verify();
  EXPECT_TRUE(v.ok) << "first mismatch at tick " << v.firstMismatchTick;
  EXPECT_EQ(v.ticks, 45);
  // Seek through snapshots taken after the spawn (10, 20, 30, 40), backwards, and to before it.
  for (const int64_t t : {int64_t(25), int64_t(13), int64_t(40), int64_t(3), int64_t(31), int64_t(45)}) {
    const StepResult sr = player.seek(t);
    ASSERT_TRUE(sr.ok) << sr.error.message();
    EXPECT_EQ(player.world().stateHash(), hashes[size_t(t - 1)]) << "after seeking to tick " << t;
    EXPECT_EQ(player.world().counts().bodies, t > 5 ? 4 : 2);
  }
}

// ---- DragTo: the viewer's mouse drag -------------------------------------------------------------

/// A 0.2 m ball resting on a small meadow (a sphere's drag has no lever arm to tumble it).
Scenario restingBall() {
  return parseScenario(R"({"format": "simgrass-scenario/1", "name": "drag",
      "field": {"patchesX": 21, "patchesZ": 21, "spacing": 0.25}, "wind": {"schedule": []},
      "bodies": {"list": [{"name": "ball", "position": [0, 0.2, 0], "shape": {"type": "sphere", "radius": 0.2}}]}})",
                       "drag.json", {});
}

template <class S>
double toMetres(S v) {
  return double(v);
}
template <>
double toMetres(Fx32 v) {
  return v.toDouble();
}
template <>
double toMetres(Fx16 v) {
  return v.toDouble();
}

template <class S>
void dragSettlesOnTheTarget() {
  // Box2D's mouse joint, 5 Hz and damping ratio 0.7, applied at the start of each tick: the centre
  // of mass reaches the target and hangs below it, the spring holding the weight. In steady state
  // the tick's pull dv = m_s (-v_end - b C) must return the g h that gravity took, while the mean
  // velocity over the tick is zero (v_end = -g h / 2): C = g h (1/2 - 1/m_s) / b, with m_s and b
  // the implicit coefficients (h omega = 0.52: m_s = 0.502, b = 16.3 /s), 15 mm (9.9 mm, g /
  // omega^2, in the continuous limit). The decay's time constant is ~1 / (zeta omega) = 45 ms:
  // after 1.5 s it hangs there within 3 mm (sub-steps integrate the fall inside the tick) and no
  // longer moves (under 0.1 mm over a further 10 ticks).
  auto w = makeTyped<S>(restingBall());
  const InputVec3 target = at(3, 5, -2, 2);  // (1.5, 2.5, -1) m
  stepN(*w, 90, command(0, BodyCommandKind::DragTo, target));
  const double h = 1.0 / 60, omega = 2 * 3.14159265358979 * 5, zeta = 0.7;
  const double a1 = 2 * zeta + h * omega, a2 = h * omega * a1, massScale = a2 / (1 + a2), bias = omega / a1;
  const double sag = 9.81 * h * (1 / massScale - 0.5) / bias;
  ASSERT_NEAR(sag, 0.015, 1e-3);
  const Vec3<S> before = w->bodies()[0].position;
  stepN(*w, 10, command(0, BodyCommandKind::DragTo, target));
  const RigidBody<S>& b = w->bodies()[0];
  EXPECT_NEAR(toMetres(b.position.x()), 1.5, 2e-3);
  EXPECT_NEAR(toMetres(b.position.y()), 2.5 - sag, 3e-3);
  EXPECT_NEAR(toMetres(b.position.z()), -1.0, 2e-3);
  for (int a = 0; a < 3; ++a)
    EXPECT_LT(std::fabs(toMetres(S(b.position[a] - before[a]))), 1e-4) << "still moving along axis " << a;
  // Let go: it falls back to the ground and comes to rest there.
  stepN(*w, 240);
  EXPECT_NEAR(toMetres(w->bodies()[0].position.y()), 0.2, 0.01);
}

TEST(BodyInputs, DragToSettlesOnTheTargetFx32) { dragSettlesOnTheTarget<Fx32>(); }
TEST(BodyInputs, DragToSettlesOnTheTargetFx16) { dragSettlesOnTheTarget<Fx16>(); }
TEST(BodyInputs, DragToSettlesOnTheTargetDouble) { dragSettlesOnTheTarget<double>(); }

TEST(BodyInputs, DragToAFarTargetIsBounded) {
  // A target a million metres away (a hostile or mistaken input) pulls at most 50 m/s per axis
  // a tick (settings::kDragMaxSpeedChange): bounded, no fault. fx16 holds 32,767 m: 30 km away.
  const InputVec3 far = at(1000000, -1000000, 1000000);
  auto fx16 = makeTyped<Fx16>(restingBall());
  ASSERT_TRUE(fx16->step(command(0, BodyCommandKind::DragTo, at(30000, -30000, 30000))).ok);
  EXPECT_LE(fx16->bodies()[0].velocity.x().toDouble(), 50.0 + 1e-4);
  auto fx32 = makeTyped<Fx32>(restingBall());
  ASSERT_TRUE(fx32->step(command(0, BodyCommandKind::DragTo, far)).ok);
  const double vx = fx32->bodies()[0].velocity.x().toDouble();
  EXPECT_GT(vx, 1.0);
  EXPECT_LE(vx, 50.0 + 1e-6);
  auto d = makeTyped<double>(restingBall());
  for (int t = 0; t < 3; ++t) ASSERT_TRUE(d->step(command(0, BodyCommandKind::DragTo, far)).ok);
  EXPECT_LE(d->bodies()[0].velocity.x(), 3 * 50.0 + 1e-9);
}

TEST(BodyInputs, DragToIsARecordedInputThatReplaysBitForBit) {
  // The viewer records one DragTo a tick while the mouse button is held: the drag is an input like
  // any other, so a recording of it verifies, and the script and track name it "dragTo".
  const Scenario s = restingBall();
  std::unique_ptr<SimWorld> world = makeWorld(s, 1);
  TempDir dir;
  const std::string path = dir.file("drag.sgr");
  {
    Recorder recorder(path, s, {}, *world, RecordSettings{});
    for (int64_t t = 0; t < 60; ++t) {
      // The target moves along a circle's chord, as a mouse would (exact sixtieths of a metre).
      const StepResult r = recorder.step(command(0, BodyCommandKind::DragTo, at(t, 30, 60 - t, 60)));
      ASSERT_TRUE(r.ok) << r.error.message();
    }
    recorder.finish();
  }
  const sgr::Recording r = sgr::readRecording(path);
  EXPECT_EQ(r.inputAt(7).bodies.at(0).kind, BodyCommandKind::DragTo);
  Player player(r);
  const VerifyReport v = player.verify();
  EXPECT_TRUE(v.ok) << "first mismatch at tick " << v.firstMismatchTick;
  const InputTrack track = parseInputTrack(R"({"format": "simgrass-input-track/1", "commands": [
      {"tick": 1, "body": "ball", "command": "dragTo", "value": [1, 2, 3]}]})",
                                           "track.json", s);
  ASSERT_EQ(track.commands.size(), 1u);
  EXPECT_EQ(track.commands[0].kind, BodyCommandKind::DragTo);
}

}  // namespace
}  // namespace sg
