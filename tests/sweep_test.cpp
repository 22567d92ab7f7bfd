// `simgrass sweep`: the Pareto front against hand-worked sets, the plot module (where a point
// lands, tick labels, decoding the PNG), and a tiny sweep end to end: one row per variant in CSV
// and JSON, zero error for the row equal to the reference, non-zero error elsewhere, the Pareto
// flags recomputed here, the plots, and one-line errors for bad input.
#include <gtest/gtest.h>
#include <stb_image.h>

#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "cli_support.h"
#include "replay/report/pareto.h"
#include "replay/report/plot.h"

namespace sg {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(SweepPareto, HandWorkedFront) {
  // cost, error:   0:(1,5)  1:(2,3)  2:(3,4) dominated by 1  3:(4,1)  4:(5,1) dominated by 3 (same error, dearer)
  //                5:(2,3) equal to 1: neither dominates the other, both stay
  const std::vector<double> cost{1, 2, 3, 4, 5, 2}, error{5, 3, 4, 1, 1, 3};
  const std::vector<bool> front = paretoFront(cost, error);
  EXPECT_EQ(front, (std::vector<bool>{true, true, false, true, false, true}));
  const std::vector<size_t> order = paretoOrder(cost, front);
  EXPECT_EQ(order, (std::vector<size_t>{0, 1, 5, 3}));
}

TEST(SweepPareto, ZeroErrorAndIneligibleRows) {
  // Row 1 (error 0, the reference) is on the front; row 2 would dominate everything but faulted,
  // row 3 has a NaN cost: neither is on the front nor pushes others off it.
  const std::vector<double> cost{1, 10, 0.5, kNaN}, error{0.1, 0, 0.01, 0.001};
  const std::vector<bool> front = paretoFront(cost, error, {true, true, false, true});
  EXPECT_EQ(front, (std::vector<bool>{true, true, false, false}));
  EXPECT_TRUE(paretoFront({}, {}).empty());
}

plot::ScatterPlot threePoints() {
  plot::ScatterPlot p;
  p.title = "test";
  // Data spanning whole decades: x in [1, 100], y in [1e-3, 1e-1].
  auto point = [](double x, double y, plot::Rgb colour, plot::Marker marker) {
    plot::Point pt;
    pt.x = x, pt.y = y, pt.colour = colour, pt.marker = marker;
    return pt;
  };
  p.points.push_back(point(1, 1e-3, {0, 0, 255}, plot::Marker::Circle));
  p.points.push_back(point(100, 1e-1, {0, 160, 0}, plot::Marker::Square));
  p.points.push_back(point(10, 1e-2, {220, 0, 0}, plot::Marker::Diamond));
  return p;
}

TEST(SweepPlot, LogAxesSpanWholeDecadesAndMapLinearlyInLog) {
  const plot::ScatterPlot p = threePoints();
  const plot::Axes a = plot::layoutAxes(p);
  EXPECT_DOUBLE_EQ(a.x0, 0.0);
  EXPECT_DOUBLE_EQ(a.x1, 2.0);
  EXPECT_DOUBLE_EQ(a.y0, -3.0);
  EXPECT_DOUBLE_EQ(a.y1, -1.0);
  ASSERT_LT(a.left, a.right);
  ASSERT_LT(a.top, a.bottom);
  // The decade ends sit on the plot area's edges, the middle decade half way (y grows downwards).
  EXPECT_DOUBLE_EQ(a.pixelX(1), a.left);
  EXPECT_DOUBLE_EQ(a.pixelX(100), a.right - 1);
  EXPECT_DOUBLE_EQ(a.pixelX(10), (a.left + a.right - 1) / 2.0);
  EXPECT_DOUBLE_EQ(a.pixelY(1e-1), a.top);
  EXPECT_DOUBLE_EQ(a.pixelY(1e-3), a.bottom - 1);
  EXPECT_NEAR(a.pixelY(1e-2), (a.top + a.bottom - 1) / 2.0, 1e-9);
  // Values a log axis cannot show.
  EXPECT_TRUE(std::isnan(a.pixelX(0)));
  EXPECT_TRUE(std::isnan(a.pixelY(-1)));
  EXPECT_TRUE(std::isnan(a.pixelY(kNaN)));
}

TEST(SweepPlot, PointLandsAtItsPixel) {
  const plot::ScatterPlot p = threePoints();
  const plot::Image img = plot::render(p);
  ASSERT_EQ(img.width, p.width);
  ASSERT_EQ(img.height, p.height);
  const plot::Axes a = plot::layoutAxes(p);
  // The red diamond at (10, 1e-2) is centred half way across and down the plot area.
  const int cx = (a.left + a.right - 1) / 2, cy = (a.top + a.bottom - 1) / 2;
  EXPECT_EQ(img.at(cx, cy), (plot::Rgb{220, 0, 0}));
  EXPECT_EQ(img.at(cx + 3, cy), (plot::Rgb{220, 0, 0}));
  // 10 px off the marker (radius 5) is background or grid, not red.
  EXPECT_NE(img.at(cx + 10, cy + 10), (plot::Rgb{220, 0, 0}));
  // The blue circle in the bottom-left corner, the green square in the top-right one.
  EXPECT_EQ(img.at(a.left + 1, a.bottom - 2), (plot::Rgb{0, 0, 255}));
  EXPECT_EQ(img.at(a.right - 2, a.top + 1), (plot::Rgb{0, 160, 0}));
}

TEST(SweepPlot, LineIsDrawnBetweenItsPoints) {
  plot::ScatterPlot p;
  p.line = {{1, 1e-3}, {100, 1e-1}};
  p.lineColour = {10, 20, 30};
  const plot::Image img = plot::render(p);
  const plot::Axes a = plot::layoutAxes(p);
  // The diagonal of the plot area passes through its centre.
  const int cx = int(std::lround(a.pixelX(10))), cy = int(std::lround(a.pixelY(1e-2)));
  bool found = false;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) found = found || img.at(cx + dx, cy + dy) == plot::Rgb{10, 20, 30};
  EXPECT_TRUE(found);
}

TEST(SweepPlot, TickLabels) {
  EXPECT_EQ(plot::tickLabel(1e-3), "1e-3");
  EXPECT_EQ(plot::tickLabel(1e-9), "1e-9");
  EXPECT_EQ(plot::tickLabel(0.01), "0.01");
  EXPECT_EQ(plot::tickLabel(1), "1");
  EXPECT_EQ(plot::tickLabel(100), "100");
  EXPECT_EQ(plot::tickLabel(1e5), "1e5");
  EXPECT_EQ(plot::tickLabel(0), "0");
}

TEST(SweepPlot, PngDecodesWithItsPixels) {
  TempDir dir;
  const plot::ScatterPlot p = threePoints();
  const plot::Image img = plot::render(p);
  std::string error;
  ASSERT_TRUE(plot::writePng(dir.file("p.png"), img, &error)) << error;
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load(dir.file("p.png").c_str(), &w, &h, &n, 3);
  ASSERT_NE(data, nullptr);
  EXPECT_EQ(w, img.width);
  EXPECT_EQ(h, img.height);
  EXPECT_EQ(std::vector<uint8_t>(data, data + size_t(w) * size_t(h) * 3), img.rgb);
  stbi_image_free(data);
  EXPECT_FALSE(plot::writePng(dir.file("missing/p.png"), img, &error));
  EXPECT_NE(error.find("missing/p.png"), std::string::npos) << error;
}

// ---- the command ----------------------------------------------------------------------------

/// A 31 x 31 meadow, wind, a ball kicked at tick 6 of 1/60 s, a 15 x 15-particle LOD window.
const char* kTinyScenario = R"({"format": "simgrass-scenario/1", "name": "tiny-sweep", "timeStep": "1/60",
 "field": {"patchesX": 31, "patchesZ": 31, "spacing": 0.25},
 "particles": {"constraintLength": 0.5},
 "wind": {"schedule": [{"force": [0, 1, 0.9], "duration": 0.5}, {"force": [0, 0, 0], "duration": 0.5}]},
 "bodies": {"list": [{"name": "ball", "shape": {"type": "sphere", "radius": 0.3}, "mass": 0.45, "position": [-2, 0.3, 0]}]},
 "script": [{"tick": 6, "body": "ball", "command": "addVelocity", "value": [3, 0, 0]}],
 "camera": [{"tick": 0, "position": [-1, 2, 0]}],
 "lod": {"mode": "off", "window": [15, 15]}})";

const std::vector<std::string> kColumns{"scenario",
                                        "scalar",
                                        "k",
                                        "dt",
                                        "dt_s",
                                        "lod",
                                        "broadphase",
                                        "steps",
                                        "ms_per_tick",
                                        "ms_per_simulated_second",
                                        "tip_rms_m",
                                        "tip_max_m",
                                        "body_pos_max_m",
                                        "body_angle_max_rad",
                                        "first_divergent_time",
                                        "states_compared",
                                        "status",
                                        "pareto",
                                        "pareto_tip_max",
                                        "pareto_body",
                                        "model_error_rms_m",
                                        "model_error_max_m",
                                        "pareto_model",
                                        "model_error_body_rms_m",
                                        "model_error_body_max_m",
                                        "physics"};

std::vector<std::map<std::string, std::string>> readCsv(const std::string& path) {
  std::istringstream in(readFile(path));
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  auto split = [](const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    std::string f;
    while (std::getline(ss, f, ',')) out.push_back(f);
    return out;
  };
  if (std::getline(in, line)) header = split(line);
  while (std::getline(in, line)) {
    const std::vector<std::string> f = split(line);
    EXPECT_EQ(f.size(), header.size()) << line;
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < f.size() && i < header.size(); ++i) row[header[i]] = f[i];
    rows.push_back(row);
  }
  EXPECT_EQ(header, kColumns);
  return rows;
}

class SweepCli : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir;
    scenario_ = dir_->write("tiny.json", kTinyScenario);
    result_ = new CliResult(runCli("sweep --scenarios " + quote(scenario_) +
                                   " --seconds 1 --scalars double,fx16 --k 1,2 --dt 1/60,1/240 --lod off "
                                   "--repeats 2 --json --out " +
                                   quote(dir_->file("out"))));
  }
  static void TearDownTestSuite() {
    delete result_;
    delete dir_;
  }
  static TempDir* dir_;
  static std::string scenario_;
  static CliResult* result_;
};
TempDir* SweepCli::dir_ = nullptr;
std::string SweepCli::scenario_;
CliResult* SweepCli::result_ = nullptr;

TEST_F(SweepCli, OneRowPerVariantInCsvAndJson) {
  ASSERT_EQ(result_->exitCode, 0) << result_->describe();
  const json doc = parseJson(*result_);
  ASSERT_TRUE(doc.contains("rows"));
  const json& rows = doc["rows"];
  ASSERT_EQ(rows.size(), 8u);                                           // 2 scalars x 2 k x 2 dt x 1 lod
  EXPECT_EQ(json::parse(readFile(dir_->file("out/sweep.json"))), doc);  // --json prints the file
  const auto csv = readCsv(dir_->file("out/sweep.csv"));
  ASSERT_EQ(csv.size(), rows.size());
  std::set<std::string> seen;
  for (size_t i = 0; i < rows.size(); ++i) {
    const json& r = rows[i];
    for (const std::string& c : kColumns) EXPECT_TRUE(r.contains(c)) << c;
    const std::string key = r["scalar"].get<std::string>() + " " + std::to_string(r["k"].get<int>()) + " " +
                            r["dt"].get<std::string>() + " " + r["lod"].get<std::string>();
    EXPECT_TRUE(seen.insert(key).second) << "duplicate variant " << key;
    EXPECT_EQ(r["scenario"], "tiny-sweep");
    EXPECT_EQ(r["status"], "ok");
    // The CSV row says the same (10 significant digits).
    EXPECT_EQ(csv[i].at("scalar"), r["scalar"].get<std::string>());
    EXPECT_EQ(csv[i].at("dt"), r["dt"].get<std::string>());
    for (const char* c : {"ms_per_tick", "tip_rms_m", "tip_max_m", "body_pos_max_m"})
      EXPECT_NEAR(std::stod(csv[i].at(c)), r[c].get<double>(), 1e-9 * std::fabs(r[c].get<double>())) << c;
    EXPECT_EQ(csv[i].at("pareto"), r["pareto"].get<bool>() ? "1" : "0");
    // 1 s of its own steps; the cost per simulated second is the cost per tick / dt.
    const double dt = r["dt_s"].get<double>();
    EXPECT_EQ(r["steps"].get<int64_t>(), std::llround(1.0 / dt));
    EXPECT_GT(r["ms_per_tick"].get<double>(), 0.0);
    EXPECT_NEAR(r["ms_per_simulated_second"].get<double>(), r["ms_per_tick"].get<double>() / dt,
                1e-9 * r["ms_per_simulated_second"].get<double>());
    // Compared every 1/60 s (the coarsest dt) from 0 to 1 s.
    EXPECT_EQ(r["states_compared"].get<int64_t>(), 61);
  }
}

TEST_F(SweepCli, ReferenceRowIsExactAndOthersDiffer) {
  ASSERT_EQ(result_->exitCode, 0) << result_->describe();
  int references = 0;
  const json doc = parseJson(*result_);
  for (const json& r : doc["rows"]) {
    const bool isReference = r["scalar"] == "double" && r["k"] == 1 && r["dt"] == "1/240" && r["lod"] == "off";
    if (isReference) {
      ++references;
      EXPECT_EQ(r["tip_rms_m"].get<double>(), 0.0);
      EXPECT_EQ(r["tip_max_m"].get<double>(), 0.0);
      EXPECT_EQ(r["body_pos_max_m"].get<double>(), 0.0);
      EXPECT_EQ(r["body_angle_max_rad"].get<double>(), 0.0);
      EXPECT_EQ(r["first_divergent_time"].get<double>(), -1.0);
      EXPECT_TRUE(r["pareto"].get<bool>()) << "nothing is more accurate than an error of 0";
    } else {
      // fx16, k = 2 or a coarser step: the tips move differently (well under a rod length, 0.5 m).
      EXPECT_GT(r["tip_rms_m"].get<double>(), 0.0) << r.dump();
      EXPECT_GT(r["tip_max_m"].get<double>(), 0.0) << r.dump();
      EXPECT_LT(r["tip_rms_m"].get<double>(), 0.5) << r.dump();
      EXPECT_GE(r["first_divergent_time"].get<double>(), 0.0) << r.dump();
    }
    if (r["scalar"] == "fx16") {
      EXPECT_GT(r["body_pos_max_m"].get<double>(), 0.0) << r.dump();
    }
  }
  EXPECT_EQ(references, 1);
}

TEST_F(SweepCli, ParetoFlagsMatchAnIndependentCheck) {
  ASSERT_EQ(result_->exitCode, 0) << result_->describe();
  const json rows = parseJson(*result_)["rows"];
  const std::pair<const char*, const char*> measures[] = {{"tip_rms_m", "pareto"},
                                                          {"tip_max_m", "pareto_tip_max"},
                                                          {"body_pos_max_m", "pareto_body"},
                                                          {"model_error_rms_m", "pareto_model"}};
  for (const auto& [error, flag] : measures) {
    int onFront = 0;
    for (const json& a : rows) {
      bool dominated = false;
      for (const json& b : rows) {
        if (&a == &b) continue;
        const double ca = a["ms_per_simulated_second"], cb = b["ms_per_simulated_second"];
        const double ea = a[error], eb = b[error];
        if (cb <= ca && eb <= ea && (cb < ca || eb < ea)) dominated = true;
      }
      EXPECT_EQ(a[flag].get<bool>(), !dominated) << flag << " " << a.dump();
      onFront += dominated ? 0 : 1;
    }
    EXPECT_GE(onFront, 1) << flag;
  }
}

TEST_F(SweepCli, PlotsDecode) {
  ASSERT_EQ(result_->exitCode, 0) << result_->describe();
  const json doc = parseJson(*result_);
  ASSERT_EQ(doc["plots"].size(), 4u);
  for (const char* kind : {"tip-rms", "tip-max", "body", "model-error"}) {
    const std::string path = dir_->file(std::string("out/tiny-sweep-") + kind + ".png");
    int w = 0, h = 0, n = 0;
    unsigned char* data = stbi_load(path.c_str(), &w, &h, &n, 3);
    ASSERT_NE(data, nullptr) << path;
    EXPECT_GE(w, 600);
    EXPECT_GE(h, 400);
    EXPECT_LE(w, 4000);
    // The eight points are drawn in the plot area, in the colours of double (purple) and fx16
    // (red); the legend's samples of those colours lie outside it.
    plot::ScatterPlot sameSize;
    sameSize.width = w, sameSize.height = h;
    const plot::Axes a = plot::layoutAxes(sameSize);
    int red = 0, purple = 0;
    for (int y = a.top; y < a.bottom; ++y)
      for (int x = a.left; x < a.right; ++x) {
        const unsigned char* px = data + (size_t(y) * size_t(w) + size_t(x)) * 3;
        red += px[0] == 214 && px[1] == 39 && px[2] == 40;
        purple += px[0] == 148 && px[1] == 103 && px[2] == 189;
      }
    EXPECT_GT(red, 40) << kind;
    EXPECT_GT(purple, 40) << kind;
    stbi_image_free(data);
  }
}

TEST(SweepCliErrors, BadInputIsOneLineExit2) {
  TempDir dir;
  const std::string scenario = dir.write("tiny.json", kTinyScenario);
  // A small valid sweep with one option replaced by a bad value.
  auto args = [&](const std::string& file, const std::string& option, const std::string& value) {
    std::map<std::string, std::string> o{{"--seconds", "0.1"},      {"--scalars", "double"}, {"--k", "1"},
                                         {"--dt", "1/60"},          {"--lod", "off"},        {"--repeats", "1"},
                                         {"--out", dir.file("out")}};
    o[option] = value;
    std::string line = "sweep --scenarios " + quote(file);
    for (const auto& [k, v] : o) line += " " + k + " " + quote(v);
    return line;
  };
  const std::string blocker = dir.write("file", "not a folder");
  // A step finer than the 1/240 reference that is not a whole fraction of it.
  std::string fineText = kTinyScenario;
  fineText.replace(fineText.find("1/60"), 4, "1/500");
  const std::string fine500 = dir.write("fine.json", fineText);
  const std::pair<std::string, std::string> cases[] = {
      {args(dir.file("nope.json"), "--k", "1"), "nope.json"},
      {args(scenario, "--k", "5"), "--k"},
      {args(scenario, "--k", "1,,2"), "--k"},
      {args(scenario, "--scalars", "fx8"), "--scalars"},
      {args(scenario, "--dt", "1/90"), "--dt 1/90"},
      {args(scenario, "--dt", "2"), "--dt"},
      {args(scenario, "--lod", "maybe"), "--lod"},
      {args(scenario, "--out", blocker + "/sub"), "--out"},
      {args(fine500, "--k", "1"), "$.timeStep"},
      {args(scenario, "--seconds", "0.01"), "--seconds"},  // under one 1/60 s step
      {args(scenario, "--models", "rigid"), "--models"},
  };
  for (const auto& [args, mention] : cases) {
    const CliResult r = runCli(args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << args;
    EXPECT_NE(r.err.find(mention), std::string::npos) << args << "\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(dir.file("out/sweep.csv")));  // nothing ran
}

TEST(SweepCliErrors, HelpNamesTheOptions) {
  const CliResult r = runCli("sweep --help");
  EXPECT_EQ(r.exitCode, 0);
  for (const char* opt : {"--scenarios", "--seconds", "--out", "--scalars", "--k", "--dt", "--lod", "--models",
                          "--repeats", "--threads", "--json"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
}

// --models sweeps each scenario once per grass model, each against its own reference (the same
// model at double, k = 1, dt = 1/240): the reference setting of each model's rows is exact, the
// rows name their model, and the blade rows differ from the thesis rows.
TEST(SweepCliModels, EachModelAgainstItsOwnReference) {
  TempDir dir;
  const std::string scenario = dir.write("tiny.json", kTinyScenario);
  const CliResult r = runCli("sweep --scenarios " + quote(scenario) +
                             " --models thesis,blade --seconds 0.5 --scalars double,fx32 --k 1 --dt 1/60,1/240 "
                             "--lod off --repeats 1 --json --out " +
                             quote(dir.file("out")));
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  const json doc = parseJson(r);
  ASSERT_EQ(doc["scenarios"].size(), 2u);
  EXPECT_EQ(doc["scenarios"][0]["model"], "thesis");
  EXPECT_EQ(doc["scenarios"][1]["model"], "blade");
  EXPECT_EQ(doc["scenarios"][1]["name"], "tiny-sweep [blade]");
  ASSERT_EQ(doc["rows"].size(), 8u);  // 2 models x 2 scalars x 2 dt
  std::map<std::string, double> tipRms;
  for (const json& row : doc["rows"]) {
    EXPECT_EQ(row["status"], "ok");
    const std::string key =
        row["model"].get<std::string>() + " " + row["scalar"].get<std::string>() + " " + row["dt"].get<std::string>();
    tipRms[key] = row["tip_rms_m"].get<double>();
  }
  EXPECT_EQ(tipRms.at("thesis double 1/240"), 0.0);  // each model's reference setting is exact
  EXPECT_EQ(tipRms.at("blade double 1/240"), 0.0);
  EXPECT_GT(tipRms.at("blade double 1/60"), 0.0);
  EXPECT_NE(tipRms.at("blade fx32 1/60"), tipRms.at("thesis fx32 1/60"));
  // Each scenario's behaviour on one tuft: thesis is not stationary (its hidden upward velocity
  // stiffens it: the same gust sways it far less at 600 s), the blade is, settles after the gust
  // within seconds and, trampled by the press, stays down (docs/grass-models.md).
  const json& thesis = doc["scenarios"][0]["behaviour"];
  const json& blade = doc["scenarios"][1]["behaviour"];
  EXPECT_LT(thesis["sway_after_600_s_m"].get<double>(), 0.5 * thesis["sway_at_start_m"].get<double>()) << thesis;
  EXPECT_GT(blade["sway_at_start_m"].get<double>(), 0.0) << blade;
  EXPECT_NEAR(blade["sway_after_600_s_m"].get<double>(), blade["sway_at_start_m"].get<double>(), 1e-4) << blade;
  EXPECT_GE(blade["settle_after_gust_s"].get<double>(), 0.0) << blade;
  EXPECT_LT(blade["settle_after_gust_s"].get<double>(), 2.0) << blade;
  EXPECT_GT(blade["down_after_press_s"].get<double>(), 3.0) << blade;  // trampled: 10 s to recover
  EXPECT_GT(blade["settle_after_press_s"].get<double>(), blade["down_after_press_s"].get<double>()) << blade;
  EXPECT_NE(r.out.find("behaviour"), std::string::npos);
  // Each row's model error against the reference blade (replay/report/reference_blade.h): it
  // depends on the model and dt only, and the blade model is far closer to the truth than the
  // thesis model (tests/reference_blade_test.cpp measures all three).
  std::map<std::string, double> modelError;
  for (const json& row : doc["rows"]) {
    const std::string key = row["model"].get<std::string>() + " " + row["dt"].get<std::string>();
    const double e = row["model_error_rms_m"].get<double>();
    EXPECT_GT(e, 0.0) << row;
    EXPECT_GE(row["model_error_max_m"].get<double>(), e) << row;
    if (modelError.count(key)) {
      EXPECT_EQ(modelError[key], e) << key;  // the same for every scalar
    }
    modelError[key] = e;
  }
  // Half the thesis model's error without bodies; the ball through the blade's middle, which no
  // tip model feels, adds about the same to every model (docs/grass-models.md).
  EXPECT_LT(modelError.at("blade 1/60"), 0.75 * modelError.at("thesis 1/60"));
  EXPECT_LT(modelError.at("blade 1/240"), 0.75 * modelError.at("thesis 1/240"));
  for (const json& row : doc["rows"]) {
    EXPECT_GT(row["model_error_body_rms_m"].get<double>(), 0.0) << row;
    EXPECT_GE(row["model_error_body_max_m"].get<double>(), row["model_error_body_rms_m"].get<double>()) << row;
  }
}

}  // namespace
}  // namespace sg
