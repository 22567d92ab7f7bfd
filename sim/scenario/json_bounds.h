// Bounds for untrusted JSON: a nesting-depth check that runs on the text BEFORE any DOM is built,
// and a bounded echo of a value for one-line error messages. Pure functions, no I/O; used by the
// scenario and input-track parsers and meant for any other reader of user JSON (the viewer's
// `set` command and scripts).
//
// Why: nlohmann::json builds arbitrarily deep documents without trouble, but json::dump() (and
// any other recursive walk) recurses once per level, so echoing a value 100000 levels deep
// overflows the stack. A depth limit applied to the text, plus an echo that never recurses past
// a few levels and never writes more than a few dozen characters, closes that for good.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

namespace sg {

/// The deepest nesting of arrays and objects accepted in any user JSON (scenario, input track,
/// viewer script). The deepest scenario value needs 8 levels ($.bodies.list[i].shape.parts[k].offset).
inline constexpr int kMaxJsonDepth = 64;

/// How many characters of a value an error message echoes (then "...").
inline constexpr size_t kEchoChars = 60;

/// The byte offset (0-based) of the first '[' or '{' that opens nesting level maxDepth + 1, or
/// nullopt when the text never nests deeper than maxDepth. Brackets inside strings do not count.
/// Works on any text (valid JSON or not) in one pass, without recursion or allocation.
std::optional<size_t> findExcessNesting(std::string_view text, int maxDepth = kMaxJsonDepth);

/// The nesting depth of a DOM value (a scalar is 0, [] is 1, [[1]] is 2), computed without
/// recursion and stopping once it exceeds `limit` (returns limit + 1 then).
int jsonDepth(const nlohmann::json& value, int limit = kMaxJsonDepth);

/// `text` with every control character escaped (\n, \r, \t, \xNN; also DEL, the C1 controls and
/// the bidirectional formatting characters such as U+202E, byte by byte)
/// and every byte that is not valid UTF-8 as \xNN, whole: what a
/// one-line message prints of a file name or an error text, so that a newline cannot split it.
std::string escapeControl(std::string_view text);

/// `text` with every control character escaped (\n, \r, \t, \xNN; also DEL), cut to at most
/// `maxChars` characters of the original followed by "..." when longer. Never splits a line.
std::string echoText(std::string_view text, size_t maxChars = kEchoChars);

/// A short, one-line rendering of a JSON value for an error message: compact JSON, cut to about
/// `maxChars` characters (then "..."), control characters escaped. Bounded in time, memory and
/// stack whatever the value's size or depth (it never calls json::dump on a container).
std::string echoValue(const nlohmann::json& value, size_t maxChars = kEchoChars);

}  // namespace sg
