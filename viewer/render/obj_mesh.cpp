#include "viewer/render/obj_mesh.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <sstream>

#include "replay/input_file.h"
#include "sim/scenario/json_bounds.h"

namespace sg::viewer {
namespace {

// A mesh is drawn for looks: these bound what a file (at most InputLimits::kMeshBytes) can make
// the viewer allocate and draw. 4 M triangles is ~100 MiB of vertex data at the worst.
constexpr size_t kMaxVertices = 4'000'000;   ///< `v` lines, and `vn` lines
constexpr size_t kMaxTriangles = 4'000'000;  ///< after fan triangulation
/// |coordinate| bound (metres, body-local): keeps every cross product and normal sum finite in
/// float (edges <= 2e6, products <= 8e12, sums over 12 M corners <= 1e20).
constexpr float kMaxCoordinate = 1e6f;
/// Echoed words are cut to this many characters (a 64 MiB line must not become the error).
constexpr size_t kMaxEcho = 60;

/// `w` quoted for an error: control characters escaped, cut to kMaxEcho characters.
std::string quoted(std::string_view w) {
  static const char kHex[] = "0123456789abcdef";
  std::string q = "'";
  for (size_t i = 0; i < w.size() && i < kMaxEcho; ++i) {
    const auto c = static_cast<unsigned char>(w[i]);
    if (c < 0x20 || c == 0x7f) {
      q += "\\x";
      q += kHex[c >> 4];
      q += kHex[c & 15];
    } else {
      q += char(c);
    }
  }
  if (w.size() > kMaxEcho) q += "...";
  return q + "'";
}

/// Splits a line on spaces and tabs.
std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> w;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) w.push_back(line.substr(start, i - start));
  }
  return w;
}

/// The whole word as a number: no trailing characters, no out-of-range value rounded to inf or 0
/// (from_chars reports those), no NaN or infinity, and within kMaxCoordinate.
bool parseFloat(std::string_view s, float* out) {
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), *out);
  return ec == std::errc() && end == s.data() + s.size() && std::isfinite(*out) && std::fabs(*out) <= kMaxCoordinate;
}

/// An OBJ index (1-based, or negative: relative to the end) to 0-based, or -1 when out of range.
int64_t resolveIndex(std::string_view s, size_t count) {
  int64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || v == 0) return -1;
  const int64_t i = v > 0 ? v - 1 : int64_t(count) + v;
  return i >= 0 && i < int64_t(count) ? i : -1;
}

struct Corner {
  int64_t v = -1, vn = -1;
};

}  // namespace

bool parseObjMesh(const std::string& text, const std::string& name, ObjMesh* out, std::string* error) {
  std::vector<float> v, vn;
  std::vector<Corner> corners;  // 3 per triangle
  size_t lineNo = 0, vtCount = 0;
  auto fail = [&](const std::string& what) {
    *error = name + ":" + std::to_string(lineNo) + ": expected " + what;
    return false;
  };
  std::istringstream in(text);
  std::string raw;
  while (std::getline(in, raw)) {
    ++lineNo;
    std::string_view line(raw);
    if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const auto w = words(line);
    if (w.empty()) continue;
    if (w[0] == "v" || w[0] == "vn") {
      // v x y z [w] (the optional w and vertex colours are ignored); vn x y z.
      if (w.size() < 4) return fail(std::string(w[0] == "v" ? "'v x y z'" : "'vn x y z'") + " (3 numbers)");
      float xyz[3];
      for (int a = 0; a < 3; ++a)
        if (!parseFloat(w[size_t(a) + 1], &xyz[a]))
          return fail("a finite number within +-1e6, got " + quoted(w[size_t(a) + 1]));
      // What may follow: v's w (4 numbers) or vertex colours (6), vn nothing; "v 1 2 3 junk"
      // loaded as if the junk were not there (an independent pass, 2026-11-28).
      const size_t extra = w.size() - 4;
      if (w[0] == "vn" ? extra != 0 : extra != 0 && extra != 1 && extra != 3)
        return fail(std::string(w[0] == "v" ? "'v x y z', 'v x y z w' or 'v x y z r g b'" : "'vn x y z'") + ", got " +
                    std::to_string(w.size() - 1) + " values");
      for (size_t a = 4; a < w.size(); ++a) {
        float ignored = 0;
        if (!parseFloat(w[a], &ignored)) return fail("a finite number within +-1e6, got " + quoted(w[a]));
      }
      auto& dst = w[0] == "v" ? v : vn;
      if (dst.size() / 3 >= kMaxVertices) return fail("at most " + std::to_string(kMaxVertices) + " vertices");
      dst.insert(dst.end(), xyz, xyz + 3);
    } else if (w[0] == "vt") {
      ++vtCount;
    } else if (w[0] == "f") {
      if (w.size() < 4) return fail("a face of at least 3 vertices");
      // Checked before the corners are read: a face of n corners is n - 2 triangles.
      if (w.size() - 3 > kMaxTriangles - corners.size() / 3)
        return fail("at most " + std::to_string(kMaxTriangles) + " triangles in the mesh");
      std::vector<Corner> face;
      for (size_t k = 1; k < w.size(); ++k) {
        // v, v/vt, v//vn or v/vt/vn.
        const std::string_view c = w[k];
        if (std::count(c.begin(), c.end(), '/') > 2)  // "1///" said "a normal index in 1..0"
          return fail("a face corner v, v/vt, v//vn or v/vt/vn, got " + quoted(c));
        // "in 1..0" named an empty range: with no vt or vn line before the face, say that.
        const auto range = [](const char* kind, size_t count) {
          return count == 0 ? std::string("no ") + kind + " index (no " + (kind[0] == 't' ? "vt" : "vn") +
                                  " line comes before this face)"
                            : std::string("a ") + kind + " index in 1.." + std::to_string(count);
        };
        const size_t s1 = c.find('/');
        Corner corner;
        corner.v = resolveIndex(c.substr(0, s1), v.size() / 3);
        if (corner.v < 0)
          return fail("a vertex index in 1.." + std::to_string(v.size() / 3) + " (or -1..-" +
                      std::to_string(v.size() / 3) + "), got " + quoted(c));
        if (s1 != std::string_view::npos) {
          const std::string_view rest = c.substr(s1 + 1);
          const size_t s2 = rest.find('/');
          const std::string_view vt = rest.substr(0, s2);
          if (!vt.empty() && resolveIndex(vt, vtCount) < 0)
            return fail(range("texture", vtCount) + ", got " + quoted(c));
          if (s2 != std::string_view::npos) {
            corner.vn = resolveIndex(rest.substr(s2 + 1), vn.size() / 3);
            if (corner.vn < 0) return fail(range("normal", vn.size() / 3) + ", got " + quoted(c));
          }
        }
        face.push_back(corner);
      }
      for (size_t k = 1; k + 1 < face.size(); ++k) corners.insert(corners.end(), {face[0], face[k], face[k + 1]});
    }
    // Anything else (o, g, s, usemtl, mtllib, l, p, ...) does not change the shape: skipped.
  }
  if (corners.empty()) {
    ++lineNo;
    return fail("at least one face ('f') before the end of the file");
  }

  // Face normals (area-weighted) accumulated per position for corners without a normal.
  std::vector<float> accumulated(v.size(), 0.0f);
  for (size_t t = 0; t < corners.size(); t += 3) {
    const float* p0 = &v[size_t(corners[t].v) * 3];
    const float* p1 = &v[size_t(corners[t + 1].v) * 3];
    const float* p2 = &v[size_t(corners[t + 2].v) * 3];
    const float e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const float e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    const float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) accumulated[size_t(corners[t + size_t(k)].v) * 3 + size_t(a)] += n[a];
  }

  // One output vertex per distinct (v, vn) pair; without a normal the vertex shares the
  // accumulated (smooth) normal of its position.
  out->positions.clear();
  out->normals.clear();
  out->indices.clear();
  out->objVertices = v.size() / 3;
  // A map, not a list per position: one position with many normals must not be quadratic.
  std::map<std::pair<int64_t, int64_t>, uint32_t> seen;
  for (const Corner& c : corners) {
    const auto [at, added] = seen.try_emplace({c.v, c.vn}, uint32_t(out->positions.size() / 3));
    const uint32_t index = at->second;
    if (added) {
      const float* p = &v[size_t(c.v) * 3];
      const float* n = c.vn >= 0 ? &vn[size_t(c.vn) * 3] : &accumulated[size_t(c.v) * 3];
      // In double: the squares of a 1e20 sum overflow float.
      const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
      out->positions.insert(out->positions.end(), p, p + 3);
      if (len > 1e-20)
        out->normals.insert(out->normals.end(), {float(n[0] / len), float(n[1] / len), float(n[2] / len)});
      else
        out->normals.insert(out->normals.end(), {0.0f, 1.0f, 0.0f});  // degenerate: any unit normal
    }
    out->indices.push_back(index);
  }
  return true;
}

namespace {
/// A mesh path as an error shows it: whole up to 60 bytes, else "..." and its last 57 bytes (cut
/// at a UTF-8 boundary), escaped as every echo is. The end, because the path is the scenario's
/// folder joined to the name the scenario gives, and the file name is what tells the reader
/// which mesh.
std::string shownPath(const std::string& path) {
  constexpr size_t kWhole = 60, kTail = 57;
  if (path.size() <= kWhole) return echoText(path);
  size_t from = path.size() - kTail;
  while (from < path.size() && (uint8_t(path[from]) & 0xC0) == 0x80) ++from;  // not inside a character
  return "..." + echoText(path.substr(from));
}
}  // namespace

bool loadObjMesh(const std::string& path, ObjMesh* out, std::string* error) {
  std::string text, expected;
  // The name comes from a scenario (bodies.list[i].mesh): bounded as every found text is
  // (docs/robustness.md), not the megabyte a hostile scenario can give it.
  const std::string shown = shownPath(path);
  if (!readInputFile(path, InputLimits::kMeshBytes, &text, &expected)) {
    *error = shown + ":0: expected " + expected;
    return false;
  }
  return parseObjMesh(text, shown, out, error);
}

}  // namespace sg::viewer
