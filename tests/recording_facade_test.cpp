// The public replay facade (replay/recording.h): a session recorded through it is the session a
// world stepped directly goes through, its file is an ordinary `.sgr` (the CLI verifies it, and it
// verifies the CLI's), and its errors are the documented ones. tests/install_consumer uses the
// same API from an installed copy; this suite checks its results in detail.
#include "replay/recording.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>

#include "replay/cli/cli_common.h"
#include "replay/format/sgr_reader.h"
#include "replay/format/sgr_writer.h"
#include "sim/world/world.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {

constexpr int64_t kTicks = 20;

RecordingSettings everyTenTicks() {
  RecordingSettings s;
  s.snapshotEvery = 10;
  return s;
}

TEST(RecordingFacade, SessionStepsLikeAWorldSteppedDirectly) {
  TempDir dir;
  const Scenario scenario = test::thesisMeadow();
  std::unique_ptr<SimWorld> direct = makeWorld(scenario, 1);
  RecordingSession session = RecordingSession::fromScenario(scenario, dir.file("a.sgr"), everyTenTicks());
  for (int64_t t = 0; t < kTicks; ++t) {
    const TickInput input = scriptedInput(scenario, t);
    ASSERT_TRUE(session.step(input)) << session.error();
    ASSERT_TRUE(direct->step(input).ok);
    ASSERT_EQ(session.stateHash(), direct->stateHash()) << "tick " << t + 1;
  }
  EXPECT_EQ(session.tick(), kTicks);
  EXPECT_EQ(session.world().tick(), kTicks);  // the read-only view is the recorded world
  EXPECT_TRUE(session.error().empty());
  const RecordingSummary summary = session.finish();
  EXPECT_EQ(summary.ticks, kTicks);
  EXPECT_EQ(summary.finalHash, direct->stateHash());
  EXPECT_EQ(summary.bytes, std::filesystem::file_size(dir.file("a.sgr")));
  EXPECT_TRUE(summary.error.empty());
}

TEST(RecordingFacade, InfoAndVerifyReadWhatTheSessionWrote) {
  TempDir dir;
  const std::string path = dir.file("a.sgr");
  RecordingSession session = RecordingSession::fromScenarioFile("", path, everyTenTicks());  // built-in meadow
  ASSERT_TRUE(session.stepScripted(kTicks)) << session.error();
  const RecordingSummary summary = session.finish();

  const RecordingInfo info = readRecordingInfo(path);
  EXPECT_TRUE(info.complete);
  EXPECT_EQ(info.startTick, 0);
  EXPECT_EQ(info.lastTick, kTicks);
  EXPECT_EQ(info.checkEvery, 1u);  // the default for a meadow this small
  EXPECT_EQ(info.snapshotEvery, 10u);
  EXPECT_EQ(info.checks, kTicks);
  EXPECT_EQ(info.snapshots, 2);
  ASSERT_TRUE(info.finalHash.has_value());
  EXPECT_EQ(*info.finalHash, summary.finalHash);
  EXPECT_TRUE(info.fault.empty());
  EXPECT_EQ(info.scenarioText, defaultScenarioText());
  EXPECT_EQ(info.variant.rfind("scalar=fx32 ", 0), 0u) << info.variant;

  const VerifyResult v = verifyRecording(path);
  EXPECT_TRUE(v.ok) << "first mismatch at tick " << v.firstMismatchTick << ": " << v.error;
  EXPECT_EQ(v.ticks, kTicks);
  EXPECT_EQ(info.hashedTicks, kTicks + 1);  // the start and every tick (SNAP and END on checked ticks)
  EXPECT_EQ(v.hashesChecked, info.hashedTicks);
  EXPECT_EQ(v.finalHash, summary.finalHash);
}

TEST(RecordingFacade, TheCommandLineAndTheFacadeAcceptEachOthersRecordings) {
  TempDir dir;
  const std::string ours = dir.file("facade.sgr"), theirs = dir.file("cli.sgr");
  RecordingSession session = RecordingSession::fromScenarioFile("", ours, everyTenTicks());
  ASSERT_TRUE(session.stepScripted(kTicks));
  const RecordingSummary summary = session.finish();

  const CliResult replayed = runCli("replay --verify --json " + quote(ours));
  ASSERT_EQ(replayed.exitCode, 0) << replayed.describe();
  const json r = parseJson(replayed);
  EXPECT_EQ(r["verified"], true);
  EXPECT_EQ(r["hash"], hex(summary.finalHash));

  const CliResult recorded = runCli("record -o " + quote(theirs) + " --ticks 20 --snapshot-every 10 --json");
  ASSERT_EQ(recorded.exitCode, 0) << recorded.describe();
  const VerifyResult v = verifyRecording(theirs);
  EXPECT_TRUE(v.ok);
  EXPECT_EQ(hex(v.finalHash), parseJson(recorded)["finalHash"]);
  EXPECT_EQ(v.finalHash, summary.finalHash);  // same scenario, same ticks: the same state
}

TEST(RecordingFacade, AScenarioFileHasItsHeightmapEmbeddedAParsedOneIsRefused) {
  TempDir dir;
  const std::string hilly = test::sourcePath("scenarios/hilly-meadow.json");
  RecordingSession session = RecordingSession::fromScenarioFile(hilly, dir.file("hilly.sgr"));
  ASSERT_TRUE(session.stepScripted(3));
  session.finish();
  EXPECT_TRUE(verifyRecording(dir.file("hilly.sgr")).ok);  // the player reads the embedded copy only

  const Scenario parsed = loadScenarioFile(hilly);
  try {
    RecordingSession::fromScenario(parsed, dir.file("refused.sgr"));
    FAIL() << "a parsed scenario naming a heightmap was accepted";
  } catch (const ScenarioError& e) {
    EXPECT_EQ(e.path(), "$.terrain.file");
  }
}

TEST(RecordingFacade, AnUnfinishedSessionLeavesARecordingCutOffThatStillVerifies) {
  TempDir dir;
  const std::string path = dir.file("cut.sgr");
  {
    RecordingSession session = RecordingSession::fromScenarioFile("", path, everyTenTicks());
    ASSERT_TRUE(session.stepScripted(12));
  }  // destroyed without finish()
  const RecordingInfo info = readRecordingInfo(path);
  EXPECT_FALSE(info.complete);
  EXPECT_FALSE(info.finalHash.has_value());
  EXPECT_EQ(info.lastTick, 12);
  const VerifyResult v = verifyRecording(path);
  EXPECT_TRUE(v.ok);
  EXPECT_EQ(v.ticks, 12);
}

TEST(RecordingFacade, FinishIsFinal) {
  TempDir dir;
  RecordingSession session = RecordingSession::fromScenarioFile("", dir.file("a.sgr"));
  ASSERT_TRUE(session.stepScripted(2));
  const RecordingSummary first = session.finish();
  const RecordingSummary again = session.finish();
  EXPECT_EQ(again.ticks, first.ticks);
  EXPECT_EQ(again.finalHash, first.finalHash);
  EXPECT_EQ(again.bytes, first.bytes);
  EXPECT_THROW(session.step(TickInput{}), std::logic_error);
}

TEST(RecordingFacade, AHashThatDiffersIsReportedWithItsTick) {
  TempDir dir;
  const std::string good = dir.file("good.sgr"), bad = dir.file("bad.sgr");
  RecordingSession session = RecordingSession::fromScenarioFile("", good);
  ASSERT_TRUE(session.stepScripted(1));
  const uint64_t real = session.finish().finalHash;
  // The same header (scenario, settings), then a well-formed CHCK whose hash is not the state's.
  const sgr::Recording original = sgr::readRecording(good);
  {
    sgr::Writer writer(bad, original.header);
    writer.input(0, TickInput{});
    writer.check({1, real ^ 1});
    writer.end({1, real ^ 1, false, ""});
  }
  const VerifyResult v = verifyRecording(bad);
  EXPECT_FALSE(v.ok);
  EXPECT_EQ(v.firstMismatchTick, 1);
  EXPECT_EQ(v.expectedHash, real ^ 1);
  EXPECT_EQ(v.actualHash, real);
  EXPECT_TRUE(v.error.empty());
}

TEST(RecordingFacade, UnreadableFilesAreRuntimeErrors) {
  TempDir dir;
  EXPECT_THROW(readRecordingInfo(dir.file("missing.sgr")), std::runtime_error);
  EXPECT_THROW(verifyRecording(dir.write("junk.sgr", "not a recording")), std::runtime_error);
  EXPECT_THROW(RecordingSession::fromScenarioFile("", dir.file("no-such-folder/a.sgr")), std::runtime_error);
  EXPECT_THROW(RecordingSession::fromScenarioFile(dir.file("missing.json"), dir.file("a.sgr")), ScenarioError);
}

}  // namespace
}  // namespace sg
