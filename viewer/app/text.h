// Small formatting helpers shared by the viewer's files.
#pragma once

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "sim/scenario/json_bounds.h"

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

namespace sg::viewer {

/// Bounds on what a user edits in the viewer (`set`, panels; docs/viewer.md "Limits").
struct EditLimits {
  static constexpr int kJsonDepth = kMaxJsonDepth;          ///< nesting of a `set` value (and the edited path)
  static constexpr size_t kPathSegments = 16;               ///< segments of a `set` path ("a.b.c")
  static constexpr size_t kPathChars = 256;                 ///< length of a `set` path
  static constexpr size_t kArrayEntries = size_t(1) << 16;  ///< entries an edited array may grow to
  static constexpr size_t kShownChars = kEchoChars;         ///< echoed user text in messages
};

/// User text quoted in a one-line message (sim/scenario/json_bounds.h echoText: control
/// characters escaped, at most `max` characters, then "...").
inline std::string shownText(const std::string& s, size_t max = EditLimits::kShownChars) { return echoText(s, max); }

/// The deepest nesting of arrays and objects in JSON text, found without parsing (brackets inside
/// strings do not count): past `limit` it returns a value above `limit`.
inline int jsonNestingDepth(const std::string& text, int limit) {
  return findExcessNesting(text, limit) ? limit + 1 : 0;
}

}  // namespace sg::viewer
