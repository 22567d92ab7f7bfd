// `simgrass compare`: replay a recording's inputs under variant settings and measure each
// variant's cost and error against the recording's own settings.
#pragma once

#include <CLI/CLI.hpp>

namespace sg {
void addCompareCommand(CLI::App& app, int* exitCode);
}
