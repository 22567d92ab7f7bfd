// Small helpers shared by the `simgrass` subcommands.
#pragma once

#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <string>

namespace sg {

/// A 64-bit hash as 16 lower-case hex digits (how every command prints hashes).
inline std::string hex(uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return buf;
}

/// Exit codes shared by the commands.
enum ExitCode : int {
  kExitOk = 0,
  kExitMismatch = 1,   ///< a simulation fault, a hash mismatch, a variant that had to be identical
  kExitBadInput = 2,   ///< bad command line, scenario, recording or input track
  kExitTruncated = 3,  ///< a recording cut off before END: everything in it checked out
};

}  // namespace sg
