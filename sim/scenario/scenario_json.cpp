// Scenario JSON -> Scenario, with one-line errors that name the file, the JSON path and what
// was expected. Numbers are read from their raw text (collected by a SAX pass) so that the
// decimal -> fixed-point conversion is exact.
#include <algorithm>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "sim/scenario/json_bounds.h"
#include "sim/scenario/scenario.h"

namespace sg {
namespace {
using json = nlohmann::json;

// Records the raw text of every non-integer number by JSON path, rejects duplicate keys and
// refuses nesting deeper than kMaxJsonDepth before any DOM exists (json_bounds.h: a deep DOM is
// harmless, but every recursive walk of it - json::dump in an error message - overflows the stack).
class RawNumberCollector : public nlohmann::json_sax<json> {
 public:
  std::map<std::string, std::string> raw;
  std::string duplicatePath;  // first duplicate key seen, as a JSON path

  bool null() override { return after(); }
  bool boolean(bool) override { return after(); }
  bool number_integer(number_integer_t) override { return after(); }
  bool number_unsigned(number_unsigned_t) override { return after(); }
  bool number_float(number_float_t v, const string_t& s) override {
    // Kept only when the double's shortest text (what Reader::number falls back to) is not the
    // same exact value: "0.5" or "1e-3" need no entry, so a 16 MiB array of short numbers costs
    // no per-number path string and map node (it cost ~700 MB before; now the DOM's share).
    if (!sameExactValue(s, json(v).dump())) raw[path()] = s;
    return after();
  }
  bool string(string_t&) override { return after(); }
  bool binary(binary_t&) override { return after(); }
  bool start_object(std::size_t) override { return open(false); }
  bool key(string_t& k) override {
    Frame& f = frames_.back();
    if (!f.keys.insert(k).second && duplicatePath.empty()) {
      f.key = k;
      duplicatePath = path();
    }
    f.key = k;
    return true;
  }
  bool end_object() override {
    frames_.pop_back();
    return after();
  }
  bool start_array(std::size_t) override { return open(true); }
  bool end_array() override {
    frames_.pop_back();
    return after();
  }
  bool parse_error(std::size_t position, const std::string& token, const nlohmann::detail::exception& e) override {
    errorByte = position;
    errorToken = token;
    errorPath = path();
    numberOverflow = e.id == 406;  // out_of_range.406: a number beyond double, e.g. 1e400
    return false;
  }
  std::size_t errorByte = 0;
  std::string errorToken, errorPath;
  bool numberOverflow = false;
  std::string tooDeepPath;  ///< set when nesting exceeded kMaxJsonDepth: the path of the container holding it

 private:
  struct Frame {
    bool array;
    std::string key;
    int64_t index;
    std::set<std::string> keys;
  };
  std::vector<Frame> frames_;
  bool open(bool array) {
    if (frames_.size() >= size_t(kMaxJsonDepth)) {
      tooDeepPath = path();
      return false;  // stops the parse: nothing deeper is ever read
    }
    frames_.push_back(Frame{array, {}, 0, {}});
    return true;
  }
  std::string path() const {
    std::string p = "$";
    // Appended piece by piece: `"[" + std::string&&` trips GCC 12's -Wrestrict false positive (PR105329).
    for (const Frame& f : frames_) {
      if (f.array) {
        p += '[';
        p += std::to_string(f.index);
        p += ']';
      } else {
        p += '.';
        p += echoText(f.key);  // a key in a message is bounded and has no control characters
      }
    }
    return p;
  }
  static bool sameExactValue(const std::string& text, const std::string& shortest) {
    if (text == shortest) return true;
    const auto a = Rational::parse(text, nullptr), b = Rational::parse(shortest, nullptr);
    return a && b && *a == *b;
  }
  bool after() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
    return true;
  }
};

const char* typeName(const json& j) {
  switch (j.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::boolean:
      return "a boolean";
    case json::value_t::string:
      return "a string";
    case json::value_t::array:
      return "an array";
    case json::value_t::object:
      return "an object";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float:
      return "a number";
    default:
      return "a value";
  }
}

class Reader {
 public:
  Reader(std::string file, const std::map<std::string, std::string>& raw) : file_(std::move(file)), raw_(raw) {}

  [[noreturn]] void fail(const std::string& path, const std::string& expected) const {
    throw ScenarioError(file_, path, expected);
  }
  [[noreturn]] void failGot(const std::string& path, const std::string& expected, const json& got) const {
    // Show a number as the user wrote it, not as the double it parsed to.
    const auto raw = got.is_number_float() ? raw_.find(path) : raw_.end();
    fail(path, expected + ", got " + (raw != raw_.end() ? echoText(raw->second) : echoValue(got)));
  }

  /// Checks that j is an object whose keys are all in `allowed`.
  void object(const json& j, const std::string& path, std::initializer_list<const char*> allowed) const {
    if (!j.is_object()) fail(path, std::string("an object, got ") + typeName(j));
    for (auto it = j.begin(); it != j.end(); ++it) {
      bool ok = false;
      for (const char* a : allowed) ok = ok || it.key() == a;
      if (!ok) {
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        const std::string key = echoText(it.key());
        std::string where = path;
        where += '.';
        where += key;
        std::string expected = "one of the keys {";
        expected += list;
        expected += "}; unknown key '";
        expected += key;
        expected += '\'';
        fail(where, expected);
      }
    }
  }

  Rational number(const json& j, const std::string& path) const {
    std::string text;
    if (j.is_number_integer()) {
      text = j.dump();
    } else if (j.is_number_float()) {
      auto it = raw_.find(path);
      text = it != raw_.end() ? it->second : j.dump();
    } else if (j.is_string()) {
      text = j.get<std::string>();  // fractions such as "1/60"
    } else {
      fail(path, std::string("a number, got ") + typeName(j));
    }
    std::string why;
    auto r = Rational::parse(text, &why);
    if (!r) fail(path, why + ", got " + echoText(text));
    return *r;
  }
  Rational positive(const json& j, const std::string& path) const {
    Rational r = number(j, path);
    if (r.num <= 0) failGot(path, "a positive number", j);
    return r;
  }
  Rational nonNegative(const json& j, const std::string& path) const {
    Rational r = number(j, path);
    if (r.num < 0) failGot(path, "a number >= 0", j);
    return r;
  }
  int64_t integer(const json& j, const std::string& path, int64_t lo, int64_t hi) const {
    const std::string expected = "an integer from " + std::to_string(lo) + " to " + std::to_string(hi);
    if (!j.is_number_integer()) failGot(path, expected, j);
    if (j.is_number_unsigned()) {
      if (j.get<uint64_t>() > uint64_t(hi) || int64_t(j.get<uint64_t>()) < lo) failGot(path, expected, j);
      return int64_t(j.get<uint64_t>());
    }
    const int64_t v = j.get<int64_t>();
    if (v < lo || v > hi) failGot(path, expected, j);
    return v;
  }
  template <size_t N>
  std::array<Rational, N> vector(const json& j, const std::string& path) const {
    if (!j.is_array() || j.size() != N) failGot(path, "an array of " + std::to_string(N) + " numbers", j);
    std::array<Rational, N> out;
    for (size_t i = 0; i < N; ++i) out[i] = number(j[i], path + "[" + std::to_string(i) + "]");
    return out;
  }
  /// A world position [x, z] at j[key], if present.
  void center(const json& j, const std::string& path, Rational* x, Rational* z) const {
    if (!j.contains("center")) return;
    const auto c = vector<2>(j["center"], path + ".center");
    *x = c[0];
    *z = c[1];
  }
  std::string string(const json& j, const std::string& path) const {
    if (!j.is_string()) fail(path, std::string("a string, got ") + typeName(j));
    return j.get<std::string>();
  }
  /// A string naming a file: no control character (a "\u0000" would cut the name where the
  /// file is opened, reading "ok.png" for "ok.png\u0000junk" and recording the longer name).
  std::string fileName(const json& j, const std::string& path) const {
    std::string name = string(j, path);
    // "" named the scenario's own folder ("expected '' to be a regular file, got a directory").
    if (name.empty()) fail(path, "a file name, got an empty string");
    for (size_t i = 0; i < name.size(); ++i) {
      const auto c = static_cast<unsigned char>(name[i]);
      if (c < 0x20 || c == 0x7f)
        fail(path, "a file name without control characters, got '" + echoText(name) + "' (character " +
                       std::to_string(i + 1) + ")");
    }
    return name;
  }
  template <class E>
  E choice(const json& j, const std::string& path, std::initializer_list<std::pair<const char*, E>> options) const {
    std::string list;
    for (auto& o : options) list += std::string(list.empty() ? "" : ", ") + "\"" + o.first + "\"";
    if (j.is_string())
      for (auto& o : options)
        if (j.get<std::string>() == o.first) return o.second;
    failGot(path, "one of " + list, j);
  }
  const std::string& file() const { return file_; }

 private:
  std::string file_;
  const std::map<std::string, std::string>& raw_;
};

void parseField(const Reader& r, const json& j, Scenario::Field& f) {
  const std::string p = "$.field";
  r.object(j, p, {"patchesX", "patchesZ", "spacing", "jitter", "center", "scaleY", "scaleXZ", "atlasVariants"});
  if (j.contains("patchesX")) f.patchesX = r.integer(j["patchesX"], p + ".patchesX", 1, int64_t(1) << 20);
  if (j.contains("patchesZ")) f.patchesZ = r.integer(j["patchesZ"], p + ".patchesZ", 1, int64_t(1) << 20);
  if (j.contains("spacing")) f.spacing = r.positive(j["spacing"], p + ".spacing");
  if (j.contains("jitter")) {
    f.jitter = r.nonNegative(j["jitter"], p + ".jitter");
    if (compare(f.jitter, Rational{1, 2}) > 0)
      r.failGot(p + ".jitter", "a fraction of the spacing from 0 to 0.5", j["jitter"]);
  }
  r.center(j, p, &f.centerX, &f.centerZ);
  if (j.contains("scaleY")) f.scaleY = r.positive(j["scaleY"], p + ".scaleY");
  if (j.contains("scaleXZ")) f.scaleXZ = r.positive(j["scaleXZ"], p + ".scaleXZ");
  if (j.contains("atlasVariants")) f.atlasVariants = int(r.integer(j["atlasVariants"], p + ".atlasVariants", 1, 16));
}

void parseBlade(const Reader& r, const json& j, Scenario::Particles::Blade& b) {
  const std::string p = "$.particles.blade";
  r.object(j, p, {"frequency", "dampingRatio", "trampleSeconds"});
  if (j.contains("frequency")) {
    b.frequency = r.positive(j["frequency"], p + ".frequency");
    if (compare(b.frequency, Rational{1000, 1}) > 0)
      r.failGot(p + ".frequency", "a sway frequency above 0 and up to 1000 Hz", j["frequency"]);
  }
  if (j.contains("dampingRatio")) {
    b.dampingRatio = r.nonNegative(j["dampingRatio"], p + ".dampingRatio");
    if (compare(b.dampingRatio, Rational{100, 1}) > 0)
      r.failGot(p + ".dampingRatio", "a damping ratio from 0 to 100", j["dampingRatio"]);
  }
  if (j.contains("trampleSeconds")) {
    b.trampleSeconds = r.nonNegative(j["trampleSeconds"], p + ".trampleSeconds");
    if (compare(b.trampleSeconds, Rational{3600, 1}) > 0)
      r.failGot(p + ".trampleSeconds", "a recovery time from 0 to 3600 s", j["trampleSeconds"]);
  }
}

void parseParticles(const Reader& r, const json& j, Scenario::Particles& s) {
  const std::string p = "$.particles";
  r.object(j, p,
           {"interpolation", "constraintLength", "initialVelocity", "acceleration", "mass", "damping", "model",
            "constraintMode", "blade", "tiltDrop"});
  // The model first: it sets the defaults of the keys below.
  if (j.contains("model") && j.contains("constraintMode"))
    r.fail(p + ".constraintMode", "either \"model\" or its old name \"constraintMode\", not both");
  if (j.contains("model"))
    s.model =
        r.choice<GrassModel>(j["model"], p + ".model",
                             {{"thesis", GrassModel::Thesis}, {"pbd", GrassModel::Pbd}, {"blade", GrassModel::Blade}});
  if (j.contains("constraintMode"))
    s.model = r.choice<GrassModel>(j["constraintMode"], p + ".constraintMode",
                                   {{"thesis", GrassModel::Thesis}, {"pbd", GrassModel::Pbd}});
  s.writtenModel = s.model;
  if (s.model == GrassModel::Blade) {  // a real blade: at rest, under gravity, held up by its stiffness
    s.initialVelocity = {Rational{0, 1}, Rational{0, 1}, Rational{0, 1}};
    s.acceleration = {Rational{0, 1}, Rational{-981, 100}, Rational{0, 1}};
    s.damping = Rational{1, 1};  // its dampingRatio is the damping
  }
  if (j.contains("blade")) {
    if (s.model != GrassModel::Blade) r.fail(p + ".blade", "no 'blade' block unless \"model\": \"blade\"");
    parseBlade(r, j["blade"], s.blade);
  }
  if (j.contains("interpolation")) s.interpolation = int(r.integer(j["interpolation"], p + ".interpolation", 1, 4));
  if (j.contains("constraintLength")) s.constraintLength = r.positive(j["constraintLength"], p + ".constraintLength");
  if (j.contains("initialVelocity")) s.initialVelocity = r.vector<3>(j["initialVelocity"], p + ".initialVelocity");
  if (j.contains("acceleration")) s.acceleration = r.vector<3>(j["acceleration"], p + ".acceleration");
  if (j.contains("mass")) s.mass = r.positive(j["mass"], p + ".mass");
  if (j.contains("damping")) {
    s.damping = r.positive(j["damping"], p + ".damping");
    if (compare(s.damping, Rational{1, 1}) > 0) r.failGot(p + ".damping", "a damping factor in (0, 1]", j["damping"]);
  }
  if (j.contains("tiltDrop")) {
    s.tiltDrop = r.vector<3>(j["tiltDrop"], p + ".tiltDrop");
    for (int i = 0; i < 3; ++i) {
      const std::string q = p + ".tiltDrop[" + std::to_string(i) + "]";
      if (s.tiltDrop[i].num < 0) r.failGot(q, "a number >= 0", j["tiltDrop"][i]);
      if (i > 0 && compare(s.tiltDrop[i], s.tiltDrop[i - 1]) <= 0)
        r.failGot(q, "thresholds in increasing order", j["tiltDrop"][i]);
    }
  }
}

void parseWind(const Reader& r, const json& j, Scenario::Wind& w) {
  const std::string p = "$.wind";
  r.object(j, p, {"travelSpeed", "travel", "schedule"});
  if (j.contains("travelSpeed")) w.travelSpeed = r.positive(j["travelSpeed"], p + ".travelSpeed");
  if (j.contains("travel"))
    w.travel = r.choice<WindTravel>(j["travel"], p + ".travel",
                                    {{"direction", WindTravel::Direction}, {"forward", WindTravel::Forward}});
  if (j.contains("schedule")) {
    const json& s = j["schedule"];
    if (!s.is_array() || s.size() > 1024) r.failGot(p + ".schedule", "an array of at most 1024 gusts", s);
    w.schedule.clear();
    for (size_t i = 0; i < s.size(); ++i) {
      const std::string q = p + ".schedule[" + std::to_string(i) + "]";
      r.object(s[i], q, {"force", "duration", "front"});
      if (!s[i].contains("force")) r.fail(q + ".force", "a force [x, y, z] (missing)");
      if (!s[i].contains("duration")) r.fail(q + ".duration", "a duration in seconds (missing)");
      w.schedule.push_back(
          {r.vector<3>(s[i]["force"], q + ".force"), r.positive(s[i]["duration"], q + ".duration"), {}});
      if (s[i].contains("front")) {
        const auto front = r.vector<2>(s[i]["front"], q + ".front");
        const Rational limit{1000000, 1};
        for (const Rational& c : front)
          if (compare(c, limit) > 0 || compare(c, Rational{-1000000, 1}) < 0)
            r.failGot(q + ".front", "a horizontal direction [x, z] with components within +-1e6", s[i]["front"]);
        if (front[0].isZero() && front[1].isZero())
          r.failGot(q + ".front", "a horizontal direction [x, z], not [0, 0]", s[i]["front"]);
        w.schedule.back().front = front;
      }
    }
  }
}

void parseTerrain(const Reader& r, const json& j, Scenario::Terrain& t, const ScenarioFileReader& readFile) {
  const std::string p = "$.terrain";
  r.object(j, p, {"type", "height", "file", "cellSize", "maxHeight", "center"});
  const bool heightmap =
      j.contains("type") && r.choice<bool>(j["type"], p + ".type", {{"flat", false}, {"heightmap", true}});
  t.flat = !heightmap;
  if (!heightmap) {
    for (const char* k : {"file", "cellSize", "maxHeight", "center"})
      if (j.contains(k))
        r.fail(p + "." + k, "no '" + std::string(k) + "' for a flat terrain (set \"type\": \"heightmap\")");
    if (j.contains("height")) t.flatHeight = r.number(j["height"], p + ".height");
    return;
  }
  if (j.contains("height")) r.fail(p + ".height", "no 'height' for a heightmap terrain (use maxHeight)");
  if (!j.contains("file")) r.fail(p + ".file", "the heightmap PNG file name (missing)");
  t.heightmapPath = r.fileName(j["file"], p + ".file");
  if (j.contains("cellSize")) t.cellSize = r.positive(j["cellSize"], p + ".cellSize");
  if (j.contains("maxHeight")) t.maxHeight = r.nonNegative(j["maxHeight"], p + ".maxHeight");
  r.center(j, p, &t.centerX, &t.centerZ);
  std::vector<uint8_t> bytes;
  std::string why;
  if (!readFile || !readFile(t.heightmapPath, &bytes, &why)) r.fail(p + ".file", why.empty() ? "a readable file" : why);
  // The size cap is checked on the PNG header before decoding (a 16384 x 16384 image would
  // allocate 256 MiB first) and again on the decoded image (whatever the decoder).
  const std::string name = "'" + echoText(t.heightmapPath) + "'";
  auto tooLarge = [&](uint64_t w, uint64_t h) {
    if (w > uint64_t(kMaxHeightmapSide) || h > uint64_t(kMaxHeightmapSide))
      r.fail(p + ".file", name + " to be a heightmap of at most " + std::to_string(kMaxHeightmapSide) + " x " +
                              std::to_string(kMaxHeightmapSide) + " samples, got " + std::to_string(w) + " x " +
                              std::to_string(h));
  };
  static constexpr uint8_t kPngSignatureAndIhdr[16] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n',
                                                       0,    0,   0,   13,  'I',  'H',  'D',  'R'};
  if (bytes.size() >= 24 && std::equal(bytes.begin(), bytes.begin() + 16, kPngSignatureAndIhdr)) {
    auto be32 = [&](size_t at) {
      return uint64_t(bytes[at]) << 24 | uint64_t(bytes[at + 1]) << 16 | uint64_t(bytes[at + 2]) << 8 | bytes[at + 3];
    };
    tooLarge(be32(16), be32(20));
  }
  if (!decodeHeightmapPng(bytes, &t.heightmap, &why)) r.fail(p + ".file", name + " to be " + why);
  tooLarge(uint64_t(t.heightmap.width), uint64_t(t.heightmap.height));
}

/// The smallest radius or half extent a body part may have (m): below it the exact mass
/// properties (r^5 in the inertia) outgrow 128-bit fractions, and no scalar resolves it anyway.
const Rational kMinPartSize{1, 1000000};

ShapeSpec parseShapePart(const Reader& r, const json& j, const std::string& p, bool allowOffset) {
  ShapeSpec part;
  if (allowOffset) r.object(j, p, {"type", "radius", "halfExtents", "offset"});
  if (!j.contains("type")) r.fail(p + ".type", "\"sphere\" or \"box\" (missing)");
  part.type = r.choice<ShapeType>(j["type"], p + ".type", {{"sphere", ShapeType::Sphere}, {"box", ShapeType::Box}});
  if (part.type == ShapeType::Sphere) {
    if (j.contains("halfExtents")) r.fail(p + ".halfExtents", "no 'halfExtents' for a sphere (use radius)");
    if (!j.contains("radius")) r.fail(p + ".radius", "a sphere radius in m (missing)");
    part.radius = r.positive(j["radius"], p + ".radius");
    if (compare(part.radius, kMinPartSize) < 0)
      r.failGot(p + ".radius", "a radius of at least 0.000001 m (1 micrometre)", j["radius"]);
  } else {
    if (j.contains("radius")) r.fail(p + ".radius", "no 'radius' for a box (use halfExtents)");
    if (!j.contains("halfExtents")) r.fail(p + ".halfExtents", "box half extents [x, y, z] in m (missing)");
    part.halfExtents = r.vector<3>(j["halfExtents"], p + ".halfExtents");
    for (int i = 0; i < 3; ++i)
      if (part.halfExtents[size_t(i)].num <= 0 || compare(part.halfExtents[size_t(i)], kMinPartSize) < 0)
        r.failGot(p + ".halfExtents[" + std::to_string(i) + "]", "a half extent of at least 0.000001 m (1 micrometre)",
                  j["halfExtents"][size_t(i)]);
  }
  if (j.contains("offset")) part.offset = r.vector<3>(j["offset"], p + ".offset");
  return part;
}

BodySpec parseBody(const Reader& r, const json& j, const std::string& p) {
  BodySpec b;
  r.object(j, p,
           {"name", "shape", "mass", "position", "orientation", "velocity", "angularVelocity", "linearDamping",
            "angularDamping", "restitution", "friction", "mower", "canSleep", "mesh"});
  if (!j.contains("name")) r.fail(p + ".name", "a body name (missing)");
  b.name = r.string(j["name"], p + ".name");
  if (!j.contains("shape"))
    r.fail(p + ".shape", "a shape {\"type\": \"sphere\" | \"box\" | \"compound\", ...} (missing)");
  const json& sh = j["shape"];
  const std::string sp = p + ".shape";
  r.object(sh, sp, {"type", "radius", "halfExtents", "parts"});
  if (sh.contains("type") && sh["type"] == "compound") {
    b.compound = true;
    if (!sh.contains("parts") || !sh["parts"].is_array() || sh["parts"].empty() || sh["parts"].size() > 16)
      r.fail(sp + ".parts", "an array of 1 to 16 sphere/box parts");
    for (size_t i = 0; i < sh["parts"].size(); ++i)
      b.parts.push_back(parseShapePart(r, sh["parts"][i], sp + ".parts[" + std::to_string(i) + "]", true));
  } else {
    if (sh.contains("type") && sh["type"] != "sphere" && sh["type"] != "box")
      r.failGot(sp + ".type", "one of \"sphere\", \"box\", \"compound\"", sh["type"]);
    if (sh.contains("parts")) r.fail(sp + ".parts", "no 'parts' unless \"type\": \"compound\"");
    b.parts.push_back(parseShapePart(r, sh, sp, false));
  }
  if (j.contains("mass")) b.mass = r.positive(j["mass"], p + ".mass");
  if (j.contains("position")) b.position = r.vector<3>(j["position"], p + ".position");
  if (j.contains("orientation")) {
    b.orientation = r.vector<4>(j["orientation"], p + ".orientation");
    // A unit quaternion, to within 1e-3 in its squared norm (so that 4-digit decimals such as
    // [0.7071, 0, 0.7071, 0] pass); the world normalises it in the scalar (makeBody). A zero or a
    // clearly non-unit quaternion is a mistake, not a rotation. Checked in integers, each component
    // rounded to 2^-40 (an error of 2^-39 in the sum, far inside the 0.001): squaring the exact
    // fractions overflowed 128 bits for a component of many digits (-3.52e-18, or 0.7071 to 30
    // digits) and called a unit quaternion non-unit (an independent pass, 2026-11-28).
    Int128 norm2 = 0;
    bool unit = true;
    for (const Rational& q : b.orientation) {
      const std::optional<Int128> scaled = q.toScaledInteger(40);
      if (!scaled || *scaled > (Int128(1) << 41) || *scaled < -(Int128(1) << 41)) {
        unit = false;  // |q| > 2
        break;
      }
      norm2 += *scaled * *scaled;  // <= 4 x 2^82
    }
    const Int128 one = Int128(1) << 80;
    unit = unit && norm2 * 1000 >= one * 999 && norm2 * 1000 <= one * 1001;
    if (!unit)
      r.failGot(p + ".orientation", "a unit quaternion [w, x, y, z] (w^2 + x^2 + y^2 + z^2 = 1 within 0.001)",
                j["orientation"]);
  }
  if (j.contains("velocity")) b.velocity = r.vector<3>(j["velocity"], p + ".velocity");
  if (j.contains("angularVelocity")) b.angularVelocity = r.vector<3>(j["angularVelocity"], p + ".angularVelocity");
  auto factor = [&](const char* key, Rational& out) {
    if (!j.contains(key)) return;
    out = r.positive(j[key], p + "." + key);
    if (compare(out, Rational{1, 1}) > 0) r.failGot(p + "." + key, "a damping factor in (0, 1]", j[key]);
  };
  factor("linearDamping", b.linearDamping);
  factor("angularDamping", b.angularDamping);
  if (j.contains("restitution")) {
    b.restitution = r.nonNegative(j["restitution"], p + ".restitution");
    if (compare(b.restitution, Rational{1, 1}) > 0)
      r.failGot(p + ".restitution", "a restitution in [0, 1]", j["restitution"]);
  }
  if (j.contains("friction")) b.friction = r.nonNegative(j["friction"], p + ".friction");
  if (j.contains("mower")) {
    if (!j["mower"].is_boolean()) r.failGot(p + ".mower", "true or false", j["mower"]);
    b.mower = j["mower"].get<bool>();
  }
  if (j.contains("canSleep")) {
    if (!j["canSleep"].is_boolean()) r.failGot(p + ".canSleep", "true or false", j["canSleep"]);
    b.canSleep = j["canSleep"].get<bool>();
  }
  // Looks only (the renderer loads it); stored as written, never part of the fingerprint.
  if (j.contains("mesh")) b.mesh = r.fileName(j["mesh"], p + ".mesh");
  return b;
}

void parseBodies(const Reader& r, const json& j, Scenario::Bodies& b, GrassModel writtenModel) {
  const std::string p = "$.bodies";
  r.object(j, p,
           {"gravity", "substeps", "velocityIterations", "islandVelocityIterations", "positionIterations",
            "contactHertz", "particleBroadphase", "bodyBroadphase", "boxParticleNormal", "tipContact", "mowerCutHeight",
            "grassDrag", "list"});
  if (j.contains("contactHertz")) b.contactHertz = r.positive(j["contactHertz"], p + ".contactHertz");
  if (j.contains("grassDrag")) b.grassDrag = r.nonNegative(j["grassDrag"], p + ".grassDrag");
  if (j.contains("mowerCutHeight")) b.mowerCutHeight = r.nonNegative(j["mowerCutHeight"], p + ".mowerCutHeight");
  if (j.contains("gravity")) b.gravity = r.vector<3>(j["gravity"], p + ".gravity");
  if (j.contains("substeps")) b.substeps = int(r.integer(j["substeps"], p + ".substeps", 1, 64));
  if (j.contains("velocityIterations"))
    b.velocityIterations = int(r.integer(j["velocityIterations"], p + ".velocityIterations", 1, 1000));
  if (j.contains("islandVelocityIterations"))
    b.islandVelocityIterations =
        int(r.integer(j["islandVelocityIterations"], p + ".islandVelocityIterations", 1, 1000));
  if (j.contains("positionIterations"))
    b.positionIterations = int(r.integer(j["positionIterations"], p + ".positionIterations", 0, 1000));
  if (j.contains("particleBroadphase"))
    b.particleBroadphase =
        r.choice<ParticleBroadphase>(j["particleBroadphase"], p + ".particleBroadphase",
                                     {{"grid", ParticleBroadphase::Grid}, {"brute", ParticleBroadphase::Brute}});
  if (j.contains("bodyBroadphase"))
    b.bodyBroadphase =
        r.choice<BodyBroadphase>(j["bodyBroadphase"], p + ".bodyBroadphase",
                                 {{"brute", BodyBroadphase::Brute}, {"sap", BodyBroadphase::SweepAndPrune}});
  if (j.contains("boxParticleNormal"))
    b.boxParticleNormal =
        r.choice<BoxParticleNormal>(j["boxParticleNormal"], p + ".boxParticleNormal",
                                    {{"up", BoxParticleNormal::Up}, {"nearest-face", BoxParticleNormal::NearestFace}});
  if (j.contains("tipContact")) {
    b.tipContact = r.choice<TipContact>(j["tipContact"], p + ".tipContact",
                                        {{"push", TipContact::Push}, {"hold", TipContact::Hold}});
    // The blade always holds: a file that asks it to push would run exactly as "hold" (an
    // independent pass found the key ignored). A `--variant model=blade` over a thesis file with
    // "push" is a comparison across models, and the blade's docs say it holds.
    if (writtenModel == GrassModel::Blade && b.tipContact == TipContact::Push)
      r.failGot(p + ".tipContact", "\"hold\" or no tipContact with \"model\": \"blade\" (a blade always holds)",
                j["tipContact"]);
  }
  if (j.contains("list")) {
    const json& l = j["list"];
    if (!l.is_array() || l.size() > 1024) r.failGot(p + ".list", "an array of at most 1024 bodies", l);
    for (size_t i = 0; i < l.size(); ++i) {
      const std::string q = p + ".list[" + std::to_string(i) + "]";
      b.list.push_back(parseBody(r, l[i], q));
      for (size_t k = 0; k + 1 < b.list.size(); ++k)
        if (b.list[k].name == b.list.back().name)
          r.fail(q + ".name", "a unique body name, '" + echoText(b.list.back().name) + "' is taken");
    }
  }
}

void parseMarkings(const Reader& r, const json& j, Scenario::Markings& m) {
  const std::string p = "$.markings";
  r.object(j, p, {"center", "length", "width", "lineWidth", "centerCircleRadius"});
  m.enabled = true;
  r.center(j, p, &m.centerX, &m.centerZ);
  if (j.contains("length")) m.length = r.positive(j["length"], p + ".length");
  if (j.contains("width")) m.width = r.positive(j["width"], p + ".width");
  if (j.contains("lineWidth")) m.lineWidth = r.positive(j["lineWidth"], p + ".lineWidth");
  if (j.contains("centerCircleRadius"))
    m.centerCircleRadius = r.nonNegative(j["centerCircleRadius"], p + ".centerCircleRadius");
}

void parseCamera(const Reader& r, const json& cams, const std::string& p, std::vector<CameraKey>& out) {
  if (!cams.is_array() || cams.size() > 10000000) r.failGot(p, "an array of {tick, position}", cams);
  for (size_t i = 0; i < cams.size(); ++i) {
    const std::string q = p + "[" + std::to_string(i) + "]";
    r.object(cams[i], q, {"tick", "position"});
    if (!cams[i].contains("tick")) r.fail(q + ".tick", "the tick the camera moves (missing)");
    if (!cams[i].contains("position")) r.fail(q + ".position", "a position [x, y, z] (missing)");
    CameraKey key;
    key.tick = r.integer(cams[i]["tick"], q + ".tick", 0, kMaxTick);
    if (!out.empty() && key.tick <= out.back().tick)
      r.failGot(q + ".tick", "a tick after the previous camera key's " + std::to_string(out.back().tick),
                cams[i]["tick"]);
    key.position = r.vector<3>(cams[i]["position"], q + ".position");
    out.push_back(key);
  }
}

void parseLod(const Reader& r, const json& j, Scenario::Lod& l) {
  const std::string p = "$.lod";
  r.object(j, p, {"mode", "window", "center", "edgeSpacing", "edgeRows"});
  if (j.contains("mode"))
    l.mode = r.choice<LodMode>(j["mode"], p + ".mode", {{"off", LodMode::Off}, {"window", LodMode::Window}});
  if (j.contains("window")) {
    const json& w = j["window"];
    if (!w.is_array() || w.size() != 2) r.failGot(p + ".window", "[particles along x, particles along z]", w);
    l.windowX = r.integer(w[0], p + ".window[0]", 3, 1 << 20);
    l.windowZ = r.integer(w[1], p + ".window[1]", 3, 1 << 20);
  }
  if (j.contains("center")) l.centerGiven = true;
  r.center(j, p, &l.centerX, &l.centerZ);
  if (j.contains("edgeSpacing")) l.edgeSpacing = int(r.integer(j["edgeSpacing"], p + ".edgeSpacing", 1, 64));
  if (j.contains("edgeRows")) l.edgeRows = int(r.integer(j["edgeRows"], p + ".edgeRows", 0, 1000));
}

/// A command's body: a name from $.bodies.list, or an index (scenario bodies first, then spawned
/// ones in spawn order; a command to an index that does not exist when it runs is ignored).
int32_t scriptBody(const Reader& r, const json& body, const Scenario& s, const std::string& p) {
  const int64_t last = bodyIndexLimit(s.bodies.list.size()) - 1;
  if (body.is_number_integer()) return int32_t(r.integer(body, p, 0, last));
  if (!body.is_string()) r.failGot(p, "a body name or index 0.." + std::to_string(last), body);
  const std::string name = r.string(body, p);
  for (size_t k = 0; k < s.bodies.list.size(); ++k)
    if (s.bodies.list[k].name == name) return int32_t(k);
  r.failGot(p, "the name of a body in $.bodies.list", body);
  return -1;
}

void parseScript(const Reader& r, const json& j, const Scenario& s, const std::string& p,
                 std::vector<ScriptedCommand>& script) {
  if (!j.is_array() || j.size() > 1000000) r.failGot(p, "an array of commands", j);
  for (size_t i = 0; i < j.size(); ++i) {
    const std::string q = p + "[" + std::to_string(i) + "]";
    const json& c = j[i];
    r.object(c, q, {"tick", "body", "command", "value"});
    ScriptedCommand cmd;
    cmd.source = int64_t(i);
    if (!c.contains("tick")) r.fail(q + ".tick", "the tick the command applies to (missing)");
    cmd.tick = r.integer(c["tick"], q + ".tick", 0, kMaxTick);
    if (!c.contains("body")) r.fail(q + ".body", "a body name or index (missing)");
    cmd.body = scriptBody(r, c["body"], s, q + ".body");
    if (!c.contains("command")) r.fail(q + ".command", "a command (missing)");
    cmd.kind = r.choice<BodyCommandKind>(c["command"], q + ".command",
                                         {{"displace", BodyCommandKind::Displace},
                                          {"addVelocity", BodyCommandKind::AddVelocity},
                                          {"impulse", BodyCommandKind::Impulse},
                                          {"teleport", BodyCommandKind::Teleport},
                                          {"reset", BodyCommandKind::Reset},
                                          {"spawn", BodyCommandKind::Spawn},
                                          {"mowerOn", BodyCommandKind::MowerOn},
                                          {"mowerOff", BodyCommandKind::MowerOff},
                                          {"dragTo", BodyCommandKind::DragTo}});
    // reset and the blade switches take no value; every other command needs one.
    const bool needsValue = cmd.kind != BodyCommandKind::Reset && cmd.kind != BodyCommandKind::MowerOn &&
                            cmd.kind != BodyCommandKind::MowerOff;
    if (c.contains("value"))
      cmd.value = r.vector<3>(c["value"], q + ".value");
    else if (needsValue)
      r.fail(q + ".value", "a vector [x, y, z] (missing)");
    script.push_back(cmd);
  }
  std::stable_sort(script.begin(), script.end(),
                   [](const ScriptedCommand& a, const ScriptedCommand& b) { return a.tick < b.tick; });
}

std::string lineColumn(const std::string& text, size_t byte) {
  size_t line = 1, col = 1;
  for (size_t i = 0; i < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(col);
}
}  // namespace

ScenarioError::ScenarioError(const std::string& file, const std::string& path, const std::string& expected)
    : std::runtime_error(escapeControl(file + ": " + path + ": expected " + expected)), file_(file), path_(path) {}

namespace {
/// Parses JSON text, reporting the byte and line of a syntax error and the path of a number that
/// overflows; `raw` receives every number as written (for exact rationals).
json loadJson(const std::string& text, const std::string& sourceName, std::map<std::string, std::string>* raw) {
  // nlohmann's lexer takes a NUL byte for the end of the input: "{...}\0GARBAGE {{" would parse.
  // Nothing but whitespace may follow the value, and a NUL inside it is no JSON either.
  if (const size_t nul = text.find('\0'); nul != std::string::npos)
    throw ScenarioError(sourceName, "byte " + std::to_string(nul + 1) + " (" + lineColumn(text, nul) + ")",
                        "valid JSON (a NUL byte; nothing but whitespace may follow the value)");
  // The SAX pass first: it knows the JSON path of a number that overflows a double.
  RawNumberCollector collector;
  const bool wellFormed = json::sax_parse(text, &collector);
  if (!wellFormed && !collector.tooDeepPath.empty()) {
    const size_t byte = findExcessNesting(text).value_or(0);
    throw ScenarioError(sourceName, collector.tooDeepPath,
                        "arrays and objects nested at most " + std::to_string(kMaxJsonDepth) + " deep, level " +
                            std::to_string(kMaxJsonDepth + 1) + " opens at byte " + std::to_string(byte + 1) + " (" +
                            lineColumn(text, byte) + ")");
  }
  if (!wellFormed && collector.numberOverflow)
    throw ScenarioError(sourceName, collector.errorPath,
                        "a number from 1e-36 to below 1e36 in magnitude, got " + echoText(collector.errorToken));
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {
    // e.what() is "[json.exception.parse_error.101] parse error at line L, column C: ..."
    std::string what = e.what();
    const size_t colon = what.find(": ", what.find("error"));
    // The detail ends with the token last read, which may be a whole unterminated string: cut it.
    const std::string detail = echoText(colon == std::string::npos ? what : what.substr(colon + 2), 2 * kEchoChars);
    const size_t byte = collector.errorByte;
    throw ScenarioError(sourceName, "byte " + std::to_string(byte) + " (" + lineColumn(text, byte ? byte - 1 : 0) + ")",
                        "valid JSON (" + detail + ")");
  }
  if (!collector.duplicatePath.empty())
    throw ScenarioError(sourceName, collector.duplicatePath, "each key once (this key appears twice)");

  *raw = std::move(collector.raw);
  return root;
}
}  // namespace

Scenario parseScenario(const std::string& text, const std::string& sourceName, const ScenarioFileReader& readFile) {
  std::map<std::string, std::string> raw;
  const json root = loadJson(text, sourceName, &raw);
  Reader r(sourceName, raw);
  Scenario s;
  s.sourceName = sourceName;
  s.text = text;
  r.object(root, "$",
           {"format", "name", "description", "seed", "scalar", "timeStep", "field", "particles", "wind", "terrain",
            "bodies", "script", "markings", "camera", "lod"});
  if (root.contains("format") && root["format"] != "simgrass-scenario/1")
    r.failGot("$.format", "\"simgrass-scenario/1\"", root["format"]);
  if (root.contains("name")) s.name = r.string(root["name"], "$.name");
  if (root.contains("description")) r.string(root["description"], "$.description");
  if (root.contains("seed")) {
    // -0 is 0 (the parser keeps it as a signed integer: it was refused as "got 0").
    const json& seed = root["seed"];
    const bool negativeZero = seed.is_number_integer() && !seed.is_number_unsigned() && seed.get<int64_t>() == 0;
    if (!seed.is_number_unsigned() && !negativeZero) r.failGot("$.seed", "an integer from 0 to 2^64-1", seed);
    s.seed = negativeZero ? 0 : seed.get<uint64_t>();
  }
  if (root.contains("scalar")) {
    auto k = root["scalar"].is_string() ? parseScalarKind(root["scalar"].get<std::string>()) : std::nullopt;
    if (!k) r.failGot("$.scalar", "one of \"fx32\", \"fx16\", \"float\", \"double\"", root["scalar"]);
    s.scalar = *k;
  }
  if (root.contains("timeStep")) {
    s.timeStep = r.positive(root["timeStep"], "$.timeStep");
    if (compare(s.timeStep, Rational{1, 1}) > 0 || compare(s.timeStep, Rational{1, 100000}) < 0)
      r.failGot("$.timeStep", "a time step from 1e-5 to 1 s", root["timeStep"]);
  }
  if (root.contains("field")) parseField(r, root["field"], s.field);
  if (root.contains("particles")) parseParticles(r, root["particles"], s.particles);
  if (root.contains("wind")) parseWind(r, root["wind"], s.wind);
  if (root.contains("terrain")) parseTerrain(r, root["terrain"], s.terrain, readFile);
  if (root.contains("bodies")) parseBodies(r, root["bodies"], s.bodies, s.particles.writtenModel);
  if (root.contains("script")) parseScript(r, root["script"], s, "$.script", s.script);
  if (root.contains("markings")) parseMarkings(r, root["markings"], s.markings);
  if (root.contains("camera")) parseCamera(r, root["camera"], "$.camera", s.camera);
  if (root.contains("lod")) parseLod(r, root["lod"], s.lod);
  if (s.wind.schedule.empty()) {
    // An empty schedule is allowed: no wind.
  }
  return s;
}

const std::string& defaultScenarioText() {
  static const std::string text = R"JSON({
  "format": "simgrass-scenario/1",
  "name": "thesis-meadow",
  "description": "The thesis meadow: 151 x 151 tufts, one particle each, thesis wind schedule, flat ground.",
  "seed": 1,
  "scalar": "fx32",
  "timeStep": "1/60",
  "field": {
    "patchesX": 151, "patchesZ": 151,
    "spacing": 0.25, "jitter": 0.3, "center": [0, 0],
    "scaleY": 1.0, "scaleXZ": 0.5, "atlasVariants": 4
  },
  "particles": {
    "interpolation": 1,
    "constraintLength": 1.0,
    "initialVelocity": [0.2, 0.2, 0.2],
    "acceleration": [0, 1, 0],
    "mass": 1,
    "damping": 0.97,
    "constraintMode": "thesis",
    "tiltDrop": [0.2, 0.3, 0.4]
  },
  "wind": {
    "travelSpeed": 7.5,
    "travel": "direction",
    "schedule": [
      {"force": [0, 1, 0.9], "duration": 5},
      {"force": [0, 0, 0], "duration": 6},
      {"force": [0, 1, -0.9], "duration": 4},
      {"force": [0, 0, 0], "duration": 6}
    ]
  },
  "terrain": {"type": "flat", "height": 0}
}
)JSON";
  return text;
}

}  // namespace sg

namespace sg {

InputTrack parseInputTrack(const std::string& text, const std::string& sourceName, const Scenario& scenario) {
  std::map<std::string, std::string> raw;
  const json root = loadJson(text, sourceName, &raw);
  Reader r(sourceName, raw);
  InputTrack track;
  track.sourceName = sourceName;
  r.object(root, "$", {"format", "ticks", "camera", "commands"});
  if (!root.contains("format")) r.fail("$.format", "\"simgrass-input-track/1\" (the key is missing)");
  if (root["format"] != "simgrass-input-track/1") r.failGot("$.format", "\"simgrass-input-track/1\"", root["format"]);
  if (root.contains("ticks")) track.ticks = r.integer(root["ticks"], "$.ticks", 0, kMaxTick);
  if (root.contains("camera")) parseCamera(r, root["camera"], "$.camera", track.camera);
  if (root.contains("commands")) parseScript(r, root["commands"], scenario, "$.commands", track.commands);
  validateInputTrack(track, scenario.scalar);
  return track;
}

}  // namespace sg
