// Small formatting helpers shared by the viewer's files.
#pragma once

#include <algorithm>
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

namespace sg::viewer {

/// Bounds on what a user edits in the viewer (`set`, panels; docs/viewer.md "Limits").
struct EditLimits {
  static constexpr int kJsonDepth = 64;                     ///< nesting of a `set` value (and the edited path)
  static constexpr size_t kPathSegments = 16;               ///< segments of a `set` path ("a.b.c")
  static constexpr size_t kPathChars = 256;                 ///< length of a `set` path
  static constexpr size_t kArrayEntries = size_t(1) << 16;  ///< entries an edited array may grow to
  static constexpr size_t kShownChars = 60;                 ///< echoed user text in messages
};

/// User text quoted in a one-line message: control characters escaped (\n, \x01), at most `max`
/// characters of the original shown, then "..." (so no input can make a message long or multi-line).
inline std::string shownText(const std::string& s, size_t max = EditLimits::kShownChars) {
  std::string out;
  const size_t n = std::min(s.size(), max);
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c == '\n')
      out += "\\n";
    else if (c == '\r')
      out += "\\r";
    else if (c == '\t')
      out += "\\t";
    else if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out += char(c);
    }
  }
  if (s.size() > max) out += "...";
  return out;
}

/// The deepest nesting of arrays and objects in JSON text (brackets inside strings do not count),
/// found without parsing: a value 100000 levels deep is refused before any recursive code (the
/// parser's result, its dump, its destructor) sees it. Stops counting once past `limit`.
inline int jsonNestingDepth(const std::string& text, int limit) {
  int depth = 0, deepest = 0;
  bool inString = false, escaped = false;
  for (char c : text) {
    if (inString) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        inString = false;
      continue;
    }
    if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > limit) return deepest;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

}  // namespace sg::viewer
