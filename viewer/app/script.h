// The viewer's test script (`simgrass-viewer --script FILE`, docs/viewer.md): one command a line,
// parsed up front so a bad line fails before any window opens. With a script the run is
// frame-locked: exactly one simulation tick per rendered frame.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace sg::viewer {

struct ScriptCommand {
  enum class Kind {
    Frames,
    Key,
    Camera,
    Select,
    RecordStart,
    RecordStop,
    Screenshot,
    Quit,
    // playback (a .sgr is open)
    Play,
    Pause,
    Step,
    Seek,
    Speed,
    AbView,
    // files, panels, output
    Open,
    Set,
    Regenerate,
    Lod,
    Print,
    Status,
    // input and live control
    Tap,      ///< tap K: press and release within one frame
    Mouse,    ///< mouse X Y: the cursor at window pixel (X, Y)
    Button,   ///< button left|right down|up
    Back,     ///< back N: step N ticks back (live: through the history; playback: seek)
    Restart,  ///< restart: the live session back to tick 0 (Home)
    Physics,  ///< physics cpu|gpu|gpu-readback: where the live world's grass stages run (count: PhysicsPath)
  } kind = Kind::Quit;
  int64_t count = 0;  ///< frames N; select N; step N; seek T; lod 1|0; ab 0 (side) | 1 (overlay)
  double number = 0;  ///< speed X
  int key = 0;        ///< GLFW key code (key K down|up, tap K) or mouse button (button)
  bool down = false;
  float camera[5] = {0, 0, 0, 0, 0};  ///< x y z yaw pitch; mouse: x y
  std::string path;                   ///< record start PATH; screenshot PATH; open PATH; set PATH (dotted JSON path)
  std::string value;                  ///< set PATH VALUE (JSON text)
  int line = 0;                       ///< 1-based line in the script file
};

/// GLFW key code of a script key name: a letter or digit (case-insensitive), or tab, space,
/// shift, ctrl, escape, backspace, period (or "."), comma (or ","), slash (or "/"), home,
/// pagedown, pageup, f1 ... f12. -1 when unknown.
int scriptKeyCode(const std::string& name);

/// Parses script text. Blank lines and lines starting with '#' are skipped. On an error returns
/// false with *error = "FILE:LINE: what" (one line).
bool parseScript(const std::string& text, const std::string& file, std::vector<ScriptCommand>* out, std::string* error);

}  // namespace sg::viewer
