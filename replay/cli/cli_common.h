// Small helpers shared by the `simgrass` subcommands.
#pragma once

#include <cinttypes>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <vector>

#include "replay/input_file.h"
#include "sim/scenario/json_bounds.h"

namespace sg {

/// A 64-bit hash as 16 lower-case hex digits (how every command prints hashes).
inline std::string hex(uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return buf;
}

/// A user-given value as an error message echoes it: at most 60 bytes, then "...".
inline std::string echoed(const std::string& value) { return echoText(value); }

/// Prints one line on stderr: the printf-formatted text (a trailing newline in `format` is
/// optional) with every control character in it escaped, then one newline. Every error and
/// warning line of the commands goes through here.
#if defined(__GNUC__)
__attribute__((format(printf, 1, 2)))
#endif
inline void
printError(const char* format, ...) {
  std::va_list args;
  va_start(args, format);
  std::va_list again;
  va_copy(again, args);
  const int n = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string text(n > 0 ? size_t(n) : 0, '\0');
  if (n > 0) std::vsnprintf(text.data(), text.size() + 1, format, again);
  va_end(again);
  while (!text.empty() && text.back() == '\n') text.pop_back();
  const std::string line = escapeControl(text) + "\n";
  std::fwrite(line.data(), 1, line.size(), stderr);
  std::fflush(stderr);
}

/// True, after one line on stderr, when the output file `output` (given with `option`, e.g.
/// "--export-state") is one of the command's `inputs` (same device and inode: hard links and
/// "./x" spellings included): the command refuses to overwrite its own input.
template <class Inputs>
bool overwritesAnyOf(const char* command, const char* option, const std::string& output, const Inputs& inputs) {
  if (output.empty()) return false;
  for (const std::string& input : inputs) {
    if (input.empty() || !sameFile(input, output)) continue;
    printError("simgrass %s: %s %s: expected an output file other than the input %s (it would be overwritten)", command,
               option, output.c_str(), input.c_str());
    return true;
  }
  return false;
}
inline bool overwritesInput(const char* command, const char* option, const std::string& output,
                            std::initializer_list<std::string> inputs) {
  return overwritesAnyOf(command, option, output, inputs);
}
/// The same for a list of inputs built at run time (a scenario's heightmap and meshes).
inline bool overwritesInput(const char* command, const char* option, const std::string& output,
                            const std::vector<std::string>& inputs) {
  return overwritesAnyOf(command, option, output, inputs);
}

/// True, after one line on stderr, when two output options name the same file (one would
/// silently replace the other).
inline bool sameOutputTwice(const char* command, const char* optionA, const std::string& a, const char* optionB,
                            const std::string& b) {
  // Spelled the same once made absolute and normalised ("./x", "d/../x"), or the same existing file.
  auto normal = [](const std::string& p) {
    std::error_code ec;
    const std::filesystem::path abs = std::filesystem::absolute(p, ec);
    return ec ? std::filesystem::path(p).lexically_normal() : abs.lexically_normal();
  };
  if (a.empty() || b.empty() || !(a == b || normal(a) == normal(b) || sameFile(a, b))) return false;
  printError("simgrass %s: %s %s: expected a file other than the %s output", command, optionB, b.c_str(), optionA);
  return true;
}

/// Exit codes shared by the commands.
enum ExitCode : int {
  kExitOk = 0,
  kExitMismatch = 1,   ///< a simulation fault, a hash mismatch, a variant that had to be identical
  kExitBadInput = 2,   ///< bad command line, scenario, recording or input track
  kExitTruncated = 3,  ///< a recording cut off before END: everything in it checked out
};

}  // namespace sg
