// `simgrass render`: run a scenario (or replay a `.sgr` recording) and write PNG frames of chosen
// ticks, rendered offscreen (OSMesa); optionally a contact sheet and a video (docs/rendering.md).
#pragma once

#include <CLI/CLI.hpp>

namespace sg {
void addRenderCommand(CLI::App& app, int* exitCode);
}
