// `simgrass diff` and `simgrass compare`: the divergence measures against hand-built
// observations with known answers, the heat map, the lock-step rule for time steps, and the two
// commands end to end on a small meadow with bodies.
#include <gtest/gtest.h>
#include <stb_image.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <sstream>

#include "cli_support.h"
#include "replay/divergence.h"
#include "replay/lockstep.h"
#include "test_support.h"

namespace sg {
namespace {

/// A px x pz field whose tips stand on a 0.25 m lattice, 1 m up, and `bodies` bodies at rest.
Observation field(int64_t px, int64_t pz, int bodies = 0) {
  Observation o;
  o.patchesX = px, o.patchesZ = pz;
  for (int64_t j = 0; j < pz; ++j)
    for (int64_t i = 0; i < px; ++i) {
      o.tipX.push_back(0.25 * double(i));
      o.tipY.push_back(1.0);
      o.tipZ.push_back(0.25 * double(j));
    }
  for (int b = 0; b < bodies; ++b) {
    o.bodyPosition.insert(o.bodyPosition.end(), {double(b), 0.5, -1.0});
    o.bodyOrientation.insert(o.bodyOrientation.end(), {1.0, 0.0, 0.0, 0.0});
  }
  return o;
}

TEST(Divergence, IdenticalObservationsMeasureZero) {
  const Observation a = field(5, 4, 2);
  const TickDivergence d = measureDivergence(a, a, true);
  EXPECT_EQ(d.tipMax, 0.0);
  EXPECT_EQ(d.tipRms, 0.0);
  EXPECT_EQ(d.bodyPosMax, 0.0);
  EXPECT_EQ(d.bodyAngleMax, 0.0);
  EXPECT_TRUE(d.identical);
  EXPECT_FALSE(d.observedDifference());
  EXPECT_FALSE(measureDivergence(a, a, false).identical);  // the flag is the caller's hash comparison
}

TEST(Divergence, TipErrorOfAKnownDisplacement) {
  const Observation a = field(2, 2);
  Observation b = a;
  b.tipX[3] += 3e-3;  // one tip of four moves 5 mm (a 3-4-5 triangle)
  b.tipY[3] -= 4e-3;
  const TickDivergence d = measureDivergence(a, b, false);
  EXPECT_NEAR(d.tipMax, 5e-3, 1e-15);
  EXPECT_NEAR(d.tipRms, std::sqrt(25e-6 / 4.0), 1e-15);  // 2.5 mm
  EXPECT_TRUE(d.observedDifference());
  const std::vector<double> dist = tipDistances(a, b);
  ASSERT_EQ(dist.size(), 4u);
  EXPECT_EQ(dist[0], 0.0);
  EXPECT_NEAR(dist[3], 5e-3, 1e-15);
}

TEST(Divergence, BodyAngleOfAKnownRotation) {
  Observation a = field(1, 1, 1), b = a;
  const double h = std::sqrt(0.5);
  b.bodyOrientation = {h, 0.0, h, 0.0};  // 90 degrees about y
  EXPECT_NEAR(measureDivergence(a, b, false).bodyAngleMax, std::numbers::pi / 2, 1e-12);
  EXPECT_EQ(measureDivergence(a, b, false).bodyPosMax, 0.0);

  // q and -q are the same rotation; a tiny rotation is measured accurately (2 acos(|dot|)
  // would return 0 or ~3e-8 for it).
  const double qa[4] = {0.5, 0.5, 0.5, 0.5}, qaNeg[4] = {-0.5, -0.5, -0.5, -0.5};
  EXPECT_EQ(relativeRotationAngle(qa, qaNeg), 0.0);
  const double eps = 1e-12;
  const double qi[4] = {1, 0, 0, 0}, qTiny[4] = {std::cos(eps / 2), 0, 0, std::sin(eps / 2)};
  EXPECT_NEAR(relativeRotationAngle(qi, qTiny), eps, 1e-24);
  // 180 degrees about x, from a rotated start: the relative rotation, not the absolute ones.
  const double q1[4] = {h, 0, h, 0}, q2[4] = {0, h, 0, -h};  // q2 = q1 * (0, 1, 0, 0)
  EXPECT_NEAR(relativeRotationAngle(q1, q2), std::numbers::pi, 1e-12);

  b = a;
  b.bodyPosition[1] += 0.25;
  b.contacts = 2;
  const TickDivergence d = measureDivergence(a, b, false);
  EXPECT_NEAR(d.bodyPosMax, 0.25, 1e-15);
  EXPECT_EQ(d.contactsA, 0);
  EXPECT_EQ(d.contactsB, 2);
}

TEST(Divergence, MismatchedObservationsAreRefused) {
  const Observation a = field(3, 3), b = field(3, 4), c = field(3, 3, 1);
  EXPECT_EQ(observationMismatch(a, a), "");
  EXPECT_EQ(observationMismatch(a, b), "3 x 3 patches, 0 bodies vs 3 x 4 patches, 0 bodies");
  EXPECT_THROW(measureDivergence(a, b, false), std::invalid_argument);
  // Other body counts are comparable (a run may spawn bodies): the common bodies are measured.
  const TickDivergence spawned = measureDivergence(a, c, false);
  EXPECT_EQ(spawned.bodiesA, 0);
  EXPECT_EQ(spawned.bodiesB, 1);
  EXPECT_TRUE(spawned.observedDifference());
  std::string error;
  TempDir dir;
  EXPECT_FALSE(writeDivergencePng(dir.file("x.png"), a, b, &error));
  EXPECT_NE(error.find("x.png: expected observations of the same field"), std::string::npos) << error;
}

TEST(Divergence, SummaryKeepsMaximaAndFirstTicks) {
  DivergenceSummary s;
  TickDivergence d;
  d.identical = true;
  s.add(d);  // tick 0: the same
  d.tick = 1, d.identical = false;
  s.add(d);  // tick 1: the hash differs, nothing measured does
  d.tick = 2, d.tipMax = 3e-3, d.tipRms = 1e-3, d.contactsB = 2;
  s.add(d);
  d.tick = 3, d.tipMax = 2e-3, d.tipRms = 1e-3, d.bodyAngleMax = 0.5, d.contactsB = 0;
  s.add(d);
  EXPECT_EQ(s.ticks, 4);
  EXPECT_EQ(s.firstHashTick, 1);
  EXPECT_EQ(s.firstObservedTick, 2);
  EXPECT_EQ(s.tipMax, 3e-3);
  EXPECT_EQ(s.tipMaxTick, 2);
  EXPECT_NEAR(s.tipRms(), std::sqrt(2e-6 / 4.0), 1e-18);
  EXPECT_EQ(s.bodyAngleMax, 0.5);
  EXPECT_EQ(s.contactDeltaMax, 2);
  d.tick = 4, d.tipMax = std::nan("");
  s.add(d);  // a run that blew up must not read as "no error"
  EXPECT_TRUE(std::isnan(s.tipMax));
  EXPECT_EQ(s.tipMaxTick, 4);
}

struct Image {
  int w = 0, h = 0;
  std::vector<uint8_t> rgb;
  const uint8_t* at(int x, int y) const { return &rgb[(size_t(y) * size_t(w) + size_t(x)) * 3]; }
};

Image readPng(const std::string& path) {
  Image img;
  int channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &img.w, &img.h, &channels, 3);
  if (!data) {
    ADD_FAILURE() << path << " does not decode";
    return img;
  }
  img.rgb.assign(data, data + size_t(img.w) * size_t(img.h) * 3);
  stbi_image_free(data);
  return img;
}

double luminance(const uint8_t* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

TEST(Divergence, HeatMapShowsTheHotPatch) {
  TempDir dir;
  const Observation a = field(20, 10);
  Observation b = a;
  b.tipY[size_t(7 * 20 + 13)] += 0.1;  // patch (i 13, j 7) hot, a neighbour warm
  b.tipY[size_t(7 * 20 + 12)] += 0.05;
  std::string error;
  ASSERT_TRUE(writeDivergencePng(dir.file("heat.png"), a, b, &error)) << error;
  const Image img = readPng(dir.file("heat.png"));
  ASSERT_GE(img.w, 512);
  const int scale = (512 + 19) / 20;  // 26 px per patch
  ASSERT_GE(img.h, 10 * scale);
  const int x0 = (img.w - 20 * scale) / 2;
  auto patch = [&](int i, int j) { return img.at(x0 + i * scale + scale / 2, j * scale + scale / 2); };
  EXPECT_GT(luminance(patch(13, 7)), luminance(patch(12, 7)));
  EXPECT_GT(luminance(patch(12, 7)), luminance(patch(0, 0)));
  uint8_t hot[3], cold[3];
  divergenceColour(1.0, hot);
  divergenceColour(0.0, cold);
  EXPECT_EQ(std::vector<uint8_t>(patch(13, 7), patch(13, 7) + 3), std::vector<uint8_t>(hot, hot + 3));
  EXPECT_EQ(std::vector<uint8_t>(patch(5, 2), patch(5, 2) + 3), std::vector<uint8_t>(cold, cold + 3));
}

TEST(Divergence, ZeroDivergenceIsAUniformImage) {
  TempDir dir;
  const Observation a = field(151, 151);
  std::string error;
  ASSERT_TRUE(writeDivergencePng(dir.file("zero.png"), a, a, &error)) << error;
  const Image img = readPng(dir.file("zero.png"));
  ASSERT_GE(img.w, 512);
  const int scale = (512 + 150) / 151;
  const int x0 = (img.w - 151 * scale) / 2;
  for (int y = 0; y < 151 * scale; y += 7)
    for (int x = x0; x < x0 + 151 * scale; x += 7)
      ASSERT_EQ(std::vector<uint8_t>(img.at(x, y), img.at(x, y) + 3),
                std::vector<uint8_t>(img.at(x0, 0), img.at(x0, 0) + 3))
          << "pixel " << x << ", " << y;
}

TEST(Divergence, ColourRampIsMonotoneInLightness) {
  double previous = -1;
  for (int k = 0; k <= 64; ++k) {
    uint8_t c[3];
    divergenceColour(k / 64.0, c);
    EXPECT_GT(luminance(c), previous) << k;
    previous = luminance(c);
  }
  uint8_t below[3], above[3], nan[3], zero[3], one[3];
  divergenceColour(-1, below), divergenceColour(2, above), divergenceColour(std::nan(""), nan);
  divergenceColour(0, zero), divergenceColour(1, one);
  EXPECT_EQ(0, std::memcmp(below, zero, 3));
  EXPECT_EQ(0, std::memcmp(above, one, 3));
  EXPECT_EQ(0, std::memcmp(nan, one, 3));
}

// ---- lock-step time bases --------------------------------------------------------------

TEST(CompareLockStep, TimeStepsLineUpOnlyByWholeRatios) {
  const Rational r60{1, 60}, r120{1, 120}, r30{1, 30}, r90{1, 90};
  ASSERT_TRUE(lineUp(r60, r120));
  EXPECT_EQ(lineUp(r60, r120)->aSteps, 1);
  EXPECT_EQ(lineUp(r60, r120)->bSteps, 2);
  EXPECT_EQ(lineUp(r60, r30)->aSteps, 2);
  EXPECT_EQ(lineUp(r60, r30)->bSteps, 1);
  EXPECT_EQ(lineUp(r60, r60)->aSteps, 1);
  EXPECT_EQ(lineUp(r60, r60)->bSteps, 1);
  EXPECT_FALSE(lineUp(r60, r90));
  EXPECT_FALSE(lineUp(Rational{1, 50}, r60));
}

TEST(CompareLockStep, MergedInputsKeepCommandsInOrderAndTheLastCamera) {
  sgr::Recording rec;
  auto command = [](int32_t body, int64_t x) {
    return BodyCommand{body, BodyCommandKind::AddVelocity, InputVec3{x, 0, 0}};
  };
  sgr::InputRecord t1, t2;
  t1.tick = 1;
  t1.input.hasCamera = true;
  t1.input.camera = {1, 2, 3};
  t1.input.bodies = {command(0, 10), command(1, 11)};
  t2.tick = 2;
  t2.input.hasCamera = true;
  t2.input.camera = {4, 5, 6};
  t2.input.bodies = {command(0, 20)};
  rec.inputs = {t1, t2};
  const TickInput merged = LockStepReplay::mergedInput(rec, 0, 4);  // ticks 0..3
  ASSERT_EQ(merged.bodies.size(), 3u);
  EXPECT_EQ(merged.bodies[0], command(0, 10));
  EXPECT_EQ(merged.bodies[1], command(1, 11));
  EXPECT_EQ(merged.bodies[2], command(0, 20));
  EXPECT_TRUE(merged.hasCamera);
  EXPECT_EQ(merged.camera, (InputVec3{4, 5, 6}));  // tick 3 carries tick 2's camera
  EXPECT_EQ(LockStepReplay::mergedInput(rec, 0, 1), TickInput{});
  EXPECT_EQ(LockStepReplay::mergedInput(rec, 2, 1), t2.input);
}

// ---- the commands end to end ------------------------------------------------------------

/// A 31 x 31 meadow (0.5 m rods, 7.75 m across) where a football runs into a box.
constexpr const char* kSmallScenario = R"({
  "name": "small-bodies", "timeStep": "1/60",
  "field": {"patchesX": 31, "patchesZ": 31, "spacing": 0.25},
  "particles": {"constraintLength": 0.5, "tiltDrop": [0.1, 0.15, 0.2]},
  "bodies": {
    "substeps": 2,
    "list": [
      {"name": "football", "shape": {"type": "sphere", "radius": 0.3}, "mass": 0.45, "position": [-2, 0.3, -0.2],
       "restitution": 0.6, "friction": 0.6},
      {"name": "box", "shape": {"type": "box", "halfExtents": [0.35, 0.35, 0.35]}, "mass": 5, "position": [2, 0.35, 0]}
    ]
  },
  "script": [
    {"tick": 2, "body": "football", "command": "addVelocity", "value": [5, 0, 0.5]},
    {"tick": 3, "body": "box", "command": "addVelocity", "value": [-3, 0, 0]},
    {"tick": 25, "body": "football", "command": "impulse", "value": [0, 1, 0]}
  ]
})";

int64_t cliTicks() { return test::slowBuild() ? 24 : 60; }

/// Records the small scenario (or another) under `variant` to dir/name; returns the path.
std::string record(const TempDir& dir, const std::string& name, const std::string& variant = "",
                   int64_t ticks = cliTicks(), const std::string& scenario = "small.json") {
  const std::string scenarioPath = dir.path() / scenario;
  if (!fs::exists(scenarioPath)) dir.write(scenario, kSmallScenario);
  const std::string out = dir.file(name);
  const CliResult r = runCli("record " + quote(scenarioPath) + " -o " + quote(out) + " --ticks " +
                             std::to_string(ticks) + (variant.empty() ? "" : " --variant " + quote(variant)));
  EXPECT_EQ(r.exitCode, 0) << r.describe();
  return out;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

TEST(DiffCli, IdenticalRunsReportZeroEverywhere) {
  TempDir dir;
  const std::string a = record(dir, "a.sgr"), b = record(dir, "b.sgr");
  for (const std::string& other : {a, b}) {  // a recording with itself, and with a second identical run
    const CliResult r = runCli("diff " + quote(a) + " " + quote(other) + " --json --csv " + quote(dir.file("d.csv")));
    ASSERT_EQ(r.exitCode, 0) << r.describe();
    EXPECT_EQ(r.err, "");
    const json j = parseJson(r);
    EXPECT_EQ(j["firstDivergentTick"], -1);
    EXPECT_EQ(j["divergenceBy"], "hash");
    EXPECT_EQ(j["identical"], true);
    EXPECT_EQ(j["hashesComparable"], true);
    EXPECT_EQ(j["statesCompared"], cliTicks() + 1);
    for (const char* key : {"tipMax", "tipRms", "bodyPositionMax", "bodyAngleMax", "contactDeltaMax"})
      EXPECT_EQ(j[key], 0) << key;
    EXPECT_EQ(j["a"]["verified"], true);
    EXPECT_EQ(j["b"]["hashesChecked"], cliTicks() + 1);
    ASSERT_EQ(j["series"].size(), size_t(cliTicks() + 1));
    for (const json& t : j["series"]) EXPECT_EQ(t["identical"], true) << t.dump();
    const std::vector<std::string> csv = lines(readFile(dir.file("d.csv")));
    ASSERT_EQ(csv.size(), size_t(cliTicks() + 2));
    EXPECT_EQ(csv[0], "tick,tip_max_m,tip_rms_m,body_pos_max_m,body_angle_max_rad,contacts_a,contacts_b,identical");
    EXPECT_EQ(csv[5].substr(0, 10), "4,0,0,0,0,");  // tick 4, all zero
    EXPECT_EQ(csv.back().back(), '1');
  }
  const CliResult text = runCli("diff " + quote(a) + " " + quote(b));
  EXPECT_EQ(text.exitCode, 0) << text.describe();
  EXPECT_NE(text.out.find("divergence  none"), std::string::npos) << text.out;
}

TEST(DiffCli, InterpolationVariantsDivergeWithAHeatMap) {
  TempDir dir;
  const std::string a = record(dir, "k1.sgr", "interp=1"), b = record(dir, "k2.sgr", "interp=2");
  const CliResult r = runCli("diff " + quote(a) + " " + quote(b) + " --json --heatmap " + quote(dir.file("h.png")) +
                             " --heatmap-tick max");
  ASSERT_EQ(r.exitCode, 1) << r.describe();  // like diff(1): the runs differ
  EXPECT_EQ(r.err, "");
  const json j = parseJson(r);
  EXPECT_EQ(j["hashesComparable"], false);
  EXPECT_EQ(j["divergenceBy"], "observation");
  EXPECT_GT(j["tipMax"].get<double>(), 0.0);
  EXPECT_GT(j["tipRms"].get<double>(), 0.0);
  EXPECT_LT(j["tipMax"].get<double>(), 0.5);  // a tip cannot move further than its rod allows
  // The first divergent tick is the first tick whose measured error is not zero.
  const int64_t first = j["firstDivergentTick"];
  ASSERT_GE(first, 1);
  for (const json& t : j["series"]) {
    const bool differs = t["tipMax"].get<double>() > 0 || t["bodyPositionMax"].get<double>() > 0 ||
                         t["bodyAngleMax"].get<double>() > 0 || t["contactsA"] != t["contactsB"];
    EXPECT_EQ(differs, t["tick"] == first) << t.dump();
    if (differs) break;
  }
  EXPECT_EQ(j["heatmap"]["tick"], j["tipMaxTick"]);
  const Image img = readPng(dir.file("h.png"));
  EXPECT_GE(img.w, 512);
}

TEST(DiffCli, TimeStepsLineUpOrAreRefused) {
  TempDir dir;
  const std::string a = record(dir, "60.sgr"), b = record(dir, "120.sgr", "dt=1/120");
  const CliResult r = runCli("diff " + quote(a) + " " + quote(b) + " --json");
  ASSERT_EQ(r.exitCode, 1) << r.describe();
  const json j = parseJson(r);
  EXPECT_EQ(j["b"]["ticksPerStep"], 2);
  EXPECT_EQ(j["statesCompared"], cliTicks() / 2 + 1);  // B covers half of A's time
  EXPECT_EQ(j["lastTick"], cliTicks() / 2);
  EXPECT_GT(j["tipMax"].get<double>(), 0.0);

  const std::string c = record(dir, "90.sgr", "dt=1/90");
  const CliResult bad = runCli("diff " + quote(a) + " " + quote(c));
  EXPECT_EQ(bad.exitCode, 2) << bad.describe();
  EXPECT_TRUE(isOneLine(bad.err));
  EXPECT_NE(bad.err.find("90.sgr: expected a time step that is a whole multiple or fraction"), std::string::npos)
      << bad.err;
}

TEST(DiffCli, BadInputIsOneLine) {
  TempDir dir;
  const std::string a = record(dir, "a.sgr", "", 4);
  dir.write("wide.json", std::string(kSmallScenario)
                             .replace(std::string(kSmallScenario).find("\"patchesX\": 31"), 14, "\"patchesX\": 33"));
  const std::string wide = record(dir, "wide.sgr", "", 4, "wide.json");
  dir.write("junk.sgr", "not a recording");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"diff " + quote(a) + " " + quote(wide), "wide.sgr: expected a recording of a field like"},
      {"diff " + quote(a) + " " + quote(dir.file("junk.sgr")), "junk.sgr: byte 0"},
      {"diff " + quote(a) + " " + quote(dir.file("missing.sgr")), "missing.sgr"},
      {"diff " + quote(a) + " " + quote(a) + " --heatmap " + quote(dir.file("h.png")) + " --heatmap-tick 5",
       "--heatmap-tick 5: expected 'last', 'max' or a tick from 0 to 4"},
      {"diff " + quote(a) + " " + quote(a) + " --csv " + quote(dir.file("no/such/folder.csv")),
       "folder.csv: expected a CSV file"},
  };
  for (const auto& [args, expected] : cases) {
    const CliResult r = runCli(args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << args;
    EXPECT_NE(r.err.find(expected), std::string::npos) << args << "\n" << r.err;
  }
}

TEST(DiffCli, ACutOffRecordingAgreeingInFullExitsThreeAsReplayDoes) {
  // A recording killed mid-run (here: its last 40 bytes cut, inside the END chunk or the last
  // tick) is used up to its last complete chunk; agreeing there is not a clean exit 0.
  TempDir dir;
  const std::string a = record(dir, "a.sgr");
  std::vector<uint8_t> bytes = readBytes(a);
  bytes.resize(bytes.size() - 40);
  const std::string cut = dir.file("cut.sgr");
  writeBytes(cut, bytes);
  const CliResult replay = runCli("replay " + quote(cut));
  ASSERT_EQ(replay.exitCode, 3) << replay.describe();
  const CliResult diff = runCli("diff " + quote(a) + " " + quote(cut) + " --json");
  EXPECT_EQ(diff.exitCode, 3) << diff.describe();
  EXPECT_TRUE(isOneLine(diff.err)) << diff.err;
  EXPECT_NE(diff.err.find("cut.sgr: byte"), std::string::npos) << diff.err;
  const json j = parseJson(diff);
  EXPECT_EQ(j["b"]["truncated"], true);
  EXPECT_EQ(j["a"]["truncated"], false);
  EXPECT_EQ(j["identical"], true);
  const CliResult compare = runCli("compare " + quote(cut) + " --variant threads=2 --json");
  EXPECT_EQ(compare.exitCode, 3) << compare.describe();
  EXPECT_EQ(parseJson(compare)["truncated"], true);
  // A real divergence still wins over the cut: exit 1.
  const std::string k2 = record(dir, "k2.sgr", "interp=2");
  EXPECT_EQ(runCli("diff " + quote(k2) + " " + quote(cut)).exitCode, 1);
}

TEST(CompareCli, BroadPhasesAndThreadsAreIdentical) {
  TempDir dir;
  const std::string run = record(dir, "run.sgr");
  const CliResult r = runCli("compare " + quote(run) +
                             " --variant broadphase=brute --variant body-broadphase=sap --variant threads=2 --json");
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  EXPECT_EQ(r.err, "");
  const json j = parseJson(r);
  EXPECT_EQ(j["ok"], true);
  EXPECT_EQ(j["reference"]["verified"], true);
  EXPECT_EQ(j["reference"]["hashesChecked"], cliTicks() + 1);  // the start state and every tick
  ASSERT_EQ(j["variants"].size(), 3u);
  for (const json& v : j["variants"]) {
    EXPECT_EQ(v["mustBeIdentical"], true) << v.dump();
    EXPECT_EQ(v["status"], "identical") << v.dump();
    EXPECT_EQ(v["firstDivergentTick"], -1) << v.dump();
    EXPECT_EQ(v["divergenceBy"], "hash");
    EXPECT_EQ(v["tipMax"], 0);
    EXPECT_EQ(v["bodyPositionMax"], 0);
    EXPECT_EQ(v["statesCompared"], cliTicks() + 1);
  }
  EXPECT_EQ(j["variants"][2]["settings"].get<std::string>().find("threads=2") != std::string::npos, true);
}

TEST(CompareCli, StateChangingVariantsReportFiniteErrors) {
  TempDir dir;
  const std::string run = record(dir, "run.sgr");
  const CliResult r =
      runCli("compare " + quote(run) +
             " --variant scalar=fx16 --variant dt=1/120 --variant dt=1/30 --variant scalar=fx16,interp=2 --json"
             " --csv " +
             quote(dir.file("c.csv")) + " --series " + quote(dir.file("s.csv")));
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  const json j = parseJson(r);
  ASSERT_EQ(j["variants"].size(), 4u);
  EXPECT_EQ(j["variants"][3]["variant"], "scalar=fx16 interp=2");  // one --variant with a comma: one row
  for (const json& v : j["variants"]) {
    EXPECT_EQ(v["mustBeIdentical"], false) << v.dump();
    EXPECT_EQ(v["status"], "differs") << v.dump();
    EXPECT_EQ(v["divergenceBy"], "observation");
    const double tip = v["tipMax"].get<double>();
    EXPECT_TRUE(std::isfinite(tip) && tip > 0 && tip < 0.5) << v.dump();
    EXPECT_GT(v["tipRms"].get<double>(), 0.0);
    EXPECT_GE(v["firstDivergentTick"].get<int64_t>(), 0);
    EXPECT_GT(v["msPerTick"].get<double>(), 0.0);
  }
  EXPECT_EQ(j["variants"][1]["substepsPerTick"], 2);  // dt=1/120: two steps per recorded tick
  EXPECT_EQ(j["variants"][2]["ticksPerStep"], 2);     // dt=1/30: one step per two recorded ticks
  EXPECT_EQ(j["variants"][2]["statesCompared"], cliTicks() / 2 + 1);
  EXPECT_GT(j["variants"][1]["bodyPositionMax"].get<double>(), 0.0);  // the bodies move differently

  const std::vector<std::string> csv = lines(readFile(dir.file("c.csv")));
  ASSERT_EQ(csv.size(), 6u);  // header, the reference, four variants
  EXPECT_EQ(csv[0],
            "variant,settings,must_be_identical,status,ms_per_tick,tip_max_m,tip_rms_m,body_pos_max_m,"
            "body_angle_max_rad,contact_delta_max,first_divergent_tick,divergence_by,states_compared");
  EXPECT_EQ(csv[1].substr(0, 10), "reference,");
  EXPECT_EQ(csv[5].substr(0, 21), "scalar=fx16 interp=2,");
  const std::vector<std::string> series = lines(readFile(dir.file("s.csv")));
  EXPECT_EQ(series[0],
            "variant,tick,tip_max_m,tip_rms_m,body_pos_max_m,body_angle_max_rad,contacts_a,contacts_b,identical");
  EXPECT_EQ(series.size(), size_t(1 + 3 * (cliTicks() + 1) + cliTicks() / 2 + 1));

  const CliResult text = runCli("compare " + quote(run) + " --variant interp=2 --ticks 10");
  ASSERT_EQ(text.exitCode, 0) << text.describe();
  EXPECT_NE(text.out.find("verified (11 hashed ticks match)"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("interp=2"), std::string::npos) << text.out;
}

TEST(CompareCli, BadVariantsAreOneLine) {
  TempDir dir;
  const std::string run = record(dir, "run.sgr", "", 4);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--variant lod=maybe", "--variant lod=maybe: expected lod=off or window"},
      {"--variant interp=7", "--variant interp=7: expected interp=1, 2, 3 or 4"},
      {"--variant dt=1/90", "--variant dt=1/90: expected a time step that is a whole multiple"},
      {"--variant dt=1/10", "--variant dt=1/10: expected at least 6 recorded ticks"},
      {"--variant interp=2 --ticks 9", "--ticks: expected 1 to 4"},
  };
  for (const auto& [args, expected] : cases) {
    const CliResult r = runCli("compare " + quote(run) + " " + args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << args;
    EXPECT_NE(r.err.find(expected), std::string::npos) << args << "\n" << r.err;
  }
  // The recording may follow the options.
  const CliResult r = runCli("compare --variant interp=2 " + quote(run));
  EXPECT_EQ(r.exitCode, 0) << r.describe();
}

}  // namespace
}  // namespace sg
