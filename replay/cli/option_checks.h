// Checks shared by the commands' options, as CLI11 validators.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace sg {

/// Refuses an empty value where one is required: `--variant ''` and `--camera ''` ran with the
/// defaults (an independent pass). `form` is what a value looks like ("KEY=VALUE"), `name` the
/// validator's name in --help.
inline CLI::Validator nonEmptyValue(const std::string& form, const std::string& name) {
  return CLI::Validator(
      [form](std::string& v) { return v.empty() ? "expected " + form + " (got an empty value)" : std::string(); },
      name);
}

}  // namespace sg
