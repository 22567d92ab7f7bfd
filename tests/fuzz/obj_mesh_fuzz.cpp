// libFuzzer target for OBJ meshes (parseObjMesh): any text gives a mesh whose indices are in
// range and whose normals are finite unit vectors, or one error line "fuzz.obj:LINE: expected
// ..."; never a crash, a hang or a huge allocation.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "viewer/render/obj_mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sg::viewer::ObjMesh mesh;
  std::string error;
  if (!sg::viewer::parseObjMesh(std::string(reinterpret_cast<const char*>(data), size), "fuzz.obj", &mesh, &error)) {
    if (error.rfind("fuzz.obj:", 0) != 0 || error.find('\n') != std::string::npos || error.size() > 400) std::abort();
    return 0;
  }
  const size_t vertices = mesh.positions.size() / 3;
  if (mesh.normals.size() != mesh.positions.size() || mesh.indices.empty() || mesh.indices.size() % 3) std::abort();
  for (uint32_t i : mesh.indices)
    if (i >= vertices) std::abort();
  for (size_t i = 0; i < mesh.normals.size(); i += 3) {
    const double len =
        std::sqrt(double(mesh.normals[i]) * mesh.normals[i] + double(mesh.normals[i + 1]) * mesh.normals[i + 1] +
                  double(mesh.normals[i + 2]) * mesh.normals[i + 2]);
    if (!std::isfinite(mesh.positions[i]) || !(std::fabs(len - 1.0) < 1e-3)) std::abort();
  }
  return 0;
}
