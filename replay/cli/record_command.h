// `simgrass record`: run a scenario (its script or an input track) and stream a `.sgr` recording.
#pragma once

#include <CLI/CLI.hpp>

namespace sg {
void addRecordCommand(CLI::App& app, int* exitCode);
}
