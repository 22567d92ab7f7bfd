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

/// Every option that takes a value, of the app and its subcommands, refuses an empty one: no
/// option means anything by '' (a file, a list, a number), and `--export-state ''`, `--csv ''`
/// or `record --input ''` ran as if the option were absent, exit 0 (an independent pass,
/// 2026-11-28). Called once the commands are built, so an option added later is covered too.
/// As a transform (CLI11 runs those first), so the message is the same for every option rather
/// than "--scalar:  not in {...}" from a set check; it changes nothing it passes.
inline void refuseEmptyValues(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) refuseEmptyValues(*sub);
  for (CLI::Option* opt : app.get_options([](CLI::Option*) { return true; }))
    if (opt->get_type_size_max() > 0) opt->transform(nonEmptyValue("a value", ""));  // not the flags
}

}  // namespace sg
