// simgrass-viewer: the interactive host (docs/viewer.md). main() only parses the command line,
// reads the script, opens the input (a scenario, or a recording to play back, optionally A/B)
// and hands everything to App (app.h), which owns the window and the frame loop.
#include <csignal>
#include <cstdio>

#include "replay/input_file.h"
#include "replay/kernel_environment.h"
#include "replay/physics_devices.h"
#include "viewer/app/app.h"
#include "viewer/app/keys.h"

namespace {
/// The GPU physics provider before the window exists: none. The viewer runs the device in its
/// window's own context (App::open registers it), so a world asking earlier (a recording's
/// `--ab-variant physics=gpu`) is told where the GPU path is.
std::unique_ptr<sg::ParticleDeviceProvider> noDeviceBeforeTheWindow(std::string* error) {
  *error =
      "the viewer's device lives in its window's context, made after the inputs are read: play the recording "
      "there with --physics gpu (`simgrass compare R.sgr --variant physics=gpu` compares the two paths)";
  return nullptr;
}
}  // namespace

int main(int argc, char** argv) {
  using namespace sg;
  using namespace sg::viewer;
  // As simgrass: a file-size limit (ulimit -f) is a failed write the viewer reports (a screenshot,
  // a recording), not SIGXFSZ killing it with a temporary file left behind.
  std::signal(SIGXFSZ, SIG_IGN);
  if (!applyKernelEnvironment()) {
    std::fprintf(stderr, "simgrass-viewer: SIMGRASS_KERNEL: expected scalar, avx2 or auto\n");
    return kExitBadInput;
  }
  Options o;
  if (const int code = parseOptions(argc, argv, &o); code >= 0) return code;
  if (o.keys) {  // the F1 help as docs/viewer.md's Controls table (tests compare the two)
    std::printf("| Keys | What |\n|------|------|\n");
    for (const KeyHelp& k : kKeyHelp) std::printf("| %s | %s |\n", k.keys, k.what);
    return kExitOk;
  }
  std::vector<ScriptCommand> script;
  if (!o.script.empty()) {
    // The bounded reader: a FIFO or /dev/zero is refused at once, a huge file before any read.
    std::string text, expected;
    if (!readInputFile(o.script, InputLimits::kScriptBytes, &text, &expected)) {
      std::fprintf(stderr, "simgrass-viewer: %s: expected %s\n", o.script.c_str(), expected.c_str());
      return kExitBadInput;
    }
    std::string error;
    if (!parseScript(text, o.script, &script, &error)) {
      std::fprintf(stderr, "simgrass-viewer: %s\n", error.c_str());
      return kExitBadInput;
    }
  }
  // The input: a recording plays back (A/B with --ab / --ab-variant); anything else is a
  // scenario. A bad file is the CLI's one line: exit 2, or with --keep-open-on-error the window
  // opens on the built-in meadow with that line in its error window.
  std::unique_ptr<Session> live;
  std::unique_ptr<Playback> playback;
  std::string startupError;
  const bool recording = !o.input.empty() && looksLikeRecording(o.input);
  registerGpuPhysics(&noDeviceBeforeTheWindow);
  try {
    if (recording && !o.record.empty())
      throw std::invalid_argument("--record: expected a scenario to record, got the recording '" + o.input + "'");
    if (recording) {
      playback = Playback::open(o.input, o.threads);
      if (!o.abFile.empty()) playback->attachRecording(o.abFile);
      if (!o.abVariant.empty()) playback->attachVariant(o.abVariant);
    } else if (!o.abFile.empty() || !o.abVariant.empty()) {
      throw std::invalid_argument("--ab, --ab-variant: expected a recording (.sgr) as the input, got '" +
                                  (o.input.empty() ? std::string("<built-in>") : o.input) + "'");
    }
    live = Session::load(recording ? std::string() : o.input, o.threads);
  } catch (const std::exception& e) {  // ScenarioError, sgr::RecordingError, bad variant
    if (!o.keepOpenOnError) {
      std::fprintf(stderr, "simgrass-viewer: %s\n", e.what());
      return kExitBadInput;
    }
    std::fprintf(stderr, "simgrass-viewer: %s\n", e.what());
    startupError = e.what();
    playback.reset();
    try {
      live = Session::load("", o.threads);
    } catch (const std::exception& e2) {
      std::fprintf(stderr, "simgrass-viewer: %s\n", e2.what());
      return kExitBadInput;
    }
  }
  App app(o, std::move(live), std::move(playback));
  return app.run(o.script.empty() ? nullptr : &script, startupError);
}
