// A minimal Wavefront OBJ reader for body meshes drawn for looks (the collision proxy stays the
// scenario's primitives): v, vn and f (triangles and polygons, fan-triangulated; v, v/vt, v//vn,
// v/vt/vn; negative indices count back from the last vertex). Other statements (vt, o, g, s,
// usemtl, mtllib, ...) are skipped. Normals are computed (area-weighted, per vertex) when a face
// has none. Units: the file's, taken as body-local metres.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace sg::viewer {

struct ObjMesh {
  /// Unindexed-friendly triangle soup made indexable: position + unit normal per vertex.
  std::vector<float> positions;   ///< x, y, z per vertex
  std::vector<float> normals;     ///< x, y, z per vertex (unit)
  std::vector<uint32_t> indices;  ///< 3 per triangle
  size_t objVertices = 0;         ///< `v` lines read
  size_t triangles() const { return indices.size() / 3; }
};

/// Reads `path` into `out`. On failure returns false and sets `error` to one line
/// "FILE:LINE: expected ..." (LINE 0 when the file cannot be read); never throws on bad input.
bool loadObjMesh(const std::string& path, ObjMesh* out, std::string* error);

/// The same from text (`name` stands for the file in errors).
bool parseObjMesh(const std::string& text, const std::string& name, ObjMesh* out, std::string* error);

}  // namespace sg::viewer
