// `simgrass render` in a build without the viewer (SIMGRASS_BUILD_VIEWER=OFF): the command stays
// in `simgrass --help` so that scripts and users learn why it does nothing, and running it prints
// one line and exits 2 (bad input, like any command this build cannot run).
#include <cstdio>

#include "replay/cli/cli_common.h"
#include "replay/cli/render_hook.h"

namespace sg {
void addRenderCommand(CLI::App& app, int* exitCode) {
  CLI::App* cmd = app.add_subcommand(
      "render", "Render frames of a scenario run or a .sgr replay to PNG (needs a build with the viewer)");
  // Whatever follows `render` (a scenario, -o, --ticks, ...) is accepted unread: the answer is the
  // same one line for every argument list, never a parse error about an option this stub lacks.
  cmd->prefix_command();
  cmd->callback([exitCode] {
    std::fprintf(stderr, "simgrass render: this build has no viewer (configure with -DSIMGRASS_BUILD_VIEWER=ON)\n");
    *exitCode = kExitBadInput;
  });
}
}  // namespace sg
