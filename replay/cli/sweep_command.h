// `simgrass sweep`: every variant (scalar x interpolation x time step x level of detail) of a few
// fixed scenarios against a double-precision reference: cost per simulated second against tuft-tip
// and body error, as CSV, JSON and PNG plots with the Pareto front (docs/diff-and-compare.md).
#pragma once

#include <CLI/CLI.hpp>

namespace sg {
void addSweepCommand(CLI::App& app, int* exitCode);
}
