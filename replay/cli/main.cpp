// simgrass: the SimGrass testbed's command-line tool.
#include <CLI/CLI.hpp>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>

#include "replay/cli/cli_common.h"

#include "replay/cli/compare_command.h"
#include "replay/cli/diff_command.h"
#include "replay/cli/gpu_hook.h"
#include "replay/cli/option_checks.h"
#include "replay/cli/record_command.h"
#include "replay/cli/render_hook.h"
#include "replay/cli/replay_command.h"
#include "replay/cli/run_command.h"
#include "replay/cli/sweep_command.h"
#include "replay/kernel_environment.h"
#include "sim/scenario/json_bounds.h"
#include "sim/world/chunk_pool.h"

namespace {
/// The subcommand being run ("replay"), or "" before one was parsed.
std::string commandName(const CLI::App& app) {
  for (const CLI::App* sub : app.get_subcommands()) return sub->get_name();
  return "";
}

/// Integer options read as decimal: CLI11 reads "010" as octal 8 and "0x10" as 16, a silently
/// different run. Every integer option of every subcommand gets a transform, run before its
/// range check, that keeps an optional sign and decimal digits (leading zeros dropped, so
/// "010" is 10) and refuses anything else.
void makeIntegerOptionsDecimal(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) makeIntegerOptionsDecimal(*sub);
  for (CLI::Option* opt : app.get_options([](CLI::Option*) { return true; })) {
    const std::string type = opt->get_type_name();
    if (type.rfind("INT", 0) != 0 && type.rfind("UINT", 0) != 0) continue;
    opt->transform(CLI::Validator(
        [](std::string& value) -> std::string {
          size_t i = value.empty() || (value[0] != '-' && value[0] != '+') ? 0 : 1;
          const size_t digits = i;
          bool ok = i < value.size();
          for (size_t k = i; k < value.size(); ++k) ok = ok && value[k] >= '0' && value[k] <= '9';
          if (!ok) return "expected a decimal integer, got '" + sg::echoText(value) + "'";
          while (i + 1 < value.size() && value[i] == '0') ++i;
          value = value.substr(0, digits) + value.substr(i);
          return "";
        },
        "", "decimal"));
  }
}
}  // namespace

int main(int argc, char** argv) {
  // A file-size limit (ulimit -f) must be a failed write that the command reports, not SIGXFSZ
  // killing it half-way through an output.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"SimGrass: deterministic fixed-point grass physics testbed", "simgrass"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("simgrass ") + SIMGRASS_VERSION);
  if (!sg::applyKernelEnvironment()) {
    sg::printError("simgrass: SIMGRASS_KERNEL: expected scalar, avx2 or auto");
    return 2;
  }
  sg::registerBuildGpuPhysics();  // `--physics gpu`: sim/gpu's devices, or none in a build without GL
  int exitCode = 0;
  sg::addRunCommand(app, &exitCode);
  sg::addRecordCommand(app, &exitCode);
  sg::addReplayCommand(app, &exitCode);
  sg::addDiffCommand(app, &exitCode);
  sg::addCompareCommand(app, &exitCode);
  sg::addSweepCommand(app, &exitCode);
  sg::addRenderCommand(app, &exitCode);  // the viewer's, or a stub in a build without it
  makeIntegerOptionsDecimal(app);
  sg::refuseEmptyValues(app);
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
    // CLI11 echoes option values whole: cut, so a 5000-character value is not a 5000-byte line.
    sg::printError("simgrass: %s (see 'simgrass --help')", sg::echoText(e.what(), 240).c_str());
    return 2;
  } catch (const sg::ThreadStartError& e) {
    // --threads larger than the machine lets this process start (ulimit -u, address space).
    const std::string cmd = commandName(app);
    sg::printError("simgrass%s%s: %s", cmd.empty() ? "" : " ", cmd.c_str(), e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    // Last resort: every input is bounded before it is allocated for, so this is a bug (or a
    // machine out of memory); still one line and a clean exit, never an abort.
    const std::string cmd = commandName(app);
    sg::printError("simgrass%s%s: internal error: out of memory", cmd.empty() ? "" : " ", cmd.c_str());
    return 2;
  } catch (const std::exception& e) {
    const std::string cmd = commandName(app);
    sg::printError("simgrass%s%s: internal error: %s", cmd.empty() ? "" : " ", cmd.c_str(), e.what());
    return 2;
  }
  // What the command printed must have reached its destination: `--json > file` on a full disk
  // is a failed command, not a truncated file and exit 0.
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    const int err = errno;
    const std::string cmd = commandName(app);
    sg::printError("simgrass%s%s: standard output: cannot write (%s)", cmd.empty() ? "" : " ", cmd.c_str(),
                   std::strerror(err));
    return exitCode != 0 ? exitCode : 2;
  }
  return exitCode;
}
