#include "viewer/app/options.h"

#include "replay/cli/option_checks.h"
#include "viewer/app/text.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace sg::viewer {
namespace {
/// "WxH" with both from 64 to 8192 (a window the renderer and llvmpipe can handle).
bool parseSize(const std::string& s, int* w, int* h) {
  const size_t x = s.find('x');
  if (x == std::string::npos || x == 0 || x + 1 >= s.size()) return false;
  char* end = nullptr;
  *w = int(std::strtol(s.c_str(), &end, 10));
  if (end != s.c_str() + x) return false;
  *h = int(std::strtol(s.c_str() + x + 1, &end, 10));
  if (end != s.c_str() + s.size()) return false;
  return *w >= 64 && *h >= 64 && *w <= 8192 && *h <= 8192;
}
}  // namespace

int parseOptions(int argc, char** argv, Options* o) {
  CLI::App app("simgrass-viewer: the interactive SimGrass viewer (docs/viewer.md)");
  app.add_option("input", o->input,
                 "Scenario JSON, or a recording (.sgr, by extension or magic) to play back "
                 "(default: the built-in thesis meadow)");
  app.add_option("--script", o->script, "Run a test script (frame-locked: one frame per tick)");
  app.add_option("--record", o->record, "Record the session from its first tick to this .sgr");
  app.add_option("--ab", o->abFile, "A/B mode: compare the recording with this second recording");
  app.add_option(
      "--ab-variant", o->abVariant,
      "A/B mode: compare the recording with itself re-simulated under these settings (interp=2, dt=1/120, ...)");
  app.add_option("--frames", o->frames, "Quit after N frames")->check(CLI::NonNegativeNumber);
  app.add_option("--size", o->size, "Window size WxH (default 1280x720)");
  app.add_option("--msaa", o->msaa, "Samples per pixel: 0 (alpha test) or 2/4/8 (alpha to coverage; default 4)")
      ->check(CLI::IsMember({0, 2, 4, 8}));
  app.add_flag("--no-scenario-input", o->noScenarioInput, "Do not play the scenario's scripted body commands");
  app.add_flag("--keep-open-on-error", o->keepOpenOnError,
               "A bad input file opens the window anyway (built-in meadow) and shows the error there");
  app.add_option("--threads", o->threads, "Simulation worker threads")->check(CLI::Range(1, 256));
  app.add_option("--physics", o->physics,
                 "Where the grass stages run (a live scenario or a recording): cpu, gpu (compute shaders in the "
                 "window's context; "
                 "the tufts are drawn from the device's buffers, nothing copied back) or gpu-readback "
                 "(docs/gpu-physics.md)")
      ->check(CLI::IsMember({"cpu", "gpu", "gpu-readback"}));
  app.add_option("--config-dir", o->configDir,
                 "Folder of the settings kept between runs (viewer.json, imgui.ini); default "
                 "$XDG_CONFIG_HOME/simgrass or ~/.config/simgrass, none for --script runs");
  app.add_flag("--keys", o->keys, "Print every key and mouse control (the F1 help) and exit");
  app.footer("Exit codes: 0 ok, 1 no window / OpenGL, simulation fault or I/O error, 2 bad input.");
  sg::refuseEmptyValues(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "simgrass-viewer: %s\n", e.what());
    return kExitBadInput;
  }
  if (!parseSize(o->size, &o->width, &o->height)) {
    std::fprintf(stderr, "simgrass-viewer: --size: expected WxH with both from 64 to 8192, got '%s'\n",
                 shownText(o->size).c_str());
    return kExitBadInput;
  }
  // The window's framebuffer: width x height x samples, bounded like `simgrass render`'s frames.
  const int64_t samples = int64_t(o->width) * int64_t(o->height) * std::max(1, o->msaa);
  if (samples > kMaxWindowSamples) {
    std::fprintf(stderr,
                 "simgrass-viewer: --size, --msaa: expected at most %lld samples (width x height x msaa), got %lld\n",
                 static_cast<long long>(kMaxWindowSamples), static_cast<long long>(samples));
    return kExitBadInput;
  }
  if (!o->abFile.empty() && !o->abVariant.empty()) {
    std::fprintf(stderr, "simgrass-viewer: --ab, --ab-variant: expected one of the two, got both\n");
    return kExitBadInput;
  }
  return -1;
}

}  // namespace sg::viewer
