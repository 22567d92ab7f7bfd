// simgrass-viewer's controls (issue 18), each driven by a script under Xvfb through the same event
// queue the keyboard and mouse feed (viewer/app/input_events.h), and each checked against an
// independent witness: `simgrass replay --verify` and `--export-state` for what the window
// recorded, a straight run's hashes for stepping back and forth, the files the keys write, and
// docs/viewer.md for the key table the help overlay shows.
#include <gtest/gtest.h>
#include <stb/stb_image.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "replay/format/sgr_reader.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"
#include "viewer/app/input_events.h"

namespace sg {
namespace viewer_test {
bool onPath(const std::string& program);  // tests/viewer_test.cpp
CliResult runViewer(const std::string& args, bool xvfb = true, const std::string& cwd = "");
}  // namespace viewer_test

namespace {
using viewer_test::onPath;
using viewer_test::runViewer;
namespace fs = std::filesystem;

const std::string kWindow = " --size 320x240 --msaa 0";
std::string scenario(const std::string& name) { return quote(test::sourcePath("scenarios/" + name)); }

/// Every line of `out` that starts with `prefix`, without it.
std::vector<std::string> linesStarting(const std::string& out, const std::string& prefix) {
  std::vector<std::string> found;
  size_t at = 0;
  while (at < out.size()) {
    size_t end = out.find('\n', at);
    if (end == std::string::npos) end = out.size();
    const std::string line = out.substr(at, end - at);
    if (line.rfind(prefix, 0) == 0) found.push_back(line.substr(prefix.size()));
    at = end + 1;
  }
  return found;
}

/// (tick, hash) of each `print` line.
std::vector<std::pair<int64_t, std::string>> printed(const std::string& out) {
  std::vector<std::pair<int64_t, std::string>> v;
  static const std::regex re(R"(tick (\d+), hash ([0-9a-f]{16}), patches \d+x\d+, bodies (\d+))");
  for (const std::string& l : linesStarting(out, "state      ")) {
    std::smatch m;
    if (std::regex_search(l, m, re)) v.emplace_back(std::stoll(m[1]), m[2]);
  }
  return v;
}

/// The bodies of a recording's state at `tick` (`simgrass replay --to T --export-state x.json`).
json bodiesAt(const TempDir& dir, const std::string& rec, int64_t tick) {
  const std::string out = dir.file("state-" + std::to_string(tick) + ".json");
  const CliResult r =
      runCli("replay " + quote(rec) + " --to " + std::to_string(tick) + " --export-state " + quote(out));
  EXPECT_EQ(r.exitCode, 0) << r.describe();
  return json::parse(readFile(out), nullptr, false)["bodies"];
}

// ---- without a window ---------------------------------------------------------------------------

TEST(ViewerControls, TheHelpOverlaysKeyTableIsDocsViewerMdsControlsTable) {
  // One table, three places: the F1 overlay draws it, --keys prints it, the docs must hold it.
  const CliResult keys = runViewer("--keys", false);
  ASSERT_EQ(keys.exitCode, 0) << keys.describe();
  const std::string docs = readFile(test::sourcePath("docs/viewer.md"));
  const size_t start = docs.find("| Keys | What |");
  ASSERT_NE(start, std::string::npos);
  const size_t end = docs.find("\n\n", start);
  EXPECT_EQ(docs.substr(start, end - start + 1), keys.out) << "docs/viewer.md's Controls table is not kKeyHelp";
}

TEST(ViewerControls, ARouterSendsAReleaseWhereItsPressWent) {
  // Keys never go to two places: the press decides the owner, the release follows it even when
  // ImGui's wishes changed in between; repeats stay with the owner.
  viewer::InputRouter r;
  using O = viewer::InputRouter::Owner;
  const viewer::InputEvent tDown{viewer::InputEvent::Kind::Key, 84, true, false, 0};
  viewer::InputEvent tUp = tDown, tRepeat = tDown;
  tUp.down = false;
  tRepeat.repeat = true;
  EXPECT_EQ(r.route(tDown, false, false), O::App);
  EXPECT_EQ(r.route(tRepeat, true, true), O::App);
  EXPECT_EQ(r.route(tUp, true, true), O::App) << "released into a panel: still the app's";
  EXPECT_EQ(r.route(tDown, true, false), O::Ui) << "while ImGui edits text, keys are ImGui's";
  EXPECT_EQ(r.route(tUp, false, false), O::Ui);
  const viewer::InputEvent click{viewer::InputEvent::Kind::MouseButton, 0, true, false, 0};
  viewer::InputEvent release = click;
  release.down = false;
  EXPECT_EQ(r.route(click, true, true), O::Ui) << "a click over a panel";
  EXPECT_EQ(r.route(release, false, false), O::Ui);
  EXPECT_EQ(r.route(click, true, false), O::App) << "a click in the view, whatever the keyboard";
  EXPECT_EQ(r.route(release, true, true), O::App);
  EXPECT_EQ(r.route(viewer::InputEvent{viewer::InputEvent::Kind::Key, 100000, true, false, 0}, false, false), O::None);

  // A tap within one frame: the toggle is queued and the key counts as held for that frame.
  viewer::InputState s;
  s.push(tDown);
  s.push(tUp);
  EXPECT_FALSE(s.down(84));
  EXPECT_TRUE(s.heldThisFrame(84));
  EXPECT_EQ(s.takeEvents().size(), 2u);
  s.endFrame();
  EXPECT_FALSE(s.heldThisFrame(84));
  s.push(tRepeat);
  EXPECT_TRUE(s.takeEvents().empty()) << "a repeat is no new press";
}

// ---- live control -------------------------------------------------------------------------------

TEST(ViewerControls, PauseStepBackStepAndRestartRetraceTheSameTicks) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  // A straight run prints ticks 6 and 10; the paused session steps back from 10 to 6 and forward
  // again through its history, and restarts at tick 0: every hash must be the straight run's.
  const std::string script = dir.write("live.txt",
                                       "frames 6\nprint\nframes 4\nprint\npause\nframes 3\nprint\n"
                                       "back 4\nprint\nstep 4\nframes 1\nprint\nrestart\nprint\n"
                                       "tap space\nframes 2\nprint\nquit\n");
  const CliResult v = runViewer(scenario("thesis-bodies.json") + " --script " + quote(script) + kWindow);
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  const auto p = printed(v.out);
  ASSERT_EQ(p.size(), 7u) << v.describe();
  EXPECT_EQ(p[0].first, 6);
  EXPECT_EQ(p[1].first, 10);
  EXPECT_EQ(p[2], p[1]) << "paused: three frames, no tick";
  EXPECT_EQ(p[3], p[0]) << "back 4 from tick 10 is the straight run's tick 6";
  EXPECT_EQ(p[4], p[1]) << "stepping forward replays the history";
  EXPECT_EQ(p[5].first, 0);
  EXPECT_EQ(p[6].first, 2) << "a tapped Space resumes";
  const CliResult fresh = runCli("run " + scenario("thesis-bodies.json") + " --ticks 0 --json");
  EXPECT_EQ(p[5].second, parseJson(fresh).value("finalHash", std::string())) << "restart is the scenario's tick 0";
}

TEST(ViewerControls, TapsShorterThanAFrameAreNotLost) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string rec = dir.file("tapped.sgr");
  // R tapped (down and up before the frame): recording starts; T tapped: one frame of drive; R
  // tapped again: the recording stops. With the old polling, none of the three was seen.
  const std::string script = dir.write("taps.txt",
                                       "frames 2\ntap r\nframes 3\nselect 0\ntap t\nframes 3\ntap r\n"
                                       "frames 1\ntap f1\nframes 1\nstatus\nquit\n");
  const CliResult v =
      runViewer(scenario("thesis-bodies.json") + " --script " + quote(script) + kWindow, true, dir.file(""));
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  const std::vector<std::string> recorded = linesStarting(v.out, "recorded   ");
  ASSERT_EQ(recorded.size(), 1u) << "R tapped twice: one recording, started and stopped\n" << v.describe();
  const std::string file =
      recorded[0].substr(recorded[0].find(" to ") + 4, recorded[0].find(" (hash") - recorded[0].find(" to ") - 4);
  EXPECT_EQ(recorded[0].rfind("8 ticks", 0), 0u) << recorded[0];
  const CliResult verify = runCli("replay " + quote(dir.file(file)) + " --verify");
  EXPECT_EQ(verify.exitCode, 0) << verify.describe();
  EXPECT_NE(linesStarting(v.out, "view       ").at(0).find("help shown"), std::string::npos) << v.out;
  // The tapped T drove the football for its frame's tick: an AddVelocity recorded at tick 5.
  const json info = parseJson(runCli("replay " + quote(dir.file(file)) + " --info --json"));
  EXPECT_GE(info.value("inputs", 0), 2) << info.dump();
  const json b5 = bodiesAt(dir, dir.file(file), 5), b6 = bodiesAt(dir, dir.file(file), 6);
  ASSERT_TRUE(b5.is_array() && b6.is_array());
  const double dv = b6[0]["velocity"][2].get<double>() - b5[0]["velocity"][2].get<double>();
  EXPECT_GT(std::fabs(dv), 0.05) << "the tap's AddVelocity (8 m/s^2 for one tick at 1/60 s = 0.13 m/s)";
}

// ---- mouse ------------------------------------------------------------------------------------

TEST(ViewerControls, ADragPullsTheBodyUnderTheCursorAndTheRecordingVerifies) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string rec = dir.file("drag.sgr");
  // The camera looks at the football (-10, 0.3, -4) from 3 m behind it; the click lands on it, the
  // cursor moves up, the spring lifts it; then a click on empty sky selects nothing.
  const std::string script =
      dir.write("drag.txt", "camera -10 1.3 -7 0 -18\nframes 1\nrecord start " + rec +
                                "\nmouse 160 120\nbutton left down\nframes 2\nmouse 160 60\nframes 40\nstatus\n"
                                "button left up\nframes 5\nrecord stop\nmouse 300 5\nbutton left down\n"
                                "button left up\nframes 1\nstatus\nquit\n");
  const CliResult v = runViewer(scenario("thesis-bodies.json") + " --script " + quote(script) + kWindow);
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  const auto status = linesStarting(v.out, "status     ");
  ASSERT_EQ(status.size(), 2u) << v.describe();
  EXPECT_EQ(status[0], "selected body 0") << v.out;
  EXPECT_EQ(status[1], "selected body 0") << "the click on the sky changed nothing";
  const CliResult verify = runCli("replay " + quote(rec) + " --verify");
  ASSERT_EQ(verify.exitCode, 0) << verify.describe();
  const json start = bodiesAt(dir, rec, 1), held = bodiesAt(dir, rec, 40);
  ASSERT_TRUE(start.is_array() && held.is_array());
  EXPECT_NEAR(start[0]["position"][1].get<double>(), 0.3, 0.05);
  EXPECT_GT(held[0]["position"][1].get<double>(), 0.8) << "the drag lifted the football toward the cursor";
  const sgr::Recording r = sgr::readRecording(rec);
  EXPECT_EQ(r.inputAt(20).bodies.back().kind, BodyCommandKind::DragTo);
}

TEST(ViewerControls, ShootThrowsACopyOfTheSelectedBodyThatReplays) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string rec = dir.file("shot.sgr");
  const std::string script = dir.write("shoot.txt", "camera 0 2 -10 0 0\nrecord start " + rec +
                                                        "\nselect 0\ntap b\nframes 6\nprint\nrecord stop\nquit\n");
  const CliResult v = runViewer(scenario("thesis-bodies.json") + " --script " + quote(script) + kWindow);
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  EXPECT_NE(v.out.find("bodies 4"), std::string::npos) << v.out;
  ASSERT_EQ(runCli("replay " + quote(rec) + " --verify").exitCode, 0);
  const json b = bodiesAt(dir, rec, 2);
  ASSERT_EQ(b.size(), 4u);
  // Thrown along the view (+z) at 15 m/s, 1.5 m ahead of the eye, a football's copy.
  EXPECT_NEAR(b[3]["velocity"][2].get<double>(), 15.0, 1.0) << b[3].dump();
  EXPECT_EQ(b[3].value("template", -1), 0);
}

// ---- camera and level of detail ------------------------------------------------------------------

TEST(ViewerControls, FollowKeepsTheCameraOnTheBodyAndF3FreezesTheWindow) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  // lod-crossing: a 30 m window follows the camera. Frozen (F3), the camera walks 20 m and the
  // window stays; F3 again and it catches up. Then the camera follows body 0 driven along x.
  const std::string script =
      dir.write("cam.txt",
                "frames 2\nstatus\ntap f3\nkey shift down\nkey w down\nframes 60\n"
                "key w up\nkey shift up\nstatus\ntap f3\nframes 2\nstatus\n"
                "select 0\ntap l\nframes 1\nstatus\nkey t down\nframes 30\nkey t up\nstatus\nquit\n");
  const CliResult v =
      runViewer(scenario("lod-crossing.json") + " --no-scenario-input --script " + quote(script) + kWindow);
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  const auto window = linesStarting(v.out, "window     ");
  const auto camera = linesStarting(v.out, "camera     ");
  ASSERT_EQ(window.size(), 5u) << v.describe();
  EXPECT_EQ(window[1], window[0]) << "frozen: the window stood while the camera walked";
  EXPECT_NE(window[2], window[1]) << "following again: it caught up";
  auto xyz = [](const std::string& line) {
    std::istringstream in(line);
    double x, y, z;
    in >> x >> y >> z;
    return std::array<double, 3>{x, y, z};
  };
  EXPECT_GT(std::fabs(xyz(camera[1])[2] - xyz(camera[0])[2]), 10.0) << "the camera walked";
  EXPECT_NE(linesStarting(v.out, "view       ").at(3).find("(followed)"), std::string::npos) << v.out;
  // Driven 30 ticks, the body moved; the camera moved with it by about as much.
  const auto before = xyz(camera[3]), after = xyz(camera[4]);
  const double moved = std::hypot(after[0] - before[0], after[2] - before[2]);
  EXPECT_GT(moved, 0.1) << v.out;
}

// ---- the window: help, panels, screenshot key, settings, scenes, A/B ---------------------------------

TEST(ViewerControls, ScreenshotKeyHelpAndHiddenPanelsShowInTheWindow) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string config = dir.file("config");
  const std::string script =
      dir.write("ui.txt", "frames 1\nscreenshot " + dir.file("panels.png") + "\ntap f2\nframes 1\n" + "screenshot " +
                              dir.file("hidden.png") + "\ntap f1\nframes 1\n" + "screenshot " + dir.file("help.png") +
                              "\ntap f1\ntap f12\nframes 1\nquit\n");
  const CliResult v =
      runViewer(" --script " + quote(script) + " --config-dir " + quote(config) + kWindow, true, dir.file(""));
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  const std::string panels = readFile(dir.file("panels.png")), hidden = readFile(dir.file("hidden.png")),
                    help = readFile(dir.file("help.png"));
  ASSERT_FALSE(panels.empty() || hidden.empty() || help.empty());
  EXPECT_NE(panels, hidden) << "F2 hid the panels";
  EXPECT_NE(hidden, help) << "F1 drew the help";
  EXPECT_TRUE(fs::exists(dir.file("simgrass-thesis-meadow-3.png"))) << "F12 wrote the screenshot";
  // The settings went to --config-dir: panels hidden, and a second run starts with them hidden.
  const json settings = json::parse(readFile(config + "/viewer.json"), nullptr, false);
  EXPECT_EQ(settings.value("uiHidden", false), true) << settings.dump();
  EXPECT_TRUE(fs::exists(config + "/imgui.ini"));
  const std::string again = dir.write("again.txt", "frames 1\nstatus\nquit\n");
  const CliResult v2 = runViewer(" --script " + quote(again) + " --config-dir " + quote(config) + kWindow);
  ASSERT_EQ(v2.exitCode, 0) << v2.describe();
  EXPECT_NE(v2.out.find("view       panels hidden"), std::string::npos) << v2.out;
  // A damaged settings file: a warning line and the defaults, never a failed start.
  std::ofstream(config + "/viewer.json") << "{\"uiHidden\": 3";
  const CliResult v3 = runViewer(" --script " + quote(again) + " --config-dir " + quote(config) + kWindow);
  ASSERT_EQ(v3.exitCode, 0) << v3.describe();
  EXPECT_NE(v3.err.find("viewer.json: expected a JSON object"), std::string::npos) << v3.err;
  EXPECT_NE(v3.out.find("view       panels shown"), std::string::npos) << v3.out;
}

TEST(ViewerControls, PageDownOpensTheNextScenarioOfTheFolder) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  fs::copy_file(test::sourcePath("scenarios/thesis-meadow.json"), dir.file("a.json"));
  fs::copy_file(test::sourcePath("scenarios/thesis-meadow.json"), dir.file("b.json"));
  fs::copy_file(test::sourcePath("scenarios/thesis-meadow.json"), dir.file("c.json"));
  const std::string script =
      dir.write("scenes.txt",
                "tap pageup\ntap pagedown\ntap pagedown\nframes 1\nstatus\ntap pagedown\nframes 1\n"
                "status\ntap pageup\n"
                "tap pageup\nframes 1\nstatus\nquit\n");
  const CliResult v = runViewer(quote(dir.file("a.json")) + " --script " + quote(script) + kWindow);
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  const auto status = linesStarting(v.out, "status     ");
  ASSERT_EQ(status.size(), 3u) << v.describe();
  EXPECT_EQ(status[0], "opened " + dir.file("b.json"));
  EXPECT_EQ(status[1], "opened " + dir.file("c.json"));
  EXPECT_EQ(status[2], "opened " + dir.file("a.json")) << "two back from c";
}

TEST(ViewerControls, AbSideBySideHasADividerAndLabelsAndThePanelsBesideTheViews) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  const std::string rec = test::sourcePath("scenarios/recordings/thesis-bodies-fx32.sgr");
  const std::string shot = dir.file("ab.png");
  const std::string script = dir.write("ab.txt", "step 3\nframes 1\nscreenshot " + shot + "\nquit\n");
  const CliResult v =
      runViewer(quote(rec) + " --ab-variant interp=2 --script " + quote(script) + " --size 600x240 --msaa 0");
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  int width = 0, height = 0, channels = 0;
  unsigned char* data = stbi_load(shot.c_str(), &width, &height, &channels, 4);
  ASSERT_NE(data, nullptr) << shot;
  const std::vector<unsigned char> rgba(data, data + size_t(width) * size_t(height) * 4);
  stbi_image_free(data);
  ASSERT_EQ(width, 600);
  // Each view is (600 - 200) / 2 = 200 px wide (the panel column: min(360, 600 / 3) = 200):
  // the divider is a bright line at x = 200, the panel column starts at x = 400.
  auto px = [&](int x, int y) { return &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4]; };
  int bright = 0;
  for (int y = 40; y < 200; ++y)
    if (px(200, y)[0] > 220 && px(200, y)[1] > 220 && px(200, y)[2] > 220) ++bright;
  EXPECT_GT(bright, 150) << "a white divider between A and B";
  // The labels: dark boxes with white text at the top left of each view.
  int labelA = 0, labelB = 0;
  for (int x = 8; x < 40; ++x)
    for (int y = 8; y < 20; ++y) {
      labelA += px(x, y)[0] > 200 && px(x, y)[1] > 200;
      labelB += px(200 + x, y)[0] > 200 && px(200 + x, y)[1] > 200;
    }
  EXPECT_GT(labelA, 5);
  EXPECT_GT(labelB, 5);
}

// ---- golden screenshots of the new views (docs/images/viewer-*.png) --------------------------------

struct Rgba {
  int width = 0, height = 0;
  std::vector<unsigned char> px;
};

Rgba loadPng(const std::string& path) {
  Rgba img;
  int channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &img.width, &img.height, &channels, 4);
  if (data) img.px.assign(data, data + size_t(img.width) * size_t(img.height) * 4);
  stbi_image_free(data);
  return img;
}

/// Compares the columns [x0, x1) of a screenshot with its golden in docs/images, with the render
/// goldens' tolerances (tests/render_test.cpp: at most 1 % of the pixels off by more than 24 in a
/// channel, mean difference under 2). SIMGRASS_UPDATE_GOLDEN_IMAGES=1 writes the golden instead
/// (.ci/update-golden-images). Columns outside [x0, x1) hold wall-clock figures (frame times,
/// the timing graph) and are not compared.
void expectGolden(const std::string& shot, const std::string& name, int x0, int x1) {
  const std::string golden = test::sourcePath("docs/images/" + name);
  if (std::getenv("SIMGRASS_UPDATE_GOLDEN_IMAGES")) {
    fs::copy_file(shot, golden, fs::copy_options::overwrite_existing);
    std::printf("wrote %s\n", golden.c_str());
    return;
  }
  const Rgba a = loadPng(shot), b = loadPng(golden);
  ASSERT_FALSE(a.px.empty()) << shot;
  ASSERT_FALSE(b.px.empty()) << golden << " is missing: run .ci/update-golden-images";
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  int64_t differing = 0, pixels = 0;
  double sum = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = x0; x < x1; ++x) {
      const size_t o = (size_t(y) * size_t(a.width) + size_t(x)) * 4;
      int worst = 0;
      for (int c = 0; c < 3; ++c) {
        const int d = std::abs(int(a.px[o + size_t(c)]) - int(b.px[o + size_t(c)]));
        worst = std::max(worst, d);
        sum += d;
      }
      differing += worst > 24;
      ++pixels;
    }
  const double fraction = double(differing) / double(pixels), mean = sum / (3.0 * double(pixels));
  EXPECT_LE(fraction, 0.01) << name << ": " << fraction * 100 << "% of the pixels differ (the shot: " << shot << ")";
  EXPECT_LT(mean, 2.0) << name << ": mean difference " << mean;
}

TEST(ViewerControls, ScreenshotsOfTheNewViewsMatchTheirGoldens) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  // Live: the football selected (outlined), the help overlay over hidden panels; then the panels
  // (live control, timing graph) over the scene after 30 ticks.
  const std::string live =
      dir.write("live.txt", "camera -10 1.3 -7 0 -18\nselect 0\nframes 2\ntap f2\ntap f1\nframes 1\nscreenshot " +
                                dir.file("help.png") + "\ntap f1\ntap f2\nframes 30\npause\nframes 1\nscreenshot " +
                                dir.file("panels.png") + "\nquit\n");
  const CliResult v =
      runViewer(scenario("thesis-bodies.json") + " --script " + quote(live) + " --size 640x360 --msaa 0");
  ASSERT_EQ(v.exitCode, 0) << v.describe();
  expectGolden(dir.file("help.png"), "viewer-help.png", 0, 640);
  expectGolden(dir.file("panels.png"), "viewer-panels.png", 360, 640);  // the scene beside the panels
  // A/B side by side: the two views, their labels and the divider (the panel column: timings).
  const std::string ab = dir.write("ab.txt", "step 90\nframes 1\nscreenshot " + dir.file("ab.png") + "\nquit\n");
  const CliResult a = runViewer(quote(test::sourcePath("scenarios/recordings/thesis-bodies-fx32.sgr")) +
                                " --ab-variant interp=2 --script " + quote(ab) + " --size 640x360 --msaa 0");
  ASSERT_EQ(a.exitCode, 0) << a.describe();
  expectGolden(dir.file("ab.png"), "viewer-ab-side.png", 0, 2 * ((640 - 213) / 2));
}

TEST(ViewerControls, RecordCommandsThatDoNotFitTheStateAreExit2) {
  if (!onPath("xvfb-run")) GTEST_SKIP() << "xvfb-run is not on PATH";
  TempDir dir;
  for (const std::string& text :
       {std::string("frames 1\nrecord stop\n"),
        "record start " + dir.file("a.sgr") + "\nframes 1\nrecord start " + dir.file("b.sgr") + "\n"}) {
    const std::string script = dir.write("state.txt", text);
    const CliResult v = runViewer("--script " + quote(script) + kWindow);
    EXPECT_EQ(v.exitCode, 2) << v.describe();
    EXPECT_TRUE(isOneLine(v.err)) << v.describe();
    EXPECT_NE(v.err.find("state.txt:"), std::string::npos) << v.err;
  }
}

TEST(ViewerControls, BadControlLinesAreOneLineAndExit2) {
  TempDir dir;
  for (const char* line : {"mouse -1 0", "mouse 1", "button middle down", "button left sideways", "tap nokey", "back x",
                           "restart now", "key f13 down", "tap f0"}) {
    const std::string script = dir.write("bad.txt", std::string(line) + "\n");
    const CliResult v = runViewer("--script " + quote(script), false);
    EXPECT_EQ(v.exitCode, 2) << line << "\n" << v.describe();
    EXPECT_TRUE(isOneLine(v.err)) << line << "\n" << v.describe();
    EXPECT_NE(v.err.find("bad.txt:1: expected"), std::string::npos) << v.err;
  }
}

}  // namespace
}  // namespace sg
