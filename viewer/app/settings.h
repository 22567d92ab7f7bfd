// What the viewer remembers between runs: the app's own settings (camera speed, visuals, panels,
// recent files) in DIR/viewer.json and Dear ImGui's window layout in DIR/imgui.ini, DIR being
// --config-dir, else $XDG_CONFIG_HOME/simgrass, else ~/.config/simgrass. Scripted runs (tests)
// read and write nothing unless --config-dir names a folder, so they never depend on the user's.
#pragma once

#include <string>
#include <vector>

namespace sg::viewer {

struct ViewerSettings {
  float walkSpeed = 4.0f;  ///< m/s
  bool freeCamera = false;
  bool alphaToCoverage = true, ssao = false, rockBlend = true, interpolate = true;
  bool uiHidden = false;            ///< F2
  bool showTiming = true;           ///< the per-frame stage graph
  std::vector<std::string> recent;  ///< files opened, newest first (at most kMaxRecent)
  static constexpr size_t kMaxRecent = 10;

  /// Puts `path` first in the recent list (once), dropping the oldest beyond kMaxRecent.
  void remember(const std::string& path);
};

/// $XDG_CONFIG_HOME/simgrass or $HOME/.config/simgrass; empty when neither variable is set.
std::string defaultConfigDir();

/// Reads DIR/viewer.json. A missing file is the defaults; a damaged one (not JSON, a wrong type,
/// a file over 1 MiB) is the defaults too, with *warning set to one line naming the file and what
/// was expected. Unknown keys are ignored (a newer viewer's settings still load).
ViewerSettings loadSettings(const std::string& dir, std::string* warning);

/// Writes DIR/viewer.json atomically (the folder is created). False with *error (one line).
bool saveSettings(const std::string& dir, const ViewerSettings& settings, std::string* error);

}  // namespace sg::viewer
