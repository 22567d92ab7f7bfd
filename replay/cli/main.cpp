// simgrass: the SimGrass testbed's command-line tool.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>

#include "replay/cli/compare_command.h"
#include "replay/cli/diff_command.h"
#include "replay/cli/record_command.h"
#include "replay/cli/render_hook.h"
#include "replay/cli/replay_command.h"
#include "replay/cli/run_command.h"
#include "replay/cli/sweep_command.h"
#include "replay/kernel_environment.h"

int main(int argc, char** argv) {
  CLI::App app{"SimGrass: deterministic fixed-point grass physics testbed", "simgrass"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("simgrass ") + SIMGRASS_VERSION);
  if (!sg::applyKernelEnvironment()) {
    std::fprintf(stderr, "simgrass: SIMGRASS_KERNEL: expected scalar, avx2 or auto\n");
    return 2;
  }
  int exitCode = 0;
  sg::addRunCommand(app, &exitCode);
  sg::addRecordCommand(app, &exitCode);
  sg::addReplayCommand(app, &exitCode);
  sg::addDiffCommand(app, &exitCode);
  sg::addCompareCommand(app, &exitCode);
  sg::addSweepCommand(app, &exitCode);
  sg::addRenderCommand(app, &exitCode);  // the viewer's, or a stub in a build without it
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, non-zero: the command-line counterpart of a bad scenario.
    std::fprintf(stderr, "simgrass: %s (see 'simgrass --help')\n", e.what());
    return 2;
  }
  return exitCode;
}
