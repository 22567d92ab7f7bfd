// `simgrass replay`: play a `.sgr` recording back; verify every hash, seek, export a state.
#pragma once

#include <CLI/CLI.hpp>

namespace sg {
void addReplayCommand(CLI::App& app, int* exitCode);
}
