#include "sim/scenario/json_bounds.h"

#include <cstdio>
#include <utility>
#include <vector>

namespace sg {
namespace {
using json = nlohmann::json;

/// Cuts `s` to at most `n` bytes without splitting a UTF-8 sequence.
size_t cutPoint(std::string_view s, size_t n) {
  if (s.size() <= n) return s.size();
  while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;
  return n;
}

/// The length of the valid UTF-8 sequence at s[i] (2 to 4), or 0 when the bytes there are not
/// one (a stray continuation byte, a cut sequence, an overlong form, a surrogate, > U+10FFFF).
size_t utf8SequenceAt(std::string_view s, size_t i) {
  const auto b = [&](size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char lead = b(i);
  const size_t n = lead >= 0xF0 ? 4 : lead >= 0xE0 ? 3 : lead >= 0xC2 ? 2 : 0;
  if (n == 0 || lead > 0xF4 || i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k)
    if ((b(i + k) & 0xC0) != 0x80) return 0;
  if (n == 3 && lead == 0xE0 && b(i + 1) < 0xA0) return 0;   // overlong
  if (n == 3 && lead == 0xED && b(i + 1) >= 0xA0) return 0;  // a UTF-16 surrogate
  if (n == 4 && lead == 0xF0 && b(i + 1) < 0x90) return 0;   // overlong
  if (n == 4 && lead == 0xF4 && b(i + 1) >= 0x90) return 0;  // beyond U+10FFFF
  return n;
}

void appendByte(std::string& out, unsigned char c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "\\x%02x", c);
  out += buf;
}

// Escapes what a terminal or a log would act on or mangle: C0 controls and DEL, the C1 controls
// U+0080..U+009F (U+009B is a CSI on some terminals), and bytes that are not valid UTF-8.
/// Whether the UTF-8 sequence is a bidirectional formatting character: U+061C, U+200E, U+200F,
/// U+202A to U+202E and U+2066 to U+2069. They reorder the text printed after them (a scenario
/// named with U+202E, right-to-left override, reversed the rest of its error line: an independent
/// pass), so they are escaped as the controls are.
bool isBidiControl(std::string_view seq) {
  const auto b = [&](size_t k) { return static_cast<unsigned char>(seq[k]); };
  if (seq.size() == 2) return b(0) == 0xD8 && b(1) == 0x9C;
  if (seq.size() != 3 || b(0) != 0xE2) return false;
  if (b(1) == 0x80) return b(2) == 0x8E || b(2) == 0x8F || (b(2) >= 0xAA && b(2) <= 0xAE);
  return b(1) == 0x81 && b(2) >= 0xA6 && b(2) <= 0xA9;
}

void appendEscaped(std::string& out, std::string_view s) {
  for (size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    size_t n = 1;  // bytes consumed
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c < 0x20 || c == 0x7f) {
      appendByte(out, c);
    } else if (c < 0x80) {
      out += char(c);
    } else if ((n = utf8SequenceAt(s, i)) == 0) {
      appendByte(out, c);  // not UTF-8: this byte alone, then resynchronise on the next
      n = 1;
    } else if (n == 2 && c == 0xC2 && static_cast<unsigned char>(s[i + 1]) < 0xA0) {
      appendByte(out, c);  // a C1 control
      appendByte(out, static_cast<unsigned char>(s[i + 1]));
    } else if (isBidiControl(s.substr(i, n))) {
      for (size_t k = 0; k < n; ++k) appendByte(out, static_cast<unsigned char>(s[i + k]));
    } else {
      out.append(s.substr(i, n));
    }
    i += n;
  }
}

/// Writes a compact rendering of v into out until out holds more than `budget` bytes. Recursion
/// is bounded by kEchoLevels (deeper containers print as [...] / {...}).
constexpr int kEchoLevels = 8;
void render(const json& v, std::string& out, size_t budget, int level) {
  if (out.size() > budget) return;
  switch (v.type()) {
    case json::value_t::string: {
      const auto& s = v.get_ref<const json::string_t&>();
      out += '"';
      appendEscaped(out, std::string_view(s).substr(0, cutPoint(s, budget + 1)));
      if (s.size() <= budget) out += '"';
      return;
    }
    case json::value_t::array:
    case json::value_t::object: {
      const bool array = v.is_array();
      if (level >= kEchoLevels) {
        out += array ? "[...]" : "{...}";
        return;
      }
      out += array ? '[' : '{';
      bool first = true;
      for (auto it = v.begin(); it != v.end(); ++it) {
        if (out.size() > budget) return;
        if (!first) out += ',';
        first = false;
        if (!array) {
          out += '"';
          appendEscaped(out, std::string_view(it.key()).substr(0, cutPoint(it.key(), budget + 1)));
          out += "\":";
        }
        render(*it, out, budget, level + 1);
      }
      out += array ? ']' : '}';
      return;
    }
    case json::value_t::binary:
      out += "<binary>";
      return;
    case json::value_t::discarded:
      out += "<discarded>";
      return;
    default:
      out += v.dump();  // a number, a boolean or null: a short token
      return;
  }
}
}  // namespace

std::string escapeControl(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  appendEscaped(out, text);
  return out;
}

std::optional<size_t> findExcessNesting(std::string_view text, int maxDepth) {
  int depth = 0;
  bool inString = false, escaped = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
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
      if (++depth > maxDepth) return i;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return std::nullopt;
}

int jsonDepth(const json& value, int limit) {
  // Depth-first with an explicit stack of (value, depth): no recursion.
  int deepest = 0;
  std::vector<std::pair<const json*, int>> stack{{&value, 0}};
  while (!stack.empty()) {
    const auto [v, d] = stack.back();
    stack.pop_back();
    if (!v->is_structured()) continue;
    if (d + 1 > deepest) deepest = d + 1;
    if (deepest > limit) return limit + 1;
    for (const json& child : *v)
      if (child.is_structured()) stack.emplace_back(&child, d + 1);
  }
  return deepest;
}

std::string echoText(std::string_view text, size_t maxChars) {
  std::string out;
  const size_t n = cutPoint(text, maxChars);
  appendEscaped(out, text.substr(0, n));
  if (n < text.size()) out += "...";
  return out;
}

std::string echoValue(const json& value, size_t maxChars) {
  std::string out;
  render(value, out, maxChars, 0);
  if (out.size() > maxChars) {
    out.resize(cutPoint(out, maxChars));
    out += "...";
  }
  return out;
}

}  // namespace sg
