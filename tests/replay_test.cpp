// Record -> replay -> verify for every scenario and scalar; seeking through snapshots equals the
// uninterrupted run; input tracks and variant settings; the committed recordings under
// scenarios/recordings/ still replay to their committed hashes.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "replay/cli/cli_common.h"
#include "replay/format/sgr_reader.h"
#include "replay/player.h"
#include "replay/recorder.h"
#include "sim/state/byte_order.h"
#include "tests/cli_support.h"
#include "tests/state_sections.h"
#include "tests/test_support.h"

namespace sg {
namespace {

struct Recorded {
  std::vector<uint64_t> hashes;  ///< state hash after each tick, from the uninterrupted run
  sgr::Recording recording;
};

/// Records `ticks` ticks of a scenario file (scripted input) under a scalar into `dir`.
Recorded recordScenario(const TempDir& dir, const std::string& scenarioFile, ScalarKind scalar, int64_t ticks,
                        RecordSettings settings) {
  std::vector<sgr::EmbeddedFile> files;
  Scenario s = loadScenarioFile(scenarioFile, &files);
  s.scalar = scalar;
  std::unique_ptr<SimWorld> world = makeWorld(s, 1);
  const std::string path = dir.file("run.sgr");
  Recorded out;
  {
    Recorder recorder(path, s, files, *world, settings);
    for (int64_t t = 0; t < ticks; ++t) {
      const StepResult r = recorder.step(scriptedInput(s, world->tick()));
      EXPECT_TRUE(r.ok) << r.error.message();
      out.hashes.push_back(world->stateHash());
    }
    recorder.finish();
  }
  out.recording = sgr::readRecording(path);
  return out;
}

struct ScenarioCase {
  const char* file;
  int64_t ticks;  ///< Release build; the sanitizer build runs fewer
};
void PrintTo(const ScenarioCase& c, std::ostream* os) { *os << c.file << ", " << c.ticks << " ticks"; }

class RecordReplay : public testing::TestWithParam<std::tuple<ScenarioCase, ScalarKind>> {};

TEST_P(RecordReplay, EveryCheckMatchesAndSeekEqualsTheUninterruptedRun) {
  const auto [scenarioCase, scalar] = GetParam();
  const bool million = std::string(scenarioCase.file).find("million") != std::string::npos;
  if (million && test::slowBuild()) GTEST_SKIP() << "1,000,000 patches: Release builds only";
  const int64_t ticks = test::slowBuild() ? std::min<int64_t>(scenarioCase.ticks, 12) : scenarioCase.ticks;
  TempDir dir;
  RecordSettings settings;
  settings.snapshotEvery = uint32_t(std::max<int64_t>(2, ticks / 3));
  settings.checkEvery = 1;
  const Recorded rec =
      recordScenario(dir, test::sourcePath(std::string("scenarios/") + scenarioCase.file), scalar, ticks, settings);
  const sgr::Recording& r = rec.recording;
  ASSERT_TRUE(r.end.has_value());
  EXPECT_FALSE(r.truncated);
  EXPECT_EQ(r.end->tick, ticks);
  EXPECT_EQ(r.checks.size(), size_t(ticks));
  EXPECT_EQ(r.snapshots.size(), size_t(ticks / settings.snapshotEvery));

  Player player(r);
  const VerifyReport v = player.verify();
  EXPECT_TRUE(v.ok) << "first mismatch at tick " << v.firstMismatchTick;
  EXPECT_EQ(v.ticks, ticks);
  // Every tick 1..N has a CHCK (snapshots and END fall on checked ticks), plus the start: N + 1.
  EXPECT_EQ(v.checksVerified, ticks + 1);
  EXPECT_EQ(v.checksVerified, r.hashedTicks());

  // Seek at a snapshot, between snapshots, before the first one, backwards, and to 0.
  const int64_t m = settings.snapshotEvery;
  for (const int64_t t : {m, m + 1, m - 1, 2 * m - 1, int64_t(1), ticks, int64_t(0), m + m / 2}) {
    if (t > ticks) continue;
    const StepResult s = player.seek(t);
    ASSERT_TRUE(s.ok) << s.error.message();
    ASSERT_EQ(player.tick(), t);
    const uint64_t expected = t == 0 ? r.header.initialStateHash : rec.hashes[size_t(t - 1)];
    EXPECT_EQ(player.world().stateHash(), expected) << "after seeking to tick " << t;
  }
}

const ScenarioCase kScenarios[] = {
    {"thesis-meadow.json", 60}, {"hilly-meadow.json", 60},  {"thesis-bodies.json", 90},
    {"mower-field.json", 90},   {"million-meadow.json", 4}, {"lod-crossing.json", 90},
};
INSTANTIATE_TEST_SUITE_P(Scenarios, RecordReplay,
                         testing::Combine(testing::ValuesIn(kScenarios),
                                          testing::Values(ScalarKind::Fx32, ScalarKind::Fx16, ScalarKind::Float,
                                                          ScalarKind::Double)),
                         [](const auto& info) {
                           std::string name = std::get<0>(info.param).file;
                           name = name.substr(0, name.find('.'));
                           for (char& c : name)
                             if (c == '-') c = '_';
                           return name + "_" + scalarName(std::get<1>(info.param));
                         });

TEST(RecordReplay, SnapshotsAloneAreEnoughToSeek) {
  // No CHCK chunks at all: seeking still restores snapshots and checks their hashes.
  TempDir dir;
  RecordSettings settings;
  settings.checkEvery = 0;
  settings.snapshotEvery = 5;
  const Recorded rec =
      recordScenario(dir, test::sourcePath("scenarios/thesis-bodies.json"), ScalarKind::Fx32, 17, settings);
  EXPECT_TRUE(rec.recording.checks.empty());
  Player player(rec.recording);
  ASSERT_TRUE(player.seek(12).ok);
  EXPECT_EQ(player.world().stateHash(), rec.hashes[11]);
  EXPECT_TRUE(player.verify().ok);
}

TEST(RecordReplay, VerifyReportsTheFirstTickThatDiffers) {
  // Replaying under other physics (a different time step) must be caught at the first check.
  TempDir dir;
  const Recorded rec = recordScenario(dir, test::sourcePath("scenarios/thesis-meadow.json"), ScalarKind::Fx32,
                                      test::slowBuild() ? 4 : 10, RecordSettings{});
  VariantSettings other;
  other.timeStep = Rational{1, 61};
  Player player(rec.recording, 1, other);
  EXPECT_FALSE(player.sameSettingsAsRecorded());
  const VerifyReport v = player.verify();
  EXPECT_FALSE(v.ok);
  EXPECT_EQ(v.firstMismatchTick, 1);
  EXPECT_EQ(v.expectedHash, rec.hashes[0]);
  EXPECT_NE(v.actualHash, v.expectedHash);
}

TEST(RecordReplay, OnlyChangedInputIsWritten) {
  // Camera held for 10 ticks, then moved; commands on two ticks: INPT chunks only where something changed.
  Scenario s = loadScenarioFile(test::sourcePath("scenarios/thesis-bodies.json"));
  std::unique_ptr<SimWorld> world = makeWorld(s, 1);
  TempDir dir;
  {
    Recorder recorder(dir.file("in.sgr"), s, {}, *world, RecordSettings{});
    for (int t = 0; t < 20; ++t) {
      TickInput in;
      in.hasCamera = true;
      in.camera = InputVec3{int64_t(t < 10 ? 1 : 2) << 32, 0, 0};
      if (t == 3 || t == 15)
        in.bodies.push_back(BodyCommand{1, BodyCommandKind::AddVelocity, InputVec3{int64_t(1) << 31, 0, 0}});
      ASSERT_TRUE(recorder.step(in).ok);
    }
    recorder.finish();
  }
  const sgr::Recording r = sgr::readRecording(dir.file("in.sgr"));
  std::vector<int64_t> ticks;
  for (const sgr::InputRecord& i : r.inputs) ticks.push_back(i.tick);
  EXPECT_EQ(ticks, (std::vector<int64_t>{0, 3, 10, 15}));
  EXPECT_TRUE(r.inputAt(7).hasCamera);
  EXPECT_EQ(r.inputAt(7).camera.x, int64_t(1) << 32);
  EXPECT_TRUE(r.inputAt(7).bodies.empty());
  EXPECT_EQ(r.inputAt(12).camera.x, int64_t(2) << 32);
  ASSERT_EQ(r.inputAt(15).bodies.size(), 1u);
  EXPECT_EQ(r.inputAt(15).bodies[0].body, 1);
  EXPECT_TRUE(Player(r).verify().ok);
}

/// A recording assembled chunk by chunk (valid checksums), to test the reader's consistency rules.
std::vector<uint8_t> assemble(const std::vector<std::pair<sgr::ChunkType, std::vector<uint8_t>>>& chunks) {
  std::vector<uint8_t> out(sgr::kPreambleBytes);
  std::memcpy(out.data(), sgr::kMagic, sizeof sgr::kMagic);
  std::memcpy(out.data() + sizeof sgr::kMagic, &sgr::kFormatVersion, 4);
  for (const auto& [type, payload] : chunks) {
    const std::vector<uint8_t> c = sgr::frameChunk(type, payload);
    out.insert(out.end(), c.begin(), c.end());
  }
  return out;
}

std::string readerError(std::vector<uint8_t> bytes) {
  try {
    sgr::parseRecording(std::move(bytes), "x.sgr");
  } catch (const sgr::RecordingError& e) {
    return e.what();
  }
  return "no error";
}

TEST(RecordingReader, ChecksMustFollowTheirIntervalAndEndMustBeCoveredByThem) {
  sgr::Header h;
  h.checkEvery = 2;
  h.snapshotEvery = 0;
  h.variant = "scalar=fx32";
  h.scenarioHash = XXH3_64bits("", 0);
  using T = sgr::ChunkType;
  const auto head = std::make_pair(T::Head, sgr::encodeHead(h));
  auto check = [](int64_t t) { return std::make_pair(T::Check, sgr::encodeCheck({t, 7})); };
  auto end = [](int64_t t) { return std::make_pair(T::End, sgr::encodeEnd({t, 7, false, ""})); };
  EXPECT_EQ(readerError(assemble({head, check(2), check(4), end(5)})), "no error");
  // A missing CHCK (tick 4 dropped) is damage, not a shorter recording.
  EXPECT_NE(readerError(assemble({head, check(2), check(6)})).find("expected the check of tick 4, got tick 6"),
            std::string::npos);
  // An END far beyond the last check would make a replay run for ever.
  EXPECT_NE(readerError(assemble({head, check(2), end(1000000000000)}))
                .find("a final tick from 2 to 3 (before the next check or snapshot, due at tick 4)"),
            std::string::npos);
  EXPECT_NE(readerError(
                assemble({head, std::make_pair(T::Snapshot, sgr::encodeSnapshot(5, 1, std::vector<uint8_t>(9, 1), 1))}))
                .find("no SNAP chunk (HEAD says snapshotEvery = 0)"),
            std::string::npos);
  EXPECT_NE(readerError(assemble({check(2)})).find("byte 12: expected the HEAD chunk first"), std::string::npos);
}

TEST(InputTrack, CameraKeysHoldAndCommandsApplyOnTheirTick) {
  const Scenario s = loadScenarioFile(test::sourcePath("scenarios/thesis-bodies.json"));
  const InputTrack track = parseInputTrack(R"({"format": "simgrass-input-track/1", "ticks": 30,
      "camera": [{"tick": 0, "position": [0, 2, 5]}, {"tick": 10, "position": ["1/3", 2, 5]}],
      "commands": [{"tick": 4, "body": ")" + s.bodies.list[0].name +
                                               R"(", "command": "addVelocity", "value": [1, 0, 0]}]})",
                                           "track.json", s);
  EXPECT_EQ(track.ticks, 30);
  EXPECT_EQ(trackInput(track, 9).camera.x, 0);
  EXPECT_EQ(trackInput(track, 10).camera.x, toInputRaw(Rational{1, 3}));
  EXPECT_EQ(trackInput(track, 500).camera.y, int64_t(2) << 32);
  EXPECT_EQ(trackInput(track, 4).bodies.size(), 1u);
  EXPECT_TRUE(trackInput(track, 5).bodies.empty());
}

TEST(InputTrack, ErrorsNameTheFileAndJsonPath) {
  const Scenario s = loadScenarioFile(test::sourcePath("scenarios/thesis-bodies.json"));
  auto error = [&s](const std::string& text) {
    try {
      parseInputTrack(text, "track.json", s);
    } catch (const ScenarioError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error(R"({"ticks": 3})"),
            R"(track.json: $.format: expected "simgrass-input-track/1" (the key is missing))");
  EXPECT_EQ(
      error(
          R"({"format": "simgrass-input-track/1", "camera": [{"tick": 5, "position": [0,0,0]}, {"tick": 5, "position": [0,0,0]}]})"),
      "track.json: $.camera[1].tick: expected a tick after the previous camera key's 5, got 5");
  EXPECT_EQ(
      error(
          R"({"format": "simgrass-input-track/1", "commands": [{"tick": 1, "body": "nobody", "command": "displace", "value": [0,0,0]}]})"),
      R"(track.json: $.commands[0].body: expected the name of a body in $.bodies.list, got "nobody")");
  EXPECT_NE(error(R"({"format": "simgrass-input-track/1", "ticks": -1})").find("$.ticks"), std::string::npos);
  EXPECT_NE(error("{").find("valid JSON"), std::string::npos);
}

TEST(Variant, ParsesDescribesAndOverrides) {
  const VariantSettings v =
      VariantSettings::parse("scalar=fx16, interp=2 dt=1/120 broadphase=brute body-broadphase=sap threads=3");
  EXPECT_EQ(v.describe(), "scalar=fx16 interp=2 broadphase=brute body-broadphase=sap dt=1/120 threads=3");
  EXPECT_EQ(VariantSettings::parse(v.describe()).describe(), v.describe());
  const VariantSettings base = VariantSettings::resolvedFrom(test::thesisMeadow());
  EXPECT_EQ(base.describe(), "scalar=fx32 interp=1 broadphase=grid body-broadphase=brute dt=1/60 lod=off");
  EXPECT_TRUE(VariantSettings::parse("broadphase=brute threads=2").mustBeIdenticalTo(base));
  EXPECT_FALSE(VariantSettings::parse("interp=2").mustBeIdenticalTo(base));
  EXPECT_FALSE(VariantSettings::parse("dt=1/120").mustBeIdenticalTo(base));
  EXPECT_FALSE(VariantSettings::parse("lod=window").mustBeIdenticalTo(base));
  EXPECT_TRUE(VariantSettings::parse("lod=off").mustBeIdenticalTo(base));
  EXPECT_TRUE(VariantSettings::parse("scalar=fx32").mustBeIdenticalTo(base));
  for (const char* bad : {"interp=5", "scalar=q8", "dt=0", "dt=2", "threads=0", "lod=maybe", "speed=3", "interp"}) {
    EXPECT_THROW(VariantSettings::parse(bad), std::invalid_argument) << bad;
  }
  try {
    VariantSettings::parse("interp=9");
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "interp=9: expected interp=1, 2, 3 or 4");
  }
}

// The grass model as a variant: described only when it is not thesis (recordings made before the
// key keep their resolved text), never identical to another model, and switching into or out of
// the blade model takes that model's acceleration, initial velocity and damping defaults.
TEST(Variant, ModelSwitchesTheModelAndItsDefaults) {
  const VariantSettings base = VariantSettings::resolvedFrom(test::thesisMeadow());
  EXPECT_FALSE(VariantSettings::parse("model=blade").mustBeIdenticalTo(base));
  EXPECT_FALSE(VariantSettings::parse("model=pbd").mustBeIdenticalTo(base));
  EXPECT_TRUE(VariantSettings::parse("model=thesis").mustBeIdenticalTo(base));
  Scenario s = test::thesisMeadow();
  VariantSettings::parse("model=blade").applyTo(s);
  EXPECT_EQ(s.particles.model, GrassModel::Blade);
  EXPECT_EQ(s.particles.acceleration[1], (Rational{-981, 100}));
  EXPECT_EQ(s.particles.initialVelocity[0], (Rational{0, 1}));
  EXPECT_EQ(s.particles.damping, (Rational{1, 1}));
  EXPECT_EQ(VariantSettings::resolvedFrom(s).describe(),
            "scalar=fx32 interp=1 broadphase=grid body-broadphase=brute dt=1/60 lod=off model=blade");
  // A thesis variant of a scenario written for another model names its model.
  Scenario written = test::thesisMeadow();
  written.particles.writtenModel = GrassModel::Blade;
  EXPECT_EQ(VariantSettings::resolvedFrom(written).describe(),
            "scalar=fx32 interp=1 broadphase=grid body-broadphase=brute dt=1/60 lod=off model=thesis");
  VariantSettings::parse("model=pbd").applyTo(s);
  EXPECT_EQ(s.particles.model, GrassModel::Pbd);
  EXPECT_EQ(s.particles.acceleration, test::thesisMeadow().particles.acceleration);
  EXPECT_EQ(s.particles.damping, test::thesisMeadow().particles.damping);
  try {
    VariantSettings::parse("model=rigid");
    ADD_FAILURE() << "model=rigid parsed";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "model=rigid: expected model=thesis, pbd or blade");
  }
}

// ---- committed recordings ----------------------------------------------------------------------
// scenarios/recordings/*.sgr were made by .ci/rerecord; expected.json holds each one's final hash.
// A change to the physics or the format that breaks them must say so and re-record.
TEST(CommittedRecordings, ReplayToTheirCommittedHashes) {
  std::ifstream in(test::sourcePath("scenarios/recordings/expected.json"));
  ASSERT_TRUE(in) << "scenarios/recordings/expected.json is missing";
  const nlohmann::json expected = nlohmann::json::parse(in);
  ASSERT_GE(expected.size(), 3u);
  for (const auto& [name, entry] : expected.items()) {
    SCOPED_TRACE(name);
    const sgr::Recording r = sgr::readRecording(test::sourcePath("scenarios/recordings/" + name));
    ASSERT_TRUE(r.end.has_value());
    EXPECT_EQ(hex(r.end->hash), entry["finalHash"].get<std::string>());
    EXPECT_EQ(r.end->tick, entry["ticks"].get<int64_t>());
    if (test::slowBuild() && r.end->tick > 120) continue;  // the sanitizer build checks the short ones
    Player player(r);
    const VerifyReport v = player.verify();
    EXPECT_TRUE(v.ok) << "first mismatch at tick " << v.firstMismatchTick;
    EXPECT_EQ(v.ticks, r.end->tick);
  }
}

// ---- command line ------------------------------------------------------------------------------
TEST(ReplayCli, RecordVerifySeekExportAndInfo) {
  TempDir dir;
  const std::string sgr = dir.file("run.sgr");
  const CliResult rec = runCli("record " + quote(test::sourcePath("scenarios/thesis-bodies.json")) + " -o " +
                               quote(sgr) + " --ticks 40 --snapshot-every 15 --json");
  ASSERT_EQ(rec.exitCode, 0) << rec.describe();
  const json r = parseJson(rec);
  EXPECT_EQ(r["ticks"], 40);
  EXPECT_EQ(r["checkEvery"], 1);
  const std::string finalHash = r["finalHash"];

  const CliResult verify = runCli("replay " + quote(sgr) + " --verify --json");
  ASSERT_EQ(verify.exitCode, 0) << verify.describe();
  const json v = parseJson(verify);
  EXPECT_EQ(v["verified"], true);
  EXPECT_EQ(v["ticks"], 40);
  EXPECT_EQ(v["hash"], finalHash);

  const CliResult seek =
      runCli("replay " + quote(sgr) + " --to 22 --export-state " + quote(dir.file("s22.bin")) + " --json");
  ASSERT_EQ(seek.exitCode, 0) << seek.describe();
  const json s = parseJson(seek);
  EXPECT_EQ(s["tick"], 22);
  EXPECT_EQ(s["matchesRecording"], true);
  EXPECT_GT(fs::file_size(dir.file("s22.bin")), 40u);

  const CliResult info = runCli("replay " + quote(sgr) + " --info");
  ASSERT_EQ(info.exitCode, 0) << info.describe();
  EXPECT_NE(info.out.find("2 snapshots"), std::string::npos) << info.out;

  const CliResult tooFar = runCli("replay " + quote(sgr) + " --to 41");
  EXPECT_EQ(tooFar.exitCode, 2);
  EXPECT_TRUE(isOneLine(tooFar.err));
  EXPECT_NE(tooFar.err.find("--to: expected a tick from 0 to 40"), std::string::npos) << tooFar.err;
}

TEST(ReplayCli, ExportStateAsJsonHoldsTheBinaryStatesNumbers) {
  TempDir dir;
  const std::string sgr = dir.file("b.sgr");
  ASSERT_EQ(runCli("record " + quote(test::sourcePath("scenarios/thesis-bodies.json")) + " -o " + quote(sgr) +
                   " --ticks 30 --json")
                .exitCode,
            0);
  const CliResult bin = runCli("replay " + quote(sgr) + " --to 22 --export-state " + quote(dir.file("s.bin")));
  ASSERT_EQ(bin.exitCode, 0) << bin.describe();
  const CliResult js = runCli("replay " + quote(sgr) + " --to 22 --export-state " + quote(dir.file("s.json")));
  ASSERT_EQ(js.exitCode, 0) << js.describe();
  const std::string raw = readFile(dir.file("s.bin"));
  const std::vector<uint8_t> state(raw.begin(), raw.end());
  const json s = json::parse(readFile(dir.file("s.json")));
  EXPECT_EQ(s["format"], "simgrass-state/2");
  EXPECT_EQ(s["tick"], 22);
  EXPECT_EQ(s["scalar"], "fx32");
  EXPECT_EQ(loadLE<int64_t>(state.data() + 36), 22);
  // Every particle position and velocity is the binary state's Q32.32 value (the scenario has no
  // level-of-detail window, so storage order is lattice order).
  const int64_t n = s["particles"]["countX"].get<int64_t>() * s["particles"]["countZ"].get<int64_t>();
  ASSERT_EQ(loadLE<int64_t>(state.data() + 44), n);
  const test::StateSection part = test::findSection(state, "PART");
  const auto& position = s["particles"]["position"];
  const auto& velocity = s["particles"]["velocity"];
  ASSERT_EQ(int64_t(position.size()), 3 * n);
  for (int64_t q = 0; q < n; q += 97)
    for (int a = 0; a < 3; ++a) {
      const double p = double(loadLE<int64_t>(state.data() + part.payloadAt + 8 * (a * n + q))) / 4294967296.0;
      const double v = double(loadLE<int64_t>(state.data() + part.payloadAt + 8 * ((3 + a) * n + q))) / 4294967296.0;
      EXPECT_EQ(position[size_t(3 * q + a)].get<double>(), p) << "particle " << q;
      EXPECT_EQ(velocity[size_t(3 * q + a)].get<double>(), v) << "particle " << q;
    }
  const test::StateSection bodies = test::findSection(state, "BODY");
  ASSERT_EQ(s["bodies"].size(), bodies.length / (13 * 8 + 8));
  for (size_t b = 0; b < s["bodies"].size(); ++b)
    for (int a = 0; a < 3; ++a)
      EXPECT_EQ(
          s["bodies"][b]["position"][size_t(a)].get<double>(),
          double(loadLE<int64_t>(state.data() + bodies.payloadAt + b * (13 * 8 + 8) + 8 * size_t(a))) / 4294967296.0);
  EXPECT_EQ(int64_t(s["patches"]["tipOffset"].size()),
            3 * s["patches"]["countX"].get<int64_t>() * s["patches"]["countZ"].get<int64_t>());
  // A folder that does not exist: one line, exit 2, nothing left behind.
  const CliResult bad = runCli("replay " + quote(sgr) + " --to 22 --export-state " + quote(dir.file("no/such/s.json")));
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_TRUE(isOneLine(bad.err)) << bad.err;
}

TEST(ReplayCli, RecordWithAnInputTrackAndAVariant) {
  TempDir dir;
  const std::string track = dir.write("track.json", R"({"format": "simgrass-input-track/1", "ticks": 25,
      "camera": [{"tick": 0, "position": [0, 2, 5]}],
      "commands": [{"tick": 2, "body": "football", "command": "addVelocity", "value": [2, 0, 0]}]})");
  // --variant before the scenario: it takes one value, the path stays the scenario.
  const CliResult rec = runCli("record --variant interp=2 " + quote(test::sourcePath("scenarios/thesis-bodies.json")) +
                               " -o " + quote(dir.file("t.sgr")) + " --input " + quote(track) + " --json");
  ASSERT_EQ(rec.exitCode, 0) << rec.describe();
  EXPECT_EQ(parseJson(rec)["ticks"], 25);
  EXPECT_NE(parseJson(rec)["variant"].get<std::string>().find("interp=2"), std::string::npos);
  const sgr::Recording r = sgr::readRecording(dir.file("t.sgr"));
  ASSERT_EQ(r.inputs.size(), 2u);  // the camera at 0, the command at 2
  EXPECT_TRUE(Player(r).verify().ok);

  const CliResult bad = runCli("record -o " + quote(dir.file("x.sgr")) + " --variant interp=7");
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_TRUE(isOneLine(bad.err)) << bad.err;
  const CliResult badTrack =
      runCli("record " + quote(test::sourcePath("scenarios/thesis-bodies.json")) + " -o " + quote(dir.file("y.sgr")) +
             " --input " + quote(dir.write("bad.json", "{\"format\": 3}")));
  EXPECT_EQ(badTrack.exitCode, 2);
  EXPECT_TRUE(isOneLine(badTrack.err)) << badTrack.err;
  EXPECT_NE(badTrack.err.find("bad.json: $.format"), std::string::npos) << badTrack.err;
}

}  // namespace
}  // namespace sg
