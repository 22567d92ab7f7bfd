#include "viewer/render/obj_mesh.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

namespace sg::viewer {
namespace {

constexpr size_t kMaxVertices = 4'000'000;  // a mesh for looks; guards against runaway files

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

bool parseFloat(std::string_view s, float* out) {
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), *out);
  return ec == std::errc() && end == s.data() + s.size() && std::isfinite(*out);
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
          return fail("a finite number, got '" + std::string(w[size_t(a) + 1]) + "'");
      auto& dst = w[0] == "v" ? v : vn;
      if (dst.size() / 3 >= kMaxVertices) return fail("at most " + std::to_string(kMaxVertices) + " vertices");
      dst.insert(dst.end(), xyz, xyz + 3);
    } else if (w[0] == "vt") {
      ++vtCount;
    } else if (w[0] == "f") {
      if (w.size() < 4) return fail("a face of at least 3 vertices");
      std::vector<Corner> face;
      for (size_t k = 1; k < w.size(); ++k) {
        // v, v/vt, v//vn or v/vt/vn.
        const std::string_view c = w[k];
        const size_t s1 = c.find('/');
        Corner corner;
        corner.v = resolveIndex(c.substr(0, s1), v.size() / 3);
        if (corner.v < 0)
          return fail("a vertex index in 1.." + std::to_string(v.size() / 3) + " (or -1..-" +
                      std::to_string(v.size() / 3) + "), got '" + std::string(c) + "'");
        if (s1 != std::string_view::npos) {
          const std::string_view rest = c.substr(s1 + 1);
          const size_t s2 = rest.find('/');
          const std::string_view vt = rest.substr(0, s2);
          if (!vt.empty() && resolveIndex(vt, vtCount) < 0)
            return fail("a texture index in 1.." + std::to_string(vtCount) + ", got '" + std::string(c) + "'");
          if (s2 != std::string_view::npos) {
            corner.vn = resolveIndex(rest.substr(s2 + 1), vn.size() / 3);
            if (corner.vn < 0)
              return fail("a normal index in 1.." + std::to_string(vn.size() / 3) + ", got '" + std::string(c) + "'");
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
  std::vector<std::vector<std::pair<int64_t, uint32_t>>> seen(v.size() / 3);
  for (const Corner& c : corners) {
    auto& list = seen[size_t(c.v)];
    uint32_t index = 0;
    bool found = false;
    for (const auto& [normal, i] : list)
      if (normal == c.vn) index = i, found = true;
    if (!found) {
      index = uint32_t(out->positions.size() / 3);
      list.push_back({c.vn, index});
      const float* p = &v[size_t(c.v) * 3];
      const float* n = c.vn >= 0 ? &vn[size_t(c.vn) * 3] : &accumulated[size_t(c.v) * 3];
      float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      out->positions.insert(out->positions.end(), p, p + 3);
      if (len > 1e-20f)
        out->normals.insert(out->normals.end(), {n[0] / len, n[1] / len, n[2] / len});
      else
        out->normals.insert(out->normals.end(), {0.0f, 1.0f, 0.0f});  // degenerate: any unit normal
    }
    out->indices.push_back(index);
  }
  return true;
}

bool loadObjMesh(const std::string& path, ObjMesh* out, std::string* error) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    *error = path + ":0: expected a readable OBJ file (cannot open it)";
    return false;
  }
  std::ostringstream text;
  text << file.rdbuf();
  return parseObjMesh(text.str(), path, out, error);
}

}  // namespace sg::viewer
