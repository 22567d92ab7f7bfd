// Input robustness: every bad scenario ends in ONE ScenarioError line that names the file, the
// JSON path and what was expected; never a crash, a hang or a silently accepted value.
//
// Table-driven: each row is a broken scenario text and the JSON path its error must name.
// Stages: parseScenario (syntax, keys, types, ranges, heightmap files), validateForScalar (scalar
// range and resolution, gust length, memory) and makeWorld (the whole chain).
#include <gtest/gtest.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <string>
#include <typeinfo>
#include <vector>

#include "tests/test_support.h"

namespace sg {
namespace {

constexpr const char* kFile = "bad.json";

// ---- PNG fixtures --------------------------------------------------------------------------

/// PNG bytes written by stb_image_write (8-bit, comp channels), pixel values a simple ramp.
std::vector<uint8_t> makePng(int w, int h, int comp) {
  std::vector<uint8_t> pixels(size_t(w) * size_t(h) * size_t(comp));
  for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = uint8_t(i * 37 % 256);
  std::vector<uint8_t> out;
  stbi_write_png_to_func(
      [](void* ctx, void* data, int size) {
        auto* o = static_cast<std::vector<uint8_t>*>(ctx);
        const auto* p = static_cast<const uint8_t*>(data);
        o->insert(o->end(), p, p + size);
      },
      &out, w, h, comp, pixels.data(), w * comp);
  return out;
}

/// A valid 2x2 16-bit grayscale PNG (bit depth 16, colour type 0), every sample 0x1234. Built
/// with Python's zlib/struct: stb_image_write cannot write 16-bit PNGs.
const std::vector<uint8_t>& png16Bit() {
  static const std::vector<uint8_t> bytes = {
      0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00,
      0x00, 0x02, 0x00, 0x00, 0x00, 0x02, 0x10, 0x00, 0x00, 0x00, 0x00, 0x07, 0x4d, 0x8e, 0xbb, 0x00, 0x00, 0x00,
      0x0f, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0x10, 0x32, 0x11, 0x32, 0x61, 0x00, 0x11, 0x00, 0x05, 0x3e,
      0x01, 0x19, 0x8f, 0x13, 0x1a, 0x21, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
  return bytes;
}

/// Files a scenario may name; everything else is "not found".
const std::map<std::string, std::vector<uint8_t>>& fixtureFiles() {
  static const std::map<std::string, std::vector<uint8_t>> files = [] {
    std::map<std::string, std::vector<uint8_t>> f;
    f["gray4x3.png"] = makePng(4, 3, 1);
    f["rgb.png"] = makePng(2, 2, 3);
    f["grayalpha.png"] = makePng(2, 2, 2);
    f["one.png"] = makePng(1, 1, 1);
    f["thin.png"] = makePng(1, 5, 1);
    f["sixteen.png"] = png16Bit();
    f["text.png"] = std::vector<uint8_t>{'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd', '\n'};
    f["empty.png"] = {};
    const std::vector<uint8_t> good = makePng(4, 3, 1);
    f["truncated.png"] = std::vector<uint8_t>(good.begin(), good.begin() + 33);  // signature + IHDR only
    std::vector<uint8_t> corrupt = good;
    corrupt[41] = 0x00;  // first byte of the IDAT payload: the zlib header
    f["corrupt.png"] = corrupt;
    f["a\nb.png"] = f["text.png"];
    return f;
  }();
  return files;
}

bool fixtureReader(const std::string& path, std::vector<uint8_t>* bytes, std::string* error) {
  auto it = fixtureFiles().find(path);
  if (it == fixtureFiles().end()) {
    *error = "an existing file, '" + path + "' was not found";
    return false;
  }
  *bytes = it->second;
  return true;
}

Scenario parse(const std::string& text) { return parseScenario(text, kFile, fixtureReader); }

// ---- the one-line error contract ------------------------------------------------------------

/// Runs f and checks it throws a ScenarioError for kFile whose path is `path` (or starts with
/// it when prefix is set), whose message is one line "bad.json: <path>: expected ..." and
/// contains `extra`.
testing::AssertionResult throwsScenarioError(const std::function<void()>& f, const std::string& path,
                                             const std::string& extra = "", bool prefix = false) {
  try {
    f();
  } catch (const ScenarioError& e) {
    const std::string what = e.what();
    auto fail = [&]() { return testing::AssertionFailure() << "message: [" << what << "]\n  "; };
    if (what.rfind(std::string(kFile) + ": ", 0) != 0) return fail() << "does not start with 'bad.json: '";
    if (e.file() != kFile) return fail() << "file() is '" << e.file() << "'";
    if (what.find('\n') != std::string::npos || what.find('\r') != std::string::npos)
      return fail() << "is not a single line";
    if (what.find(path) == std::string::npos) return fail() << "does not name the path '" << path << "'";
    if (prefix ? e.path().rfind(path, 0) != 0 : e.path() != path)
      return fail() << "path() is '" << e.path() << "', expected " << (prefix ? "it to start with " : "") << "'" << path
                    << "'";
    if (what.find("expected") == std::string::npos) return fail() << "does not say what was expected";
    if (!extra.empty() && what.find(extra) == std::string::npos) return fail() << "does not contain '" << extra << "'";
    return testing::AssertionSuccess();
  } catch (const std::exception& e) {
    return testing::AssertionFailure() << "threw " << typeid(e).name() << " instead of ScenarioError: " << e.what();
  } catch (...) {
    return testing::AssertionFailure() << "threw a non-std exception instead of ScenarioError";
  }
  return testing::AssertionFailure() << "no ScenarioError was thrown (the scenario was accepted)";
}

struct BadCase {
  std::string name;     ///< test name suffix
  std::string text;     ///< scenario JSON
  std::string path;     ///< the JSON path (or byte position) the error must name
  std::string extra;    ///< another text the message must contain ("" = none)
  bool prefix = false;  ///< path() only has to start with `path`
};
void PrintTo(const BadCase& c, std::ostream* os) { *os << c.name << ": " << c.text.substr(0, 200); }
std::string caseName(const testing::TestParamInfo<BadCase>& info) { return info.param.name; }

std::string deepArray(int depth) { return std::string(size_t(depth), '[') + std::string(size_t(depth), ']'); }
std::string manyGusts(int n) {
  std::string s = "[";
  for (int i = 0; i < n; ++i) s += std::string(i ? "," : "") + R"({"force": [0, 1, 0], "duration": 1})";
  return s + "]";
}
std::string heightmapTerrain(const std::string& file) {
  return R"({"terrain": {"type": "heightmap", "file": ")" + file + R"("}})";
}

// ---- parse errors ----------------------------------------------------------------------------

class ScenarioParseError : public testing::TestWithParam<BadCase> {};

TEST_P(ScenarioParseError, OneLineNamingFilePathAndExpected) {
  const BadCase& c = GetParam();
  EXPECT_TRUE(throwsScenarioError([&] { parse(c.text); }, c.path, c.extra, c.prefix));
}

const std::vector<BadCase> kSyntaxCases = {
    // The position is that of the offending character: byte offset (1-based), line, column.
    {"SyntaxErrorNamesByteLineColumn", "{\n  \"seed\": ,\n}", "byte 13 (line 2, column 11)", "valid JSON"},
    {"TrailingGarbage", "{} x", "byte 4 (line 1, column 4)", "valid JSON"},
    {"EmptyFile", "", "byte 1 (line 1, column 1)", "valid JSON"},
    {"OnlyWhitespace", "  \n  ", "byte ", "valid JSON", true},
    {"UnterminatedObject", "{\"seed\": 1", "byte ", "valid JSON", true},
    {"TrailingComma", "{\"seed\": 1,}", "byte ", "valid JSON", true},
    {"Comment", "{\"seed\": 1 // one\n}", "byte ", "valid JSON", true},
    {"NaNLiteral", R"({"field": {"spacing": NaN}})", "byte ", "valid JSON", true},
    {"InfinityLiteral", R"({"field": {"spacing": Infinity}})", "byte ", "valid JSON", true},
    {"RawNewlineInString", "{\"name\": \"two\nlines\"}", "byte ", "valid JSON", true},
    {"InvalidUtf8InString", "{\"name\": \"\xff\xfe\"}", "byte ", "valid JSON", true},
    {"NulByte", std::string("{\"seed\": 1\0}", 12), "byte ", "valid JSON", true},
};
INSTANTIATE_TEST_SUITE_P(ScenarioSyntax, ScenarioParseError, testing::ValuesIn(kSyntaxCases), caseName);

const std::vector<BadCase> kStructureCases = {
    {"TopLevelArray", "[1, 2]", "$", "an object, got an array"},
    {"TopLevelString", "\"meadow\"", "$", "an object"},
    {"TopLevelNull", "null", "$", "an object"},
    {"TopLevelNumber", "42", "$", "an object"},
    {"UnknownTopLevelKey", R"({"seed": 1, "colour": "green"})", "$.colour", "unknown key 'colour'"},
    {"UnknownFieldKey", R"({"field": {"spacng": 0.25}})", "$.field.spacng", "unknown key"},
    {"UnknownParticlesKey", R"({"particles": {"dampening": 0.9}})", "$.particles.dampening", "unknown key"},
    {"UnknownWindKey", R"({"wind": {"speed": 1}})", "$.wind.speed", "unknown key"},
    {"UnknownGustKey", R"({"wind": {"schedule": [{"force": [0, 0, 0], "duration": 1, "gust": 2}]}})",
     "$.wind.schedule[0].gust", "unknown key"},
    {"UnknownTerrainKey", R"({"terrain": {"type": "flat", "slope": 1}})", "$.terrain.slope", "unknown key"},
    // A key with an escaped newline must not break the one-line rule (the path is escaped somehow).
    {"UnknownKeyWithNewline", "{\"a\\nb\": 1}", "$.", "unknown key", true},
    {"DuplicateTopLevelKey", R"({"seed": 1, "seed": 2})", "$.seed", "twice"},
    {"DuplicateNestedKey", R"({"field": {"spacing": 0.25, "spacing": 0.5}})", "$.field.spacing", "twice"},
    {"DuplicateKeyInSecondGust",
     R"({"wind": {"schedule": [{"force": [0, 1, 0.5], "duration": 1},
                               {"force": [0, 0, 0], "duration": 1, "duration": 2}]}})",
     "$.wind.schedule[1].duration", "twice"},
    {"FormatWrong", R"({"format": "simgrass-scenario/2"})", "$.format", "simgrass-scenario/1"},
    {"FormatNumber", R"({"format": 1})", "$.format", ""},
    {"FieldNotObject", R"({"field": 3})", "$.field", "an object"},
    {"FieldNull", R"({"field": null})", "$.field", "an object"},
    // Refused while parsing, before a DOM exists (tests/input_hardening_test.cpp has the rest).
    {"FieldDeeplyNestedArray", "{\"field\": " + deepArray(100000) + "}", "$.field[0]", "nested at most 64", true},
    {"ParticlesArray", R"({"particles": []})", "$.particles", "an object"},
    {"WindString", R"({"wind": "strong"})", "$.wind", "an object"},
    {"TerrainNumber", R"({"terrain": 0})", "$.terrain", "an object"},
};
INSTANTIATE_TEST_SUITE_P(ScenarioStructure, ScenarioParseError, testing::ValuesIn(kStructureCases), caseName);

const std::vector<BadCase> kTypeCases = {
    {"NameNumber", R"({"name": 5})", "$.name", "a string"},
    {"DescriptionArray", R"({"description": ["a"]})", "$.description", "a string"},
    {"SpacingString", R"({"field": {"spacing": "abc"}})", "$.field.spacing", "a number"},
    {"SpacingBoolean", R"({"field": {"spacing": true}})", "$.field.spacing", "a number"},
    {"SpacingNull", R"({"field": {"spacing": null}})", "$.field.spacing", "a number"},
    {"SpacingObject", R"({"field": {"spacing": {"value": 1}}})", "$.field.spacing", "a number"},
    {"SpacingEmptyString", R"({"field": {"spacing": ""}})", "$.field.spacing", "a number"},
    {"SpacingFractionWithoutDenominator", R"({"field": {"spacing": "1/"}})", "$.field.spacing", ""},
    {"SpacingExponentWithoutDigits", R"({"field": {"spacing": "1e"}})", "$.field.spacing", ""},
    {"CenterOneElement", R"({"field": {"center": [0]}})", "$.field.center", "an array of 2 numbers"},
    {"CenterThreeElements", R"({"field": {"center": [0, 0, 0]}})", "$.field.center", "an array of 2 numbers"},
    {"CenterNotArray", R"({"field": {"center": 0}})", "$.field.center", "an array of 2 numbers"},
    {"CenterElementString", R"({"field": {"center": [0, "x"]}})", "$.field.center[1]", "a number"},
    {"InitialVelocityTwoElements", R"({"particles": {"initialVelocity": [0.2, 0.2]}})", "$.particles.initialVelocity",
     "an array of 3 numbers"},
    {"AccelerationNumber", R"({"particles": {"acceleration": 1}})", "$.particles.acceleration",
     "an array of 3 numbers"},
    {"AccelerationElementNull", R"({"particles": {"acceleration": [0, null, 0]}})", "$.particles.acceleration[1]",
     "a number"},
    {"ForceFourElements", R"({"wind": {"schedule": [{"force": [0, 1, 0, 0], "duration": 1}]}})",
     "$.wind.schedule[0].force", "an array of 3 numbers"},
    {"ForceElementBoolean", R"({"wind": {"schedule": [{"force": [0, 1, false], "duration": 1}]}})",
     "$.wind.schedule[0].force[2]", "a number"},
    {"TiltDropTwoElements", R"({"particles": {"tiltDrop": [0.2, 0.3]}})", "$.particles.tiltDrop",
     "an array of 3 numbers"},
    {"ScalarNumber", R"({"scalar": 32})", "$.scalar", "fx32"},
    {"ConstraintModeNumber", R"({"particles": {"constraintMode": 1}})", "$.particles.constraintMode", "thesis"},
    {"TerrainFileNumber", R"({"terrain": {"type": "heightmap", "file": 5}})", "$.terrain.file", "a string"},
    {"FlatHeightString", R"({"terrain": {"type": "flat", "height": "low"}})", "$.terrain.height", "a number"},
};
INSTANTIATE_TEST_SUITE_P(ScenarioTypes, ScenarioParseError, testing::ValuesIn(kTypeCases), caseName);

const std::vector<BadCase> kValueCases = {
    // field
    {"SpacingZero", R"({"field": {"spacing": 0}})", "$.field.spacing", "positive"},
    {"ContactHertzZero", R"({"bodies": {"contactHertz": 0}})", "$.bodies.contactHertz", "positive"},
    {"TipContactUnknown", R"({"bodies": {"tipContact": "stick"}})", "$.bodies.tipContact",
     "one of \"push\", \"hold\", got \"stick\""},
    {"ContactHertzNegative", R"({"bodies": {"contactHertz": -60}})", "$.bodies.contactHertz", "positive"},
    {"IslandSweepsZero", R"({"bodies": {"islandVelocityIterations": 0}})", "$.bodies.islandVelocityIterations",
     "an integer"},
    {"IslandSweepsTooMany", R"({"bodies": {"islandVelocityIterations": 1001}})", "$.bodies.islandVelocityIterations",
     "an integer"},
    {"IslandSweepsFraction", R"({"bodies": {"islandVelocityIterations": 2.5}})", "$.bodies.islandVelocityIterations",
     "an integer"},
    {"SpacingNegative", R"({"field": {"spacing": -0.25}})", "$.field.spacing", "positive"},
    {"SpacingNegativeFraction", R"({"field": {"spacing": "-1/4"}})", "$.field.spacing", "positive"},
    {"SpacingZeroFraction", R"({"field": {"spacing": "0/5"}})", "$.field.spacing", "positive"},
    {"JitterAboveHalf", R"({"field": {"jitter": 0.51}})", "$.field.jitter", "0.5"},
    {"JitterNegative", R"({"field": {"jitter": -0.1}})", "$.field.jitter", ""},
    {"ScaleYZero", R"({"field": {"scaleY": 0}})", "$.field.scaleY", "positive"},
    {"ScaleXZNegative", R"({"field": {"scaleXZ": -1}})", "$.field.scaleXZ", "positive"},
    {"AtlasVariantsZero", R"({"field": {"atlasVariants": 0}})", "$.field.atlasVariants", "an integer"},
    {"AtlasVariants17", R"({"field": {"atlasVariants": 17}})", "$.field.atlasVariants", "an integer"},
    {"PatchesXZero", R"({"field": {"patchesX": 0}})", "$.field.patchesX", "an integer"},
    {"PatchesXNegative", R"({"field": {"patchesX": -3}})", "$.field.patchesX", "an integer"},
    {"PatchesXNonInteger", R"({"field": {"patchesX": 1.5}})", "$.field.patchesX", "an integer"},
    {"PatchesXString", R"({"field": {"patchesX": "151"}})", "$.field.patchesX", "an integer"},
    {"PatchesXHuge", R"({"field": {"patchesX": 1099511627776}})", "$.field.patchesX", "an integer"},
    {"PatchesXAboveUint64", R"({"field": {"patchesX": 100000000000000000000000}})", "$.field.patchesX", "an integer"},
    {"PatchesZZero", R"({"field": {"patchesZ": 0}})", "$.field.patchesZ", "an integer"},
    {"PatchesZJustAboveLimit", R"({"field": {"patchesZ": 1048577}})", "$.field.patchesZ", "an integer"},
    // particles
    {"DampingZero", R"({"particles": {"damping": 0}})", "$.particles.damping", ""},
    {"DampingAboveOne", R"({"particles": {"damping": 1.01}})", "$.particles.damping", ""},
    {"DampingNegative", R"({"particles": {"damping": -0.5}})", "$.particles.damping", ""},
    {"InterpolationFive", R"({"particles": {"interpolation": 5}})", "$.particles.interpolation", "an integer"},
    {"InterpolationZero", R"({"particles": {"interpolation": 0}})", "$.particles.interpolation", "an integer"},
    {"InterpolationNonInteger", R"({"particles": {"interpolation": 1.5}})", "$.particles.interpolation", "an integer"},
    {"MassZero", R"({"particles": {"mass": 0}})", "$.particles.mass", "positive"},
    {"ConstraintLengthZero", R"({"particles": {"constraintLength": 0}})", "$.particles.constraintLength", "positive"},
    {"ConstraintModeUnknown", R"({"particles": {"constraintMode": "rigid"}})", "$.particles.constraintMode", "\"pbd\""},
    {"ModelUnknown", R"({"particles": {"model": "rigid"}})", "$.particles.model", "\"blade\""},
    {"ModelAndConstraintMode", R"({"particles": {"model": "pbd", "constraintMode": "pbd"}})",
     "$.particles.constraintMode", "not both"},
    {"ConstraintModeBlade", R"({"particles": {"constraintMode": "blade"}})", "$.particles.constraintMode", "\"pbd\""},
    {"BladeBlockWithoutModel", R"({"particles": {"blade": {"frequency": 1}}})", "$.particles.blade",
     "\"model\": \"blade\""},
    {"BladeFrequencyZero", R"({"particles": {"model": "blade", "blade": {"frequency": 0}}})",
     "$.particles.blade.frequency", "positive"},
    {"BladeFrequencyHuge", R"({"particles": {"model": "blade", "blade": {"frequency": 2000}}})",
     "$.particles.blade.frequency", "1000 Hz"},
    {"BladeDampingRatioNegative", R"({"particles": {"model": "blade", "blade": {"dampingRatio": -0.1}}})",
     "$.particles.blade.dampingRatio", ""},
    {"BladeTrampleTooLong", R"({"particles": {"model": "blade", "blade": {"trampleSeconds": 4000}}})",
     "$.particles.blade.trampleSeconds", "3600"},
    {"FrontZero", R"({"wind": {"schedule": [{"force": [1, 0, 0], "duration": 1, "front": [0, 0]}]}})",
     "$.wind.schedule[0].front", "not [0, 0]"},
    {"FrontThreeComponents", R"({"wind": {"schedule": [{"force": [1, 0, 0], "duration": 1, "front": [1, 0, 0]}]}})",
     "$.wind.schedule[0].front", ""},
    {"FrontHuge", R"({"wind": {"schedule": [{"force": [1, 0, 0], "duration": 1, "front": [1e7, 1]}]}})",
     "$.wind.schedule[0].front", "1e6"},
    {"BladeUnknownKey", R"({"particles": {"model": "blade", "blade": {"stiffness": 3}}})", "$.particles.blade", "",
     true},
    {"TiltDropDecreasing", R"({"particles": {"tiltDrop": [0.3, 0.2, 0.4]}})", "$.particles.tiltDrop[1]", "increasing"},
    {"TiltDropEqual", R"({"particles": {"tiltDrop": [0.2, 0.3, 0.3]}})", "$.particles.tiltDrop[2]", "increasing"},
    {"TiltDropNegative", R"({"particles": {"tiltDrop": [-0.1, 0.3, 0.4]}})", "$.particles.tiltDrop[0]", ""},
    // time step
    {"TimeStepZero", R"({"timeStep": 0})", "$.timeStep", ""},
    {"TimeStepDivisionByZero", R"({"timeStep": "1/0"})", "$.timeStep", "non-zero denominator"},
    {"TimeStepText", R"({"timeStep": "abc"})", "$.timeStep", "a number"},
    {"TimeStepTwoSeconds", R"({"timeStep": 2})", "$.timeStep", "1 s"},
    {"TimeStepTooSmall", R"({"timeStep": "1/200000"})", "$.timeStep", ""},
    {"TimeStepNegative", R"({"timeStep": "-1/60"})", "$.timeStep", ""},
    {"TimeStepDoubleFraction", R"({"timeStep": "1/60/2"})", "$.timeStep", ""},
    // numbers out of range: JSON's 1e400 is infinity, 1e-400 underflows to 0
    {"SpacingOverflowsDouble", R"({"field": {"spacing": 1e400}})", "$.field.spacing", ""},
    {"SpacingNegativeOverflowsDouble", R"({"field": {"spacing": -1e400}})", "$.field.spacing", ""},
    {"TimeStepOverflowsDouble", R"({"timeStep": 1e400})", "$.timeStep", ""},
    {"ForceOverflowsDouble", R"({"wind": {"schedule": [{"force": [0, 1e400, 0], "duration": 1}]}})",
     "$.wind.schedule[0].force[1]", ""},
    {"SpacingUnderflowsDouble", R"({"field": {"spacing": 1e-400}})", "$.field.spacing", ""},
    {"SpacingTooLarge", R"({"field": {"spacing": 1e37}})", "$.field.spacing", ""},
    {"SpacingStringTooLarge", R"({"field": {"spacing": "1e400"}})", "$.field.spacing", ""},
    {"SpacingHugeExponent", R"({"field": {"spacing": "1e99999999999999999999"}})", "$.field.spacing", ""},
    {"TooManySignificantDigits", R"({"field": {"spacing": 0.1234567890123456789012345678901}})", "$.field.spacing",
     "significant digits"},
    {"TooManyDigitsInteger", R"({"wind": {"travelSpeed": 1234567890123456789012345678901234567890}})",
     "$.wind.travelSpeed", ""},
    {"TooManyDigitsInFraction", R"({"timeStep": "1/6000000000000000000000000000000000000000"})", "$.timeStep", ""},
    // scalar and seed
    {"ScalarFx64", R"({"scalar": "fx64"})", "$.scalar", "\"fx16\""},
    {"ScalarUpperCase", R"({"scalar": "FX32"})", "$.scalar", ""},
    {"SeedNegative", R"({"seed": -1})", "$.seed", "an integer"},
    {"SeedFraction", R"({"seed": 1.5})", "$.seed", "an integer"},
    {"SeedString", R"({"seed": "1"})", "$.seed", "an integer"},
    {"SeedAbove64Bits", R"({"seed": 18446744073709551616})", "$.seed", "an integer"},
    // wind
    {"TravelUnknown", R"({"wind": {"travel": "backward"}})", "$.wind.travel", "\"forward\""},
    {"TravelSpeedZero", R"({"wind": {"travelSpeed": 0}})", "$.wind.travelSpeed", "positive"},
    {"ScheduleNotArray", R"({"wind": {"schedule": {"force": [0, 0, 0], "duration": 1}}})", "$.wind.schedule",
     "an array"},
    {"ScheduleString", R"({"wind": {"schedule": "thesis"}})", "$.wind.schedule", "an array"},
    {"ScheduleTooLong", "{\"wind\": {\"schedule\": " + manyGusts(1025) + "}}", "$.wind.schedule", "1024"},
    {"GustNotObject", R"({"wind": {"schedule": [5]}})", "$.wind.schedule[0]", "an object"},
    {"GustWithoutDuration", R"({"wind": {"schedule": [{"force": [0, 1, 0], "duration": 1}, {"force": [0, 1, 0]}]}})",
     "$.wind.schedule[1].duration", "missing"},
    {"GustWithoutForce", R"({"wind": {"schedule": [{"duration": 1}]}})", "$.wind.schedule[0].force", "missing"},
    {"GustDurationZero", R"({"wind": {"schedule": [{"force": [0, 1, 0], "duration": 0}]}})",
     "$.wind.schedule[0].duration", "positive"},
    {"GustDurationNegative",
     R"({"wind": {"schedule": [{"force": [0, 1, 0], "duration": 1}, {"force": [0, 1, 0], "duration": -2}]}})",
     "$.wind.schedule[1].duration", "positive"},
    // terrain
    {"TerrainTypeUnknown", R"({"terrain": {"type": "mountain"}})", "$.terrain.type", "\"heightmap\""},
    {"HeightmapWithoutFile", R"({"terrain": {"type": "heightmap"}})", "$.terrain.file", "missing"},
    {"HeightmapWithHeight", R"({"terrain": {"type": "heightmap", "file": "gray4x3.png", "height": 1}})",
     "$.terrain.height", ""},
    {"HeightmapCellSizeZero", R"({"terrain": {"type": "heightmap", "file": "gray4x3.png", "cellSize": 0}})",
     "$.terrain.cellSize", "positive"},
    {"HeightmapMaxHeightNegative", R"({"terrain": {"type": "heightmap", "file": "gray4x3.png", "maxHeight": -1}})",
     "$.terrain.maxHeight", ""},
    {"HeightmapCenterWrongLength", R"({"terrain": {"type": "heightmap", "file": "gray4x3.png", "center": [1]}})",
     "$.terrain.center", "an array of 2 numbers"},
    {"FlatWithFile", R"({"terrain": {"type": "flat", "file": "gray4x3.png"}})", "$.terrain.file", "heightmap"},
    {"DefaultFlatWithFile", R"({"terrain": {"file": "gray4x3.png"}})", "$.terrain.file", "heightmap"},
    {"FlatWithCellSize", R"({"terrain": {"type": "flat", "cellSize": 1}})", "$.terrain.cellSize", ""},
    {"FlatWithMaxHeight", R"({"terrain": {"maxHeight": 1}})", "$.terrain.maxHeight", ""},
};
INSTANTIATE_TEST_SUITE_P(ScenarioValues, ScenarioParseError, testing::ValuesIn(kValueCases), caseName);

const std::vector<BadCase> kHeightmapFileCases = {
    {"FileMissing", heightmapTerrain("missing.png"), "$.terrain.file", "missing.png"},
    {"NotAPng", heightmapTerrain("text.png"), "$.terrain.file", "PNG"},
    {"EmptyFile", heightmapTerrain("empty.png"), "$.terrain.file", "PNG"},
    {"SixteenBit", heightmapTerrain("sixteen.png"), "$.terrain.file", "16-bit"},
    {"Rgb", heightmapTerrain("rgb.png"), "$.terrain.file", "8-bit grayscale"},
    {"GrayAlpha", heightmapTerrain("grayalpha.png"), "$.terrain.file", "8-bit grayscale"},
    {"OnePixel", heightmapTerrain("one.png"), "$.terrain.file", "1x1"},
    {"OneSampleWide", heightmapTerrain("thin.png"), "$.terrain.file", "1x5"},
    {"TruncatedAfterHeader", heightmapTerrain("truncated.png"), "$.terrain.file", "truncated.png"},
    {"CorruptImageData", heightmapTerrain("corrupt.png"), "$.terrain.file", "corrupt.png"},
    // A control character in a file name is refused (escaped in the one-line message).
    {"FileNameWithNewline", heightmapTerrain("a\\nb.png"), "$.terrain.file", "a file name without control characters"},
};
INSTANTIATE_TEST_SUITE_P(ScenarioHeightmapFile, ScenarioParseError, testing::ValuesIn(kHeightmapFileCases), caseName);

TEST(ScenarioParse, NoReaderMeansHeightmapCannotBeRead) {
  EXPECT_TRUE(throwsScenarioError([] { parseScenario(heightmapTerrain("gray4x3.png"), kFile, {}); }, "$.terrain.file"));
}

TEST(ScenarioParse, ReaderErrorTextIsInTheMessage) {
  auto reader = [](const std::string&, std::vector<uint8_t>*, std::string* error) {
    *error = "a readable file, 'h.png': Permission denied";
    return false;
  };
  EXPECT_TRUE(throwsScenarioError([&] { parseScenario(heightmapTerrain("h.png"), kFile, reader); }, "$.terrain.file",
                                  "Permission denied"));
}

// ---- accepted boundaries (the rejections above are not over-eager) ----------------------------

TEST(ScenarioParse, AcceptsBoundaryValues) {
  const Scenario s = parse(R"({
    "seed": 18446744073709551615, "timeStep": 1,
    "field": {"patchesX": 1048576, "patchesZ": 1, "jitter": 0.5, "atlasVariants": 16, "spacing": "1/3"},
    "particles": {"interpolation": 4, "damping": 1, "tiltDrop": [0, 1e-36, 9.99e35]},
    "wind": {"schedule": []}
  })");
  EXPECT_EQ(s.seed, UINT64_MAX);
  EXPECT_EQ(s.timeStep, (Rational{1, 1}));
  EXPECT_EQ(s.field.patchesX, int64_t(1) << 20);
  EXPECT_EQ(s.field.jitter, (Rational{1, 2}));
  EXPECT_EQ(s.field.spacing, (Rational{1, 3}));
  EXPECT_EQ(s.particles.interpolation, 4);
  EXPECT_EQ(s.particles.damping, (Rational{1, 1}));
  EXPECT_TRUE(s.wind.schedule.empty());
  EXPECT_EQ(parse(R"({"timeStep": "1/100000"})").timeStep, (Rational{1, 100000}));
  EXPECT_EQ(parse(R"({"bodies": {"islandVelocityIterations": 1}})").bodies.islandVelocityIterations, 1);
  EXPECT_EQ(parse(R"({"bodies": {"islandVelocityIterations": 1000}})").bodies.islandVelocityIterations, 1000);
  EXPECT_EQ(parse("{}").bodies.islandVelocityIterations, 6);
}

TEST(ScenarioParse, NumbersAreExactFromTheirText) {
  const Scenario s = parse(R"({"timeStep": "1/60", "field": {"spacing": "0.25", "jitter": 0.3},
                               "particles": {"damping": 0.97, "mass": 1e-3}})");
  EXPECT_EQ(s.timeStep, (Rational{1, 60}));
  EXPECT_EQ(s.field.spacing, (Rational{1, 4}));
  EXPECT_EQ(s.field.jitter, (Rational{3, 10}));  // not the double nearest 0.3
  EXPECT_EQ(s.particles.damping, (Rational{97, 100}));
  EXPECT_EQ(s.particles.mass, (Rational{1, 1000}));
  // 30 significant digits are allowed.
  EXPECT_NO_THROW(parse(R"({"field": {"spacing": 0.123456789012345678901234567890}})"));
}

TEST(ScenarioParse, HeightmapFromReader) {
  const Scenario s = parse(R"({"terrain": {"type": "heightmap", "file": "gray4x3.png", "cellSize": 0.5,
                                           "maxHeight": 6, "center": [1, -1]}})");
  EXPECT_FALSE(s.terrain.flat);
  EXPECT_EQ(s.terrain.heightmapPath, "gray4x3.png");
  EXPECT_EQ(s.terrain.heightmap.width, 4);
  EXPECT_EQ(s.terrain.heightmap.height, 3);
  ASSERT_EQ(s.terrain.heightmap.samples.size(), 12u);
  for (size_t i = 0; i < 12; ++i) EXPECT_EQ(s.terrain.heightmap.samples[i], uint8_t(i * 37 % 256)) << i;
  EXPECT_EQ(s.terrain.cellSize, (Rational{1, 2}));
  for (ScalarKind k : {ScalarKind::Fx32, ScalarKind::Fx16, ScalarKind::Float, ScalarKind::Double})
    EXPECT_NO_THROW(validateForScalar(s, k, 0)) << scalarName(k);
}

// ---- scalar range, resolution, gust length and memory ----------------------------------------

const ScalarKind kAllScalars[] = {ScalarKind::Fx32, ScalarKind::Fx16, ScalarKind::Float, ScalarKind::Double};

struct ScalarCase {
  std::string name;
  std::string text;
  std::string path;                    ///< the path every rejecting scalar must name
  std::vector<ScalarKind> rejectedBy;  ///< the others must accept it
  bool namesScalar = true;             ///< the message names the rejecting scalar
};
void PrintTo(const ScalarCase& c, std::ostream* os) { *os << c.name << ": " << c.text.substr(0, 200); }
std::string scalarCaseName(const testing::TestParamInfo<ScalarCase>& info) { return info.param.name; }

class ScenarioScalarRange : public testing::TestWithParam<ScalarCase> {};

TEST_P(ScenarioScalarRange, RejectedExactlyByScalarsThatCannotHoldIt) {
  const ScalarCase& c = GetParam();
  Scenario s;
  ASSERT_NO_THROW(s = parse(c.text)) << "the scenario itself must parse";
  for (ScalarKind k : kAllScalars) {
    const bool rejected = std::find(c.rejectedBy.begin(), c.rejectedBy.end(), k) != c.rejectedBy.end();
    if (rejected) {
      EXPECT_TRUE(throwsScenarioError([&] { validateForScalar(s, k, 0); }, c.path, c.namesScalar ? scalarName(k) : ""))
          << "scalar " << scalarName(k);
    } else {
      EXPECT_NO_THROW(validateForScalar(s, k, 0)) << "scalar " << scalarName(k);
    }
  }
}

const std::vector<ScalarCase> kScalarCases = {
    // A blade too stiff for the explicit spring at dt = 1/60 (k dt^2 = 4.4), and one whose upward
    // acceleration outruns its frequency (stiffness (2 pi 0.5)^2 - 50 < 0): no scalar runs them.
    {"BladeTooStiffForTheTimeStep",
     R"({"particles": {"model": "blade", "blade": {"frequency": 20}}})",
     "$.particles.blade.frequency",
     {ScalarKind::Fx32, ScalarKind::Fx16, ScalarKind::Float, ScalarKind::Double},
     false},
    {"BladeLiftOutrunsItsFrequency",
     R"({"particles": {"model": "blade", "acceleration": [0, 50, 0], "blade": {"frequency": 0.5}}})",
     "$.particles.blade.frequency",
     {ScalarKind::Fx32, ScalarKind::Fx16, ScalarKind::Float, ScalarKind::Double},
     false},
    // A gust front so slow that its crossing does not fit 2^40 ticks (0.25 m per 1e-9 m/s / dt).
    {"FrontTooSlow",
     R"({"wind": {"travelSpeed": 1e-9, "schedule": [{"force": [1, 0, 0], "duration": 1, "front": [1, 1]}]}})",
     "$.wind.travelSpeed",
     {ScalarKind::Fx32, ScalarKind::Fx16, ScalarKind::Float, ScalarKind::Double},
     false},
    // A trample time so long that dt / T rounds to zero in fx16 (1.5e-5 resolution) but not fx32.
    {"BladeTrampleDecayRoundsToZero",
     R"({"timeStep": "1/1000", "particles": {"model": "blade", "blade": {"trampleSeconds": 3600}}})",
     "$.particles.blade.trampleSeconds",
     {ScalarKind::Fx16}},
    // A contact frequency fx32 rounds to 0 (2.3e-10 resolution), fx16 too; float and double hold it.
    {"ContactHertzRoundsToZero",
     R"({"bodies": {"contactHertz": 1e-12, "list": [{"name": "b", "shape": {"type": "sphere", "radius": 0.5}}]}})",
     "$.bodies.contactHertz",
     {ScalarKind::Fx32, ScalarKind::Fx16}},
    // 100 patches 1000 m apart reach 51 km from the centre: beyond fx16's 8 km, inside fx32's.
    {"FieldBeyondFx16",
     R"({"field": {"patchesX": 100, "patchesZ": 100, "spacing": 1000}})",
     "$.field.patchesX",
     {ScalarKind::Fx16}},
    {"FieldBeyondFx16AlongZ",
     R"({"field": {"patchesX": 10, "patchesZ": 100, "spacing": 1000}})",
     "$.field.patchesZ",
     {ScalarKind::Fx16}},
    {"FieldBeyondFx32",
     R"({"field": {"patchesX": 1048576, "patchesZ": 1, "spacing": 2000}})",
     "$.field.patchesX",
     {ScalarKind::Fx32, ScalarKind::Fx16}},
    {"SpacingRoundsToZeroInFx16", R"({"field": {"spacing": 1e-6}})", "$.field.spacing", {ScalarKind::Fx16}},
    {"ConstraintLengthRoundsToZeroInFx16",
     R"({"particles": {"constraintLength": 1e-6}})",
     "$.particles.constraintLength",
     {ScalarKind::Fx16}},
    {"TravelSpeedRoundsToZeroInFx16", R"({"wind": {"travelSpeed": 1e-6}})", "$.wind.travelSpeed", {ScalarKind::Fx16}},
    {"PerTickDampingRoundsToZeroInFx16",
     R"({"timeStep": 1, "particles": {"damping": 1e-6}})",
     "$.particles.damping",
     {ScalarKind::Fx16}},
    {"FlatHeightBeyondFx16", R"({"terrain": {"height": 10000}})", "$.terrain.height", {ScalarKind::Fx16}},
    {"ForceBeyondFx16",
     R"({"wind": {"schedule": [{"force": [0, 10000, 0], "duration": 1}]}})",
     "$.wind.schedule[0].force[1]",
     {ScalarKind::Fx16}},
    {"ForceBeyondFx32",
     R"({"wind": {"schedule": [{"force": [0, 0, 0], "duration": 1}, {"force": [1e10, 0, 0], "duration": 1}]}})",
     "$.wind.schedule[1].force[0]",
     {ScalarKind::Fx32, ScalarKind::Fx16}},
    {"HeightmapMaxHeightBeyondFx16",
     R"({"terrain": {"type": "heightmap", "file": "gray4x3.png", "maxHeight": 10000}})",
     "$.terrain.maxHeight",
     {ScalarKind::Fx16}},
    {"HeightmapCellSizeBeyondFx16",
     R"({"terrain": {"type": "heightmap", "file": "gray4x3.png", "cellSize": 10000}})",
     "$.terrain.cellSize",
     {ScalarKind::Fx16}},
    // Gusts shorter than one tick (1/60 s) cannot be scheduled, for any scalar.
    {"GustShorterThanOneTick",
     R"({"wind": {"schedule": [{"force": [0, 1, 0], "duration": 0.001}]}})",
     "$.wind.schedule[0].duration",
     {ScalarKind::Fx32, ScalarKind::Fx16, ScalarKind::Float, ScalarKind::Double},
     false},
    // 0.01 s is 0.6 of a 1/60 s tick: shorter than one time step, even though it rounds to one tick.
    {"GustOfSixTenthsOfATick",
     R"({"wind": {"schedule": [{"force": [0, 1, 0], "duration": 0.01}]}})",
     "$.wind.schedule[0].duration",
     {ScalarKind::Fx32, ScalarKind::Fx16, ScalarKind::Float, ScalarKind::Double},
     false},
    {"ThirdGustShorterThanOneTick",
     R"({"timeStep": 0.5, "wind": {"schedule": [{"force": [0, 1, 0], "duration": 1},
                                                {"force": [0, 0, 0], "duration": 1},
                                                {"force": [0, 1, 0], "duration": 0.2}]}})",
     "$.wind.schedule[2].duration",
     {ScalarKind::Fx32, ScalarKind::Fx16, ScalarKind::Float, ScalarKind::Double},
     false},
    {"NothingWrong", R"({"field": {"patchesX": 10, "patchesZ": 10, "spacing": 100}})", "", {}},
};
INSTANTIATE_TEST_SUITE_P(ScenarioScalar, ScenarioScalarRange, testing::ValuesIn(kScalarCases), scalarCaseName);

TEST(ScenarioMemory, SmallLimitRejectsTheField) {
  const Scenario s = parse("{}");
  for (ScalarKind k : kAllScalars) {
    EXPECT_TRUE(throwsScenarioError([&] { validateForScalar(s, k, 1024); }, "$.field", "memory")) << scalarName(k);
    EXPECT_NO_THROW(validateForScalar(s, k, 0)) << "0 = unlimited, " << scalarName(k);
  }
}

TEST(ScenarioMemory, LimitIsInclusive) {
  const Scenario s = parse("{}");
  for (ScalarKind k : kAllScalars) {
    const uint64_t need = estimateWorldBytes(s, k);
    ASSERT_GT(need, 22801u) << scalarName(k);
    EXPECT_NO_THROW(validateForScalar(s, k, need)) << scalarName(k);
    EXPECT_TRUE(throwsScenarioError([&] { validateForScalar(s, k, need - 1); }, "$.field")) << scalarName(k);
  }
}

TEST(ScenarioMemory, LargestFieldIsRejectedNotAllocated) {
  // 2^20 x 2^20 patches: tens of TB. Checked by arithmetic before anything is allocated.
  const Scenario s = parse(R"({"field": {"patchesX": 1048576, "patchesZ": 1048576, "spacing": 0.001}})");
  EXPECT_TRUE(throwsScenarioError([&] { validateForScalar(s, ScalarKind::Fx32, uint64_t(64) << 30); }, "$.field"));
  EXPECT_TRUE(throwsScenarioError([&] { makeWorld(s, 1, uint64_t(64) << 30); }, "$.field"));
}

// ---- makeWorld: the whole chain ------------------------------------------------------------

TEST(ScenarioMakeWorld, RejectsWhatValidateRejects) {
  Scenario s = parse(R"({"field": {"patchesX": 100, "patchesZ": 100, "spacing": 1000}})");
  s.scalar = ScalarKind::Fx16;
  EXPECT_TRUE(throwsScenarioError([&] { makeWorld(s, 1, 0); }, "$.field.patchesX", "fx16"));
  s.scalar = ScalarKind::Fx32;
  EXPECT_NO_THROW(makeWorld(s, 1, 0));

  Scenario small = parse(R"({"field": {"patchesX": 4, "patchesZ": 4}})");
  EXPECT_TRUE(throwsScenarioError([&] { makeWorld(small, 1, 64); }, "$.field", "memory"));
  EXPECT_NO_THROW(makeWorld(small, 1, 0));

  Scenario shortGust = parse(R"({"field": {"patchesX": 4, "patchesZ": 4},
                                "wind": {"schedule": [{"force": [0, 1, 0], "duration": 0.001}]}})");
  EXPECT_TRUE(throwsScenarioError([&] { makeWorld(shortGust, 1, 0); }, "$.wind.schedule[0].duration"));
}

// Values the world converts to the scalar beyond the field geometry (velocities, accelerations,
// thresholds, force per mass, 1/dt): each must be rejected with its path rather than converted
// from an empty std::optional (undefined behaviour, a garbage constant).
struct WorldRangeCase {
  std::string name;
  std::string text;
  ScalarKind scalar;
  std::vector<std::string> paths;  ///< any of these path prefixes is acceptable
};
void PrintTo(const WorldRangeCase& c, std::ostream* os) { *os << c.name << ": " << c.text; }
std::string worldCaseName(const testing::TestParamInfo<WorldRangeCase>& info) { return info.param.name; }

class ScenarioWorldRange : public testing::TestWithParam<WorldRangeCase> {};

TEST_P(ScenarioWorldRange, MakeWorldRejectsValuesOutsideTheScalar) {
  const WorldRangeCase& c = GetParam();
  Scenario s;
  ASSERT_NO_THROW(s = parse(c.text));
  s.scalar = c.scalar;
  testing::AssertionResult result = testing::AssertionFailure();
  std::string messages;
  for (const std::string& p : c.paths) {
    result = throwsScenarioError([&] { makeWorld(s, 1, 0); }, p, "", true);
    if (result) break;
    messages += std::string("\n  ") + result.message();
  }
  EXPECT_TRUE(result) << "scalar " << scalarName(c.scalar) << messages;
}

const std::vector<WorldRangeCase> kWorldRangeCases = {
    {"AccelerationBeyondFx32",
     R"({"field": {"patchesX": 4, "patchesZ": 4}, "particles": {"acceleration": [0, 1e20, 0]}})",
     ScalarKind::Fx32,
     {"$.particles.acceleration"}},
    {"AccelerationBeyondFx16",
     R"({"field": {"patchesX": 4, "patchesZ": 4}, "particles": {"acceleration": [0, 40000, 0]}})",
     ScalarKind::Fx16,
     {"$.particles.acceleration"}},
    {"InitialVelocityBeyondFx32",
     R"({"field": {"patchesX": 4, "patchesZ": 4}, "particles": {"initialVelocity": [1e20, 0, 0]}})",
     ScalarKind::Fx32,
     {"$.particles.initialVelocity"}},
    {"TiltDropBeyondFx32",
     R"({"field": {"patchesX": 4, "patchesZ": 4}, "particles": {"tiltDrop": [0.2, 0.3, 1e20]}})",
     ScalarKind::Fx32,
     {"$.particles.tiltDrop"}},
    {"ForcePerMassBeyondFx32",
     R"({"field": {"patchesX": 4, "patchesZ": 4}, "particles": {"mass": 1e-20}})",
     ScalarKind::Fx32,
     {"$.particles.mass", "$.wind.schedule["}},
    // 1/dt = 50000 does not fit Q16.16 (max 32767.99).
    {"InverseTimeStepBeyondFx16",
     R"({"field": {"patchesX": 4, "patchesZ": 4}, "timeStep": "1/50000"})",
     ScalarKind::Fx16,
     {"$.timeStep"}},
};
INSTANTIATE_TEST_SUITE_P(ScenarioWorld, ScenarioWorldRange, testing::ValuesIn(kWorldRangeCases), worldCaseName);

// ---- 30 significant digits: exact arithmetic must not overflow silently ------------------------
//
// Scenario numbers may have up to 30 significant digits, so products and differences of two of
// them need up to 200 bits. Each case must either build a world with the right values or be
// rejected with a path it involves; never a crash (each runs in a child process) or a world
// built from an overflowed intermediate.

constexpr const char* k30a = "0.123456789012345678901234567891";
constexpr const char* k30b = "0.987654321098765432109876543211";

bool near(double got, double want) { return std::fabs(got - want) <= 1e-6 * std::max(1.0, std::fabs(want)); }
std::string mismatch(const char* what, double got, double want) {
  return near(got, want) ? std::string()
                         : std::string(what) + " is " + std::to_string(got) + ", expected " + std::to_string(want);
}
double fx(Fx32 v) { return ScalarTraits<Fx32>::toDouble(v); }

struct LongCase {
  std::string name;
  std::string text;
  std::vector<std::string> paths;  ///< a rejection must name one of these (prefixes)
  /// Checks the built world; returns what is wrong, "" when right.
  std::function<std::string(const World<Fx32>&)> check;
};
void PrintTo(const LongCase& c, std::ostream* os) { *os << c.name << ": " << c.text; }
std::string longCaseName(const testing::TestParamInfo<LongCase>& info) { return info.param.name; }

[[noreturn]] void buildLongCase(const LongCase& c) {
  Scenario s;
  try {
    s = parse(c.text);
    validateForScalar(s, ScalarKind::Fx32, 0);
  } catch (const ScenarioError& e) {
    const std::string what = e.what();
    bool named = false;
    for (const std::string& p : c.paths) named = named || e.path().rfind(p, 0) == 0;
    std::fprintf(stderr, "rejected: %s\n", what.c_str());
    if (!named) std::fprintf(stderr, "the path is none of those the case involves\n");
    std::_Exit(named && what.find('\n') == std::string::npos ? 0 : 1);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "threw a non-ScenarioError: %s\n", e.what());
    std::_Exit(1);
  }
  World<Fx32> world(s, 1);
  const std::string wrong = c.check ? c.check(world) : std::string();
  for (int t = 0; t < 3; ++t) world.step(TickInput{});
  std::fprintf(stderr, "accepted; %s\n", wrong.empty() ? "values right" : wrong.c_str());
  std::_Exit(wrong.empty() ? 0 : 1);
}

class ScenarioLongDecimalsDeathTest : public testing::TestWithParam<LongCase> {};

TEST_P(ScenarioLongDecimalsDeathTest, RightValuesOrOneLineRejectionNeverACrash) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(buildLongCase(GetParam()), testing::ExitedWithCode(0), "");
}

/// The same checks for two sets of numbers: short decimals (a control: the checks themselves are
/// right) and 30-digit decimals (the documented maximum).
struct Decimals {
  std::string tag, a, b, jitter, dt, speed;
};
std::vector<LongCase> longCases(const Decimals& n) {
  const double a = std::stod(n.a), b = std::stod(n.b), jitter = std::stod(n.jitter), dt = std::stod(n.dt),
               speed = std::stod(n.speed);
  const std::string small = R"("field": {"patchesX": 4, "patchesZ": 4)";
  return {
      {n.tag + "JitterTimesSpacing",
       "{" + small + R"(, "spacing": )" + n.a + R"(, "jitter": )" + n.jitter + "}}",
       {"$.field.spacing", "$.field.jitter"},
       [=](const World<Fx32>& w) { return mismatch("jitterAmplitude", fx(w.lattice().jitterAmplitude), a * jitter); }},
      {n.tag + "CenterMinusHalfTheField",
       "{" + small + R"(, "spacing": )" + n.a + R"(, "center": [)" + n.b + ", 0]}}",
       {"$.field.spacing", "$.field.center"},
       [=](const World<Fx32>& w) { return mismatch("originX", fx(w.lattice().originX), b - 1.5 * a); }},
      {n.tag + "Damping",
       "{" + small + R"(}, "particles": {"damping": )" + n.b + "}}",
       {"$.particles.damping"},
       [=](const World<Fx32>& w) {
         return mismatch("dampingPerTick", fx(w.particleConstants().dampingPerTick), std::pow(b, 1.0 / 60));
       }},
      {n.tag + "TimeStep",
       "{" + small + R"(}, "timeStep": ")" + n.dt + "\"}",
       {"$.timeStep"},
       [=](const World<Fx32>& w) {
         const std::string m = mismatch("dt", fx(w.particleConstants().dt), dt);
         return !m.empty() ? m
                           : mismatch("dampingPerTick", fx(w.particleConstants().dampingPerTick), std::pow(0.97, dt));
       }},
      {n.tag + "ForcePerMass",
       "{" + small + R"(}, "particles": {"mass": )" + n.b + R"(}, "wind": {"schedule": [{"force": [0, )" + n.a +
           R"(, 0], "duration": 1}]}})",
       {"$.particles.mass", "$.wind.schedule[0].force"},
       nullptr},
      {n.tag + "TravelSpeedTimesTimeStep",
       "{" + small + R"(}, "timeStep": ")" + n.dt + R"(", "particles": {"damping": 1}, "wind": {"travelSpeed": )" +
           n.speed + "}}",
       {"$.timeStep", "$.wind.travelSpeed"},
       [=](const World<Fx32>& w) {
         const double ticksPerRow = 0.25 / (speed * dt);
         const auto& d = w.wind().delayFromFirstRow;
         if (d.size() < 4) return std::string("fewer than 4 wind rows");
         for (size_t r = 1; r < 4; ++r)
           if (d[r] != std::llround(double(r) * ticksPerRow))
             return "delayFromFirstRow[" + std::to_string(r) + "] is " + std::to_string(d[r]) + ", expected " +
                    std::to_string(std::llround(double(r) * ticksPerRow));
         return std::string();
       }},
      {n.tag + "HeightmapCenterMinusHalfTheMap",
       R"({"terrain": {"type": "heightmap", "file": "gray4x3.png", "maxHeight": 6, "cellSize": )" + n.a +
           R"(, "center": [)" + n.b + ", 0]}}",
       {"$.terrain.cellSize", "$.terrain.center"},
       [=](const World<Fx32>& w) {
         // Samples (1, 1) and (2, 1) of the 4x3 map hold 185 and 222 (i * 37 % 256).
         for (int ix : {1, 2}) {
           const Fx32 x = Fx32::fromRaw(int64_t(std::llround((b + (ix - 1.5) * a) * 4294967296.0)));
           const double got = fx(w.terrain().heightAt(x, Fx32(0))), want = 6.0 * (ix == 1 ? 185 : 222) / 255;
           if (std::fabs(got - want) > 1e-3)
             return "height at sample (" + std::to_string(ix) + ", 1) is " + std::to_string(got) + ", expected " +
                    std::to_string(want);
         }
         return std::string();
       }},
  };
}
std::vector<LongCase> allLongCases() {
  std::vector<LongCase> all = longCases({"Short", "0.125", "0.75", "0.5", "0.02", "7.5"});
  for (LongCase& c : longCases({"Digits30", k30a, k30b, "0.499999999999999999999999999999",
                                "0.0166666666666666666666666666667", "7.12345678901234567890123456789"}))
    all.push_back(std::move(c));
  return all;
}
INSTANTIATE_TEST_SUITE_P(ScenarioLong, ScenarioLongDecimalsDeathTest, testing::ValuesIn(allLongCases()), longCaseName);

// ---- the shipped scenarios ------------------------------------------------------------------

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(ScenarioFiles, EveryShippedScenarioLoadsAndFitsEveryScalar) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(test::sourcePath("scenarios")))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 3u);
  for (const auto& f : files) {
    SCOPED_TRACE(f.string());
    Scenario s;
    try {
      s = loadScenarioFile(f.string());
    } catch (const std::exception& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    EXPECT_EQ(s.name, f.stem().string());
    EXPECT_EQ(s.sourceName, f.string());
    for (ScalarKind k : kAllScalars) {
      try {
        validateForScalar(s, k, 0);
      } catch (const std::exception& e) {
        ADD_FAILURE() << scalarName(k) << ": " << e.what();
      }
    }
  }
}

TEST(ScenarioFiles, BuiltInTextIsThesisMeadowFileByteForByte) {
  const std::string file = readText(test::sourcePath("scenarios/thesis-meadow.json"));
  ASSERT_FALSE(file.empty());
  EXPECT_EQ(defaultScenarioText(), file);
}

TEST(ScenarioFiles, EmptyPathGivesTheBuiltInMeadow) {
  const Scenario s = loadScenarioFile("");
  EXPECT_EQ(s.name, "thesis-meadow");
  EXPECT_EQ(s.field.patchesX, 151);
  EXPECT_EQ(s.field.patchesZ, 151);
  EXPECT_EQ(s.text, defaultScenarioText());
}

TEST(ScenarioFiles, MissingFileNamesTheFile) {
  const std::string path = test::sourcePath("scenarios/no-such-scenario.json");
  try {
    loadScenarioFile(path);
    ADD_FAILURE() << "no error";
  } catch (const ScenarioError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_NE(what.find("expected"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(ScenarioFiles, DirectoryIsNotAScenario) {
  const std::string path = test::sourcePath("scenarios");
  try {
    loadScenarioFile(path);
    ADD_FAILURE() << "no error";
  } catch (const ScenarioError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace sg
