// The viewer's command line (docs/viewer.md). Parsed with CLI11 before any window opens so a bad
// argument is one line and exit 2 without a display.
#pragma once

#include <cstdint>
#include <string>

namespace sg::viewer {

inline constexpr int kExitOk = 0, kExitFailure = 1, kExitBadInput = 2;

/// Samples the window's framebuffer may have (width x height x max(1, msaa)): 8192x8192 without
/// MSAA, 4096x4096 at 4x (docs/viewer.md "Limits").
inline constexpr int64_t kMaxWindowSamples = int64_t(1) << 26;

struct Options {
  std::string input;  ///< scenario JSON or recording (.sgr); empty: the built-in thesis meadow
  std::string script, record, size = "1280x720";
  std::string abFile;     ///< --ab B.sgr: a second recording to compare with
  std::string abVariant;  ///< --ab-variant SETTINGS: the same recording under a VariantSettings
  int64_t frames = -1;
  std::string physics = "cpu";  ///< --physics: where the grass stages run (live or playback)
  int threads = 1;
  int msaa = 4;
  bool noScenarioInput = false;
  bool keepOpenOnError = false;    ///< a bad input file opens the window with the error shown
  std::string configDir;           ///< --config-dir: settings and ImGui layout (settings.h)
  bool keys = false;               ///< --keys: print the key table and exit
  int width = 1280, height = 720;  ///< parsed from `size`
};

/// Parses argv. Returns -1 to go on, else the exit code (0 after --help, 2 with the error line
/// already printed to stderr).
int parseOptions(int argc, char** argv, Options* out);

}  // namespace sg::viewer
