#include "sim/math/scalar.h"

namespace sg {
const char* scalarName(ScalarKind kind) {
  switch (kind) {
    case ScalarKind::Fx32:
      return "fx32";
    case ScalarKind::Fx16:
      return "fx16";
    case ScalarKind::Float:
      return "float";
    case ScalarKind::Double:
      return "double";
  }
  return "?";
}
std::optional<ScalarKind> parseScalarKind(std::string_view name) {
  if (name == "fx32") return ScalarKind::Fx32;
  if (name == "fx16") return ScalarKind::Fx16;
  if (name == "float") return ScalarKind::Float;
  if (name == "double") return ScalarKind::Double;
  return std::nullopt;
}
}  // namespace sg
