// `simgrass render`'s registration, declared here so that main.cpp can call it without seeing the
// viewer: replay/ never includes viewer/ (docs/architecture.md, "Layers"). Exactly one definition
// is linked into the `simgrass` executable, chosen by the top-level CMakeLists.txt:
//   * viewer/cli/render_command.cpp (library simgrass_render_command) when SIMGRASS_BUILD_VIEWER
//     is on: runs a scenario or replays a `.sgr` and writes PNG frames rendered offscreen (OSMesa);
//   * replay/cli/render_unavailable.cpp (library simgrass_render_unavailable) when it is off: the
//     command is still listed, and running it says in one line that this build has no viewer.
#pragma once

#include <CLI/CLI.hpp>

namespace sg {
/// Adds the `render` subcommand to `app`; its callback stores the command's exit code in *exitCode.
void addRenderCommand(CLI::App& app, int* exitCode);
}  // namespace sg
