// Hostile scenario and input-track values (issue 14): nesting bombs, unbounded echoes, numbers
// that used to read silently wrong, values no scalar can hold, non-unit quaternions, heightmap
// memory bombs, and the JSON paths and file names of the errors. Each test fails without its fix
// (a crash, a thrown std::out_of_range, a wrong path or a value silently accepted).
#include <gtest/gtest.h>
#include <stb_image_write.h>

#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <typeinfo>
#include <vector>

#include "sim/scenario/json_bounds.h"
#include "sim/world/input_conversion.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {

constexpr const char* kFile = "bad.json";

std::vector<uint8_t> flatPng(int w, int h) {
  std::vector<uint8_t> pixels(size_t(w) * size_t(h), 0);
  std::vector<uint8_t> out;
  stbi_write_png_to_func(
      [](void* ctx, void* data, int size) {
        auto* o = static_cast<std::vector<uint8_t>*>(ctx);
        const auto* p = static_cast<const uint8_t*>(data);
        o->insert(o->end(), p, p + size);
      },
      &out, w, h, 1, pixels.data(), w);
  return out;
}

/// The first 24 bytes of a PNG whose header claims w x h samples (the rest is missing).
std::vector<uint8_t> pngHeaderOnly(uint32_t w, uint32_t h) {
  std::vector<uint8_t> b = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R'};
  for (uint32_t v : {w, h})
    for (int s = 24; s >= 0; s -= 8) b.push_back(uint8_t(v >> s));
  return b;
}

bool reader(const std::string& path, std::vector<uint8_t>* bytes, std::string* error) {
  static const std::map<std::string, std::vector<uint8_t>> files = [] {
    std::map<std::string, std::vector<uint8_t>> f;
    f["wide.png"] = flatPng(4097, 2);
    f["big.png"] = flatPng(2048, 2048);
    f["hill.png"] = flatPng(8, 8);
    f["claims16384.png"] = pngHeaderOnly(16384, 16384);
    return f;
  }();
  auto it = files.find(path);
  if (it == files.end()) {
    *error = "an existing file";
    return false;
  }
  *bytes = it->second;
  return true;
}

Scenario parse(const std::string& text) { return parseScenario(text, kFile, reader); }

/// f throws a one-line ScenarioError for `file` whose path() starts with `path` and whose
/// message contains `extra` and is at most `maxLength` characters.
testing::AssertionResult throwsError(const std::function<void()>& f, const std::string& path,
                                     const std::string& extra = "", const std::string& file = kFile,
                                     size_t maxLength = 400) {
  try {
    f();
  } catch (const ScenarioError& e) {
    const std::string what = e.what();
    auto fail = [&]() { return testing::AssertionFailure() << "message: [" << what.substr(0, 500) << "]\n  "; };
    if (e.file() != file) return fail() << "file() is '" << e.file() << "'";
    if (what.find_first_of("\n\r") != std::string::npos) return fail() << "is not one line";
    if (e.path().rfind(path, 0) != 0) return fail() << "path() is '" << e.path() << "', expected '" << path << "...'";
    if (what.find("expected") == std::string::npos) return fail() << "does not say what was expected";
    if (!extra.empty() && what.find(extra) == std::string::npos) return fail() << "does not contain '" << extra << "'";
    if (what.size() > maxLength) return fail() << "is " << what.size() << " characters long";
    return testing::AssertionSuccess();
  } catch (const std::exception& e) {
    return testing::AssertionFailure() << "threw " << typeid(e).name() << ": " << std::string(e.what()).substr(0, 300);
  }
  return testing::AssertionFailure() << "accepted";
}

std::string deep(int depth, const std::string& inner = "") {
  return std::string(size_t(depth), '[') + inner + std::string(size_t(depth), ']');
}
const char* kSphere = R"({"name": "ball", "shape": {"type": "sphere", "radius": 0.5}})";
std::string withBody(const std::string& extra) {
  return std::string(R"({"field": {"patchesX": 4, "patchesZ": 4}, "bodies": {"list": [)") + kSphere + "]}" + extra +
         "}";
}

// ---- 1. nesting depth and bounded echoes ------------------------------------------------------

TEST(JsonBounds, FindExcessNestingCountsOnlyBracketsOutsideStrings) {
  EXPECT_EQ(findExcessNesting("[[]]", 1), std::optional<size_t>(1));
  EXPECT_EQ(findExcessNesting("[[]]", 2), std::nullopt);
  EXPECT_EQ(findExcessNesting(R"({"a": "[[[[\"[[[", "b": [{}]})", 3), std::nullopt);
  EXPECT_EQ(findExcessNesting(R"({"a": "[[[[\"[[[", "b": [{}]})", 2), std::optional<size_t>(25));
  EXPECT_EQ(findExcessNesting(R"({"a": "\\", "b": [[1]]})", 2), std::optional<size_t>(18));
  EXPECT_EQ(findExcessNesting(deep(kMaxJsonDepth)), std::nullopt);
  EXPECT_EQ(findExcessNesting(deep(kMaxJsonDepth + 1)), std::optional<size_t>(kMaxJsonDepth));
}

TEST(JsonBounds, EchoOfAHugeDeepValueIsShortAndOneLine) {
  // A DOM 100000 deep (json::parse builds it without recursion): dump() would overflow the stack.
  const nlohmann::json v = nlohmann::json::parse(deep(100000));
  EXPECT_EQ(jsonDepth(v), kMaxJsonDepth + 1);
  const std::string e = echoValue(v);
  EXPECT_LE(e.size(), kEchoChars + 3);
  EXPECT_EQ(e.substr(0, 3), "[[[");
  const std::string s = echoValue(nlohmann::json(std::string(100000, 'x') + "\n"));
  EXPECT_LE(s.size(), kEchoChars + 3);
  EXPECT_EQ(echoValue(nlohmann::json("a\nb\x01")), "\"a\\nb\\x01\"");
  EXPECT_EQ(echoText("tab\there"), "tab\\there");
  EXPECT_EQ(echoValue(nlohmann::json::parse(R"({"a": [1, 2.5, null, true]})")), R"({"a":[1,2.5,null,true]})");
  EXPECT_EQ(jsonDepth(nlohmann::json::parse("[1, [2, {\"a\": []}]]")), 4);
  EXPECT_EQ(jsonDepth(nlohmann::json::parse("7")), 0);
}

TEST(ScenarioNesting, DeepValueWhereANumberIsExpectedIsRejectedNotCrashed) {
  // Echoing this value with json::dump recursed 100000 levels: a stack overflow.
  EXPECT_TRUE(throwsError([] { parse(R"({"field": {"center": )" + deep(100000) + "}}"); }, "$.field.center",
                          "nested at most 64"));
  EXPECT_TRUE(throwsError([] { parse(R"({"bodies": {"list": [{"name": )" + deep(100000) + "}]}}"); },
                          "$.bodies.list[0].name", "byte 91"));
}

TEST(ScenarioNesting, LimitIsSixtyFourLevels) {
  // 63 arrays inside the top-level object: 64 levels, parsed (and rejected for its type only).
  EXPECT_TRUE(throwsError([] { parse(R"({"name": )" + deep(63) + "}"); }, "$.name", "a string"));
  EXPECT_TRUE(throwsError([] { parse(R"({"name": )" + deep(64) + "}"); }, "$.name", "nested at most 64"));
}

TEST(InputTrackNesting, DeepCameraIsRejectedWithItsPath) {
  const Scenario s = parse(withBody(""));
  EXPECT_TRUE(throwsError(
      [&] { parseInputTrack(R"({"format": "simgrass-input-track/1", "camera": )" + deep(100000) + "}", "t.json", s); },
      "$.camera", "nested at most 64", "t.json"));
}

TEST(ScenarioEcho, LongValuesAndKeysAreTruncatedAndEscaped) {
  const std::string longText(100000, 'a');
  EXPECT_TRUE(throwsError([&] { parse(R"({"field": {"center": ")" + longText + R"(\n"}})"); }, "$.field.center",
                          "aaa...", kFile, 300));
  EXPECT_TRUE(throwsError([&] { parse(R"({"field": {")" + longText + R"(": 1}})"); }, "$.field.aaa", "unknown key",
                          kFile, 400));
  // A number's own text (kept for exact parsing) is echoed bounded too.
  EXPECT_TRUE(throwsError([&] { parse(R"({"field": {"spacing": 1.)" + std::string(5000, '1') + "}}"); },
                          "$.field.spacing", "significant digits", kFile, 300));
  // A duplicate body name is echoed bounded too.
  const std::string name(100000, 'n');
  EXPECT_TRUE(throwsError(
      [&] {
        parse(R"({"bodies": {"list": [{"name": ")" + name + R"(", "shape": {"type": "sphere", "radius": 1}},
                                      {"name": ")" +
              name + R"(", "shape": {"type": "sphere", "radius": 1}}]}})");
      },
      "$.bodies.list[1].name", "is taken", kFile, 300));
  // A control character in a value never splits the line.
  EXPECT_TRUE(throwsError([&] { parse(R"({"scalar": "fx\u000a32"})"); }, "$.scalar", "fx\\n32"));
}

// ---- 3. numbers: exact or rejected, never silently truncated ----------------------------------

TEST(ScenarioNumbers, ExponentDigitsAreNeverDropped) {
  // 1 followed by 10000 zeros, times 10^-100000, is 10^-90000: the old parser kept 5 exponent
  // digits and read it as 1.
  const std::string tiny = "1" + std::string(10000, '0') + "e-100000";
  EXPECT_TRUE(throwsError([&] { parse(R"({"field": {"spacing": )" + tiny + "}}"); }, "$.field.spacing", "1e-36"));
  EXPECT_TRUE(throwsError([&] { parse(R"({"field": {"spacing": ")" + tiny + R"("}})"); }, "$.field.spacing"));
  // ... and the other way: 10^-100001 * 10^100001 is exactly 1.
  EXPECT_EQ(parse(R"({"field": {"spacing": 0.)" + std::string(100000, '0') + "1e100001}}").field.spacing,
            (Rational{1, 1}));
  std::string why;
  EXPECT_EQ(Rational::parse("1e-0000000000001", &why), (Rational{1, 10}));
  EXPECT_EQ(Rational::parse("25e-000000000000000000000000000000001", &why), (Rational{5, 2}));
  EXPECT_EQ(Rational::parse("1" + std::string(40, '0') + "e-40", &why), (Rational{1, 1}));
  EXPECT_FALSE(Rational::parse("1e100000", &why));
  EXPECT_FALSE(Rational::parse("1e-99999999999999999999999", &why));
}

TEST(ScenarioNumbers, ExactWhetherOrNotTheRawTextIsKept) {
  // Raw number texts are kept only when the double's shortest text is another value; both ways
  // the scenario gets the exact decimal.
  const Scenario s = parse(R"({"field": {"spacing": 0.12345678901234567891, "jitter": 1e-1, "scaleY": 2.50},
                               "particles": {"mass": 12345678901234567891e-19}})");
  EXPECT_EQ(s.field.spacing, (Rational{Int128(12345678901234567891ull), Int128(10000000000000000000ull) * 10}));
  EXPECT_EQ(s.field.jitter, (Rational{1, 10}));
  EXPECT_EQ(s.field.scaleY, (Rational{5, 2}));
  EXPECT_EQ(s.particles.mass, (Rational{Int128(12345678901234567891ull), Int128(10000000000000000000ull)}));
}

// ---- 2. and 4. every value fits the chosen scalar, checked at load with its path ---------------

struct RangeCase {
  std::string name, text, path;
  ScalarKind scalar;
};
void PrintTo(const RangeCase& c, std::ostream* os) { *os << c.name; }

class ScenarioScalarHunt : public testing::TestWithParam<RangeCase> {};

TEST_P(ScenarioScalarHunt, RejectedWithItsPathNotByAThrowingConversion) {
  const RangeCase& c = GetParam();
  Scenario s;
  ASSERT_NO_THROW(s = parse(c.text));
  s.scalar = c.scalar;
  EXPECT_TRUE(throwsError([&] { makeWorld(s, 1, 0); }, c.path, scalarName(c.scalar)));
}

std::vector<RangeCase> huntCases() {
  auto field = [](const std::string& extra) {
    return std::string(R"({"field": {"patchesX": 4, "patchesZ": 4})") + extra + "}";
  };
  auto body = [](const std::string& fields) {
    return std::string(R"({"field": {"patchesX": 4, "patchesZ": 4}, "bodies": {"list": [{"name": "b", "shape": )"
                       R"({"type": "sphere", "radius": 0.5})") +
           fields + "}]}}";
  };
  std::vector<RangeCase> c = {
      // These reached World's toS: std::out_of_range, an abort in the CLI.
      {"MowerCutHeightFx32", field(R"(, "bodies": {"mowerCutHeight": 1e20})"), "$.bodies.mowerCutHeight",
       ScalarKind::Fx32},
      {"MowerCutHeightFx16", field(R"(, "bodies": {"mowerCutHeight": 40000})"), "$.bodies.mowerCutHeight",
       ScalarKind::Fx16},
      {"GrassDragFx16", field(R"(, "bodies": {"grassDrag": 40000})"), "$.bodies.grassDrag", ScalarKind::Fx16},
      {"ContactHertzFx16",
       field(
           R"(, "bodies": {"contactHertz": 40000, "list": [{"name": "b", "shape": {"type": "sphere", "radius": 0.5}}]})"),
       "$.bodies.contactHertz", ScalarKind::Fx16},
      {"MarkingsLengthFx32", field(R"(, "markings": {"length": 1e20})"), "$.markings.length", ScalarKind::Fx32},
      {"MarkingsCenterFx16", field(R"(, "markings": {"center": [40000, 0]})"), "$.markings.center[0]",
       ScalarKind::Fx16},
      {"MarkingsCircleFx16", field(R"(, "markings": {"centerCircleRadius": 1e6})"), "$.markings.centerCircleRadius",
       ScalarKind::Fx16},
      {"LodCenterFx32", field(R"(, "lod": {"mode": "window", "window": [3, 3], "center": [0, 1e20]})"),
       "$.lod.center[1]", ScalarKind::Fx32},
      // Reported as "$.mass" before (the wrong path).
      {"FrictionFx16", body(R"(, "friction": 40000)"), "$.bodies.list[0].friction", ScalarKind::Fx16},
      {"FrictionFx32", body(R"(, "friction": 1e20)"), "$.bodies.list[0].friction", ScalarKind::Fx32},
      // |halfExtents|^2 overflowed Q16.16 in the bounding radius, a fault the constructor dropped.
      {"BoxTooLargeForFx16Norm", R"({"field": {"patchesX": 4, "patchesZ": 4}, "bodies": {"list": [{"name": "b",
        "shape": {"type": "box", "halfExtents": [500, 500, 500]}}]}})",
       "$.bodies.list[0].shape", ScalarKind::Fx16},
      // A compound of one part: the path is the part's, not the shape's.
      {"OnePartCompoundOffsetFx16", R"({"field": {"patchesX": 4, "patchesZ": 4}, "bodies": {"list": [{"name": "b",
        "shape": {"type": "compound", "parts": [{"type": "sphere", "radius": 1, "offset": [0, 9000, 0]}]}}]}})",
       "$.bodies.list[0].shape.parts[0].offset[1]", ScalarKind::Fx16},
      // Scripted values beyond fx16 became 0 in the step (4.).
      {"ScriptTeleportFx16", withBody(R"(, "script": [{"tick": 0, "body": 0, "command": "teleport",
                                   "value": [40000, 0, 0]}])"),
       "$.script[0].value[0]", ScalarKind::Fx16},
      {"ScriptVelocityFx16", withBody(R"(, "script": [{"tick": 0, "body": 0, "command": "addVelocity",
                                   "value": [0, 0, -1e6]}])"),
       "$.script[0].value[2]", ScalarKind::Fx16},
      {"CameraFx16", field(R"(, "camera": [{"tick": 0, "position": [0, 0, 50000]}])"), "$.camera[0].position[2]",
       ScalarKind::Fx16},
  };
  return c;
}
INSTANTIATE_TEST_SUITE_P(Hunt, ScenarioScalarHunt, testing::ValuesIn(huntCases()),
                         [](const testing::TestParamInfo<RangeCase>& i) { return i.param.name; });

TEST(ScenarioScalarHunt, ValuesInRangeStillPass) {
  for (ScalarKind k : {ScalarKind::Fx32, ScalarKind::Fx16, ScalarKind::Float, ScalarKind::Double}) {
    Scenario s = parse(withBody(R"(, "script": [{"tick": 0, "body": 0, "command": "teleport", "value": [8000, 1, 0]}],
                                  "markings": {"length": 30}, "camera": [{"tick": 0, "position": [0, 8000, 0]}])"));
    s.scalar = k;
    EXPECT_NO_THROW(makeWorld(s, 1, 0)) << scalarName(k);
  }
}

TEST(ScenarioPaths, UnsortedScriptNamesTheCommandAsWritten) {
  // The script is sorted by tick; the error must name the command's index in the file ([0]),
  // not its index after sorting ([1]).
  Scenario s = parse(withBody(R"(, "script": [
      {"tick": 9, "body": 0, "command": "teleport", "value": [0, 40000, 0]},
      {"tick": 1, "body": 0, "command": "teleport", "value": [0, 1, 0]}])"));
  s.scalar = ScalarKind::Fx16;
  EXPECT_TRUE(throwsError([&] { validateForScalar(s, s.scalar, 0); }, "$.script[0].value[1]"));
  s.scalar = ScalarKind::Fx32;
  for (ScriptedCommand& c : s.script)
    if (c.source == 0) c.value[1] = Rational{int64_t(1) << 40, 1};  // beyond Q32.32
  EXPECT_TRUE(throwsError([&] { validateForScalar(s, s.scalar, 0); }, "$.script[0].value[1]"));
}

TEST(InputTrackRange, Fx16TeleportAndCameraAreRejectedWithTheirPaths) {
  Scenario s = parse(withBody(""));
  s.scalar = ScalarKind::Fx16;
  const std::string head = R"({"format": "simgrass-input-track/1", )";
  EXPECT_TRUE(throwsError(
      [&] {
        parseInputTrack(head + R"("commands": [{"tick": 5, "body": "ball", "command": "displace", "value": [0, 0, 1]},
                                    {"tick": 2, "body": "ball", "command": "teleport", "value": [0, 0, 33000]}]})",
                        "t.json", s);
      },
      "$.commands[1].value[2]", "fx16", "t.json"));
  EXPECT_TRUE(
      throwsError([&] { parseInputTrack(head + R"("camera": [{"tick": 0, "position": [1e30, 0, 0]}]})", "t.json", s); },
                  "$.camera[0].position[0]", "", "t.json"));
  s.scalar = ScalarKind::Float;  // the Q32.32 limit, named as such
  EXPECT_TRUE(throwsError(
      [&] { parseInputTrack(head + R"("camera": [{"tick": 0, "position": [2147483648, 0, 0]}]})", "t.json", s); },
      "$.camera[0].position[0]", "Q32.32", "t.json"));
  s.scalar = ScalarKind::Fx32;
  EXPECT_NO_THROW(parseInputTrack(
      head + R"("commands": [{"tick": 2, "body": "ball", "command": "teleport", "value": [0, 0, 33000]}]})", "t.json",
      s));
}

TEST(InputConversion, OutOfRangeInputFaultsInsteadOfBecomingZero) {
  takeFixedFaults();
  const int64_t raw = int64_t(40000) << 32;
  const Fx16 v = inputScalar<Fx16>(raw);
  EXPECT_NE(takeFixedFaults(), 0u);
  EXPECT_EQ(v, Fx16::max());
  EXPECT_EQ(inputScalar<Fx16>(-raw), Fx16::min());
  takeFixedFaults();
  EXPECT_EQ(inputScalar<Fx32>(raw), ScalarTraits<Fx32>::fromRational(Rational{40000, 1}).value());
  EXPECT_EQ(takeFixedFaults(), 0u);
}

// ---- 5. orientation quaternions ---------------------------------------------------------------

TEST(ScenarioOrientation, NonUnitAndZeroQuaternionsAreRejected) {
  auto body = [](const std::string& q) {
    return std::string(R"({"bodies": {"list": [{"name": "b", "shape": {"type": "sphere", "radius": 0.5},
                        "orientation": )") +
           q + "}]}}";
  };
  EXPECT_TRUE(throwsError([&] { parse(body("[2, 0, 0, 0]")); }, "$.bodies.list[0].orientation", "unit quaternion"));
  EXPECT_TRUE(throwsError([&] { parse(body("[0, 0, 0, 0]")); }, "$.bodies.list[0].orientation"));
  EXPECT_TRUE(throwsError([&] { parse(body("[1e-30, 0, 0, 0]")); }, "$.bodies.list[0].orientation"));
  EXPECT_TRUE(throwsError([&] { parse(body("[1e30, 0, 0, 0]")); }, "$.bodies.list[0].orientation"));
  EXPECT_NO_THROW(parse(body("[0.7071, 0, 0.7071, 0]")));
  EXPECT_NO_THROW(parse(body("[0.6, 0, 0.8, 0]")));
  EXPECT_NO_THROW(parse(body("[1, 0, 0, 0]")));
}

TEST(ScenarioBodies, TinyPartsAndUnknownShapesAreNamedAtTheirKey) {
  // A 1e-30 m box was reported at the body as "mass properties ... (use fewer digits)"; an unknown
  // shape type listed "sphere" and "box" but not "compound" (found by review).
  auto body = [](const std::string& shape) {
    return R"({"bodies": {"list": [{"name": "b", "shape": )" + shape + "}]}}";
  };
  EXPECT_TRUE(throwsError([&] { parse(body(R"({"type": "box", "halfExtents": ["1e-30", 1, 1]})")); },
                          "$.bodies.list[0].shape.halfExtents[0]", "at least 0.000001 m"));
  EXPECT_TRUE(throwsError([&] { parse(body(R"({"type": "sphere", "radius": 1e-7})")); },
                          "$.bodies.list[0].shape.radius", "at least 0.000001 m"));
  EXPECT_TRUE(throwsError(
      [&] {
        parse(body(R"({"type": "compound", "parts": [{"type": "sphere", "radius": 1e-9, "offset": [0, 0, 0]}]})"));
      },
      "$.bodies.list[0].shape.parts[0].radius", "at least 0.000001 m"));
  EXPECT_TRUE(throwsError([&] { parse(body(R"({"type": "cone", "radius": 1})")); }, "$.bodies.list[0].shape.type",
                          R"(one of "sphere", "box", "compound", got "cone")"));
  EXPECT_NO_THROW(parse(body(R"({"type": "sphere", "radius": 0.000001})")));
}

TEST(ScenarioDerived, AValueWhoseDerivedConstantOverflowsIsNamedAsSuch) {
  // 1e-30 itself is a fine spacing or mass to write; what does not fit is 1/spacing or 1/mass.
  // The message must say so, not call the written value 1e30.
  auto build = [](const char* text) { return [text] { makeWorld(parse(text)); }; };
  EXPECT_TRUE(throwsError(build(R"({"field": {"spacing": "1e-30"}})"), "$.field.spacing",
                          "whose 1/(spacing x interpolation) is within the fx32 range"));
  EXPECT_TRUE(throwsError(build(R"({"particles": {"mass": "1e-35"}})"), "$.particles.mass",
                          "whose 1/mass is within the fx32 range"));
  EXPECT_TRUE(throwsError(build(R"({"particles": {"mass": 6e8}})"), "$.particles.mass",
                          "expected a value within the fx32 range"));
  // A spacing so wide that a gust takes 2^40 ticks to cross the field is reported at the spacing;
  // a gust so slow that it does is reported at the travel speed.
  EXPECT_TRUE(throwsError(build(R"({"scalar": "double", "field": {"spacing": 1e13}})"), "$.field.spacing",
                          "a gust crossing of the field (rows x field.spacing"));
  EXPECT_TRUE(throwsError(build(R"({"scalar": "double", "wind": {"travelSpeed": 1e-12}})"), "$.wind.travelSpeed",
                          "a gust crossing of the field"));
}

TEST(ScenarioDerived, AReachOutOfRangeIsReportedAtItsLargestTerm) {
  // A blade top is terrain height + constraintLength + scaleY: the key named is the one that is
  // out of scale, not always the terrain's.
  auto build = [](const std::string& text) { return [text] { makeWorld(parse(text)); }; };
  EXPECT_TRUE(throwsError(build(R"({"scalar": "double", "particles": {"constraintLength": 1e14}})"),
                          "$.particles.constraintLength", "a blade top"));
  EXPECT_TRUE(
      throwsError(build(R"({"scalar": "double", "field": {"scaleY": 1e14}})"), "$.field.scaleY", "a blade top"));
  EXPECT_TRUE(throwsError(build(R"({"scalar": "double", "terrain": {"type": "flat", "height": 1e14}})"),
                          "$.terrain.height", "a blade top"));
  // A field or heightmap extent: the centre when it is the larger term, else what sets the size.
  EXPECT_TRUE(
      throwsError(build(R"({"scalar": "fx16", "field": {"center": [8191, 0]}})"), "$.field.center[0]", "a field"));
  EXPECT_TRUE(throwsError(build(R"({"scalar": "fx16", "field": {"spacing": 10000}})"), "$.field.spacing", "a field"));
  EXPECT_TRUE(throwsError(build(R"({"scalar": "fx16", "field": {"spacing": 1000}})"), "$.field.patchesX", "a field"));
  EXPECT_TRUE(throwsError(build(R"({"scalar": "fx16", "field": {"patchesX": 200000, "patchesZ": 2}})"),
                          "$.field.patchesX", "a field"));
  EXPECT_TRUE(throwsError(build(R"({"scalar": "fx16", "terrain": {"type": "heightmap", "file": "hill.png",
                                    "center": [8191, 8191]}})"),
                          "$.terrain.center[0]", "a heightmap"));
  EXPECT_TRUE(throwsError(build(R"({"scalar": "fx16", "terrain": {"type": "heightmap", "file": "hill.png",
                                    "cellSize": 5000}})"),
                          "$.terrain.cellSize", "a heightmap"));
}

// ---- 7. heightmap size cap and memory estimate ------------------------------------------------

TEST(ScenarioHeightmap, SideAbove4096IsRejected) {
  EXPECT_TRUE(throwsError([] { parse(R"({"terrain": {"type": "heightmap", "file": "wide.png"}})"); }, "$.terrain.file",
                          "at most 4096 x 4096"));
  // Checked on the PNG header, before decoding allocates 256 MiB.
  EXPECT_TRUE(throwsError([] { parse(R"({"terrain": {"type": "heightmap", "file": "claims16384.png"}})"); },
                          "$.terrain.file", "16384 x 16384"));
}

TEST(ScenarioHeightmap, MemoryEstimateCountsTheTerrain) {
  const Scenario s = parse(R"({"field": {"patchesX": 6, "patchesZ": 6},
                                "terrain": {"type": "heightmap", "file": "big.png", "cellSize": 0.01}})");
  const uint64_t samples = uint64_t(2048) * 2048;
  for (ScalarKind k : {ScalarKind::Fx32, ScalarKind::Fx16, ScalarKind::Float, ScalarKind::Double}) {
    EXPECT_GT(estimateWorldBytes(s, k), samples * 5) << scalarName(k);
    EXPECT_TRUE(throwsError([&] { validateForScalar(s, k, samples); }, "$.terrain.file", "memory")) << scalarName(k);
  }
}

// ---- 6. errors caused in the step name the input; file names stay one line ----------------------

TEST(InputCause, NamesTheLatestCommandByFileAndPath) {
  Scenario s = parse(std::string(R"({"bodies": {"list": [)") + kSphere + "," +
                     R"({"name": "box", "shape": {"type": "box", "halfExtents": [1, 1, 1]}}]}, "script": [
      {"tick": 9, "body": 0, "command": "teleport", "value": [0, 4, 0]},
      {"tick": 1, "body": 0, "command": "addVelocity", "value": [0, 1, 0]},
      {"tick": 9, "body": 1, "command": "displace", "value": [0, 1, 0]},
      {"tick": 7, "body": 1, "command": "impulse", "value": [0, 1, 0]}]})");
  EXPECT_EQ(describeInputCause(s, nullptr, 5, 0),
            "last input: bad.json: $.script[1] (addVelocity to body 0 at tick 1)");
  // A fault named for body 0 after body 1's impulse: fault bits do not say which body overflowed.
  EXPECT_EQ(describeInputCause(s, nullptr, 8, 0), "last input: bad.json: $.script[3] (impulse to body 1 at tick 7)");
  EXPECT_EQ(
      describeInputCause(s, nullptr, 9, 1),
      "last input: bad.json: $.script[0] (teleport to body 0 at tick 9), $.script[2] (displace to body 1 at tick 9)");
  EXPECT_EQ(describeInputCause(s, nullptr, 0, 1), "no input before it; the bodies as given in bad.json: $.bodies.list");
  std::string six;
  for (int i = 0; i < 6; ++i)
    six += std::string(i ? "," : "") + R"({"tick": 2, "body": 0, "command": "displace", "value": [0, 0, 0]})";
  const Scenario many = parse(withBody(R"(, "script": [)" + six + "]"));
  const std::string cause = describeInputCause(many, nullptr, 3, 0);
  const std::string tail = "$.script[3] (displace to body 0 at tick 2) and 2 more";
  EXPECT_EQ(cause.substr(cause.size() - tail.size()), tail) << cause;
  const Scenario one = parse(withBody(""));
  EXPECT_EQ(describeInputCause(one, nullptr, 0, 0),
            "no input before it; the body as given in bad.json: $.bodies.list[0]");
  EXPECT_EQ(describeInputCause(s, nullptr, 0, -1), "");
  const InputTrack t = parseInputTrack(
      R"({"format": "simgrass-input-track/1", "commands": [{"tick": 3, "body": 0, "command": "reset"}]})",
      "my\ntrack.json", s);
  EXPECT_EQ(describeInputCause(s, &t, 4, 0),
            "last input: my\\x0atrack.json: $.commands[0] (reset to body 0 at tick 3)");
}

TEST(InputCause, ScenarioErrorWithANewlineInTheFileNameIsOneLine) {
  EXPECT_TRUE(
      throwsError([] { parseScenario("{\"seed\": -1}", "a\nb.json", {}); }, "$.seed", "a\\nb.json", "a\nb.json"));
}

// ---- 8. the input track is read through the bounded reader ------------------------------------

TEST(RecordInputTrack, DeviceAndDeepTrackAreOneLineBadInput) {
  TempDir dir;
  const std::string out = dir.file("o.sgr");
  CliResult r = runCli("record --ticks 2 --input /dev/zero -o " + quote(out));
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_TRUE(isOneLine(r.err));
  EXPECT_NE(r.err.find("/dev/zero"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("regular file"), std::string::npos) << r.err;
  const std::string deepTrack =
      dir.write("deep.json", R"({"format": "simgrass-input-track/1", "camera": )" + deep(200000) + "}");
  r = runCli("record --ticks 2 --input " + quote(deepTrack) + " -o " + quote(out));
  EXPECT_EQ(r.exitCode, 2) << r.err.substr(0, 500);
  EXPECT_TRUE(isOneLine(r.err));
  EXPECT_NE(r.err.find("$.camera"), std::string::npos) << r.err.substr(0, 500);
}

}  // namespace
}  // namespace sg
