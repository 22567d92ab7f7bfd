// `simgrass diff`: replay two recordings side by side and measure how far apart they are.
#pragma once

#include <CLI/CLI.hpp>

namespace sg {
void addDiffCommand(CLI::App& app, int* exitCode);
}
