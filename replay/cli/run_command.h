// `simgrass run`: run a scenario headless, print the final state hash, per-stage timings and
// counts (text or --json).
#pragma once

#include <CLI/CLI.hpp>

namespace sg {
void addRunCommand(CLI::App& app, int* exitCode);
}
