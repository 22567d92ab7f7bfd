// Small formatting helpers shared by the viewer's files.
#pragma once

#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

namespace sg::viewer {

/// A 64-bit hash as 16 hex digits (how the CLI prints state hashes).
inline std::string hex(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
  return buf;
}

/// Metres to the Q32.32 raw integers a TickInput carries.
inline int64_t toRaw(double metres) { return std::llround(metres * 4294967296.0); }

}  // namespace sg::viewer
