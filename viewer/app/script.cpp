#include "viewer/app/script.h"

#include <GLFW/glfw3.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "viewer/app/text.h"

namespace sg::viewer {

int scriptKeyCode(const std::string& name) {
  std::string n;
  for (char c : name) n += char(std::tolower(static_cast<unsigned char>(c)));
  if (n.size() == 1 && n[0] >= 'a' && n[0] <= 'z') return GLFW_KEY_A + (n[0] - 'a');
  if (n.size() == 1 && n[0] >= '0' && n[0] <= '9') return GLFW_KEY_0 + (n[0] - '0');
  if (n == "tab") return GLFW_KEY_TAB;
  if (n == "space") return GLFW_KEY_SPACE;
  if (n == "shift") return GLFW_KEY_LEFT_SHIFT;
  if (n == "ctrl") return GLFW_KEY_LEFT_CONTROL;
  if (n == "escape") return GLFW_KEY_ESCAPE;
  if (n == "backspace") return GLFW_KEY_BACKSPACE;
  if (n == "period" || n == ".") return GLFW_KEY_PERIOD;
  if (n == "home") return GLFW_KEY_HOME;
  if (n == "comma" || n == ",") return GLFW_KEY_COMMA;
  if (n == "slash" || n == "/") return GLFW_KEY_SLASH;
  if (n == "pagedown") return GLFW_KEY_PAGE_DOWN;
  if (n == "pageup") return GLFW_KEY_PAGE_UP;
  if (n.size() >= 2 && n.size() <= 3 && n[0] == 'f' && std::isdigit(static_cast<unsigned char>(n[1])) &&
      (n.size() == 2 || std::isdigit(static_cast<unsigned char>(n[2])))) {
    const int f = std::stoi(n.substr(1));
    if (f >= 1 && f <= 12) return GLFW_KEY_F1 + f - 1;
  }
  return -1;
}

namespace {
bool parseCount(const std::string& s, int64_t max, int64_t* v) {
  if (s.empty() || s.size() > 12) return false;
  for (char c : s)
    if (c < '0' || c > '9') return false;
  *v = std::stoll(s);
  return *v <= max;
}

bool parseFloat(const std::string& s, float* v) {
  char* end = nullptr;
  const double d = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(d) || std::fabs(d) > 1e6) return false;
  *v = float(d);
  return true;
}
}  // namespace

bool parseScript(const std::string& text, const std::string& file, std::vector<ScriptCommand>* out,
                 std::string* error) {
  std::istringstream in(text);
  std::string raw;
  int lineNo = 0;
  auto fail = [&](const std::string& what) {
    *error = file + ":" + std::to_string(lineNo) + ": " + what;
    return false;
  };
  while (std::getline(in, raw)) {
    ++lineNo;
    if (!raw.empty() && raw.back() == '\r') raw.pop_back();
    std::istringstream words(raw);
    std::vector<std::string> w;
    for (std::string s; words >> s;) w.push_back(s);
    if (w.empty() || w[0][0] == '#') continue;
    ScriptCommand c;
    c.line = lineNo;
    const std::string& cmd = w[0];
    // The line, quoted for messages: control characters escaped and at most 60 characters of
    // it, so the message stays one short line whatever the script holds.
    const std::string shown = shownText(raw);
    if (cmd == "frames") {
      c.kind = ScriptCommand::Kind::Frames;
      if (w.size() != 2 || !parseCount(w[1], 100000000, &c.count))
        return fail("expected 'frames N' (N from 0 to 100000000), got '" + shown + "'");
    } else if (cmd == "key") {
      c.kind = ScriptCommand::Kind::Key;
      if (w.size() != 3 || (w[2] != "down" && w[2] != "up") || (c.key = scriptKeyCode(w[1])) < 0)
        return fail(
            "expected 'key K down|up' (K: a letter, a digit, tab, space, shift, ctrl, escape, backspace, "
            "period, comma, slash, home, pagedown, pageup or f1..f12), got '" +
            shown + "'");
      c.down = w[2] == "down";
    } else if (cmd == "tap") {
      c.kind = ScriptCommand::Kind::Tap;
      if (w.size() != 2 || (c.key = scriptKeyCode(w[1])) < 0)
        return fail("expected 'tap K' (K: a key name as for 'key'), got '" + shown + "'");
    } else if (cmd == "mouse") {
      c.kind = ScriptCommand::Kind::Mouse;
      bool ok = w.size() == 3 && parseFloat(w[1], &c.camera[0]) && parseFloat(w[2], &c.camera[1]);
      ok = ok && c.camera[0] >= 0 && c.camera[1] >= 0 && c.camera[0] <= 8192 && c.camera[1] <= 8192;
      if (!ok) return fail("expected 'mouse X Y' (window pixels, 0 to 8192), got '" + shown + "'");
    } else if (cmd == "button") {
      c.kind = ScriptCommand::Kind::Button;
      if (w.size() != 3 || (w[1] != "left" && w[1] != "right") || (w[2] != "down" && w[2] != "up"))
        return fail("expected 'button left|right down|up', got '" + shown + "'");
      c.key = w[1] == "left" ? GLFW_MOUSE_BUTTON_LEFT : GLFW_MOUSE_BUTTON_RIGHT;
      c.down = w[2] == "down";
    } else if (cmd == "back") {
      c.kind = ScriptCommand::Kind::Back;
      if (w.size() != 2 || !parseCount(w[1], 100000000, &c.count))
        return fail("expected 'back N' (N from 0 to 100000000), got '" + shown + "'");
    } else if (cmd == "restart") {
      c.kind = ScriptCommand::Kind::Restart;
      if (w.size() != 1) return fail("expected 'restart' alone, got '" + shown + "'");
    } else if (cmd == "camera") {
      c.kind = ScriptCommand::Kind::Camera;
      bool ok = w.size() == 6;
      for (size_t i = 0; ok && i < 5; ++i) ok = parseFloat(w[i + 1], &c.camera[i]);
      if (!ok || std::fabs(c.camera[4]) > 89)
        return fail("expected 'camera x y z yaw pitch' (m, degrees; |pitch| <= 89), got '" + shown + "'");
    } else if (cmd == "select") {
      c.kind = ScriptCommand::Kind::Select;
      if (w.size() != 2 || !parseCount(w[1], 1000000, &c.count))
        return fail("expected 'select N', got '" + shown + "'");
    } else if (cmd == "record" && w.size() == 3 && w[1] == "start") {
      c.kind = ScriptCommand::Kind::RecordStart;
      c.path = w[2];
    } else if (cmd == "record" && w.size() == 2 && w[1] == "stop") {
      c.kind = ScriptCommand::Kind::RecordStop;
    } else if (cmd == "record") {
      return fail("expected 'record start PATH' or 'record stop', got '" + shown + "'");
    } else if (cmd == "screenshot") {
      c.kind = ScriptCommand::Kind::Screenshot;
      if (w.size() != 2) return fail("expected 'screenshot PATH', got '" + shown + "'");
      c.path = w[1];
    } else if (cmd == "quit") {
      c.kind = ScriptCommand::Kind::Quit;
      if (w.size() != 1) return fail("expected 'quit', got '" + shown + "'");
    } else if (cmd == "play" || cmd == "pause" || cmd == "regenerate" || cmd == "print" || cmd == "status") {
      c.kind = cmd == "play"         ? ScriptCommand::Kind::Play
               : cmd == "pause"      ? ScriptCommand::Kind::Pause
               : cmd == "regenerate" ? ScriptCommand::Kind::Regenerate
               : cmd == "print"      ? ScriptCommand::Kind::Print
                                     : ScriptCommand::Kind::Status;
      if (w.size() != 1)
        return fail(std::string("expected '").append(cmd).append("' alone, got '").append(shown).append("'"));
    } else if (cmd == "step") {
      c.kind = ScriptCommand::Kind::Step;
      if (w.size() != 2 || !parseCount(w[1], 100000000, &c.count))
        return fail("expected 'step N' (N from 0 to 100000000), got '" + shown + "'");
    } else if (cmd == "seek") {
      c.kind = ScriptCommand::Kind::Seek;
      if (w.size() != 2 || !parseCount(w[1], 1000000000000, &c.count))
        return fail("expected 'seek T' (a tick >= 0), got '" + shown + "'");
    } else if (cmd == "speed") {
      c.kind = ScriptCommand::Kind::Speed;
      float v = 0;
      if (w.size() != 2 || !parseFloat(w[1], &v) || v < 0.25f || v > 8.0f)
        return fail("expected 'speed X' (X from 0.25 to 8), got '" + shown + "'");
      c.number = v;
    } else if (cmd == "ab") {
      c.kind = ScriptCommand::Kind::AbView;
      if (w.size() != 2 || (w[1] != "side" && w[1] != "overlay"))
        return fail("expected 'ab side' or 'ab overlay', got '" + shown + "'");
      c.count = w[1] == "overlay";
    } else if (cmd == "physics") {
      c.kind = ScriptCommand::Kind::Physics;
      if (w.size() != 2 || (w[1] != "cpu" && w[1] != "gpu" && w[1] != "gpu-readback"))
        return fail("expected 'physics cpu', 'physics gpu' or 'physics gpu-readback', got '" + shown + "'");
      c.count = w[1] == "cpu" ? 0 : w[1] == "gpu" ? 1 : 2;
    } else if (cmd == "lod") {
      c.kind = ScriptCommand::Kind::Lod;
      if (w.size() != 2 || (w[1] != "on" && w[1] != "off"))
        return fail("expected 'lod on' or 'lod off', got '" + shown + "'");
      c.count = w[1] == "on";
    } else if (cmd == "open") {
      c.kind = ScriptCommand::Kind::Open;
      if (w.size() != 2)
        return fail("expected 'open PATH' (a scenario .json or a recording .sgr), got '" + shown + "'");
      c.path = w[1];
    } else if (cmd == "set") {
      c.kind = ScriptCommand::Kind::Set;
      if (w.size() < 3) return fail("expected 'set PATH VALUE' (e.g. 'set field.patchesX 41'), got '" + shown + "'");
      c.path = w[1];
      const size_t at = raw.find(w[1], raw.find("set") + 3) + w[1].size();
      c.value = raw.substr(at);
      c.value.erase(0, c.value.find_first_not_of(" \t"));
      c.value.erase(c.value.find_last_not_of(" \t") + 1);
    } else {
      return fail("unknown command '" + shown +
                  "' (expected frames, key, tap, mouse, button, camera, select, record, screenshot, quit, play, "
                  "pause, step, back, restart, seek, speed, ab, open, set, regenerate, lod, physics, print or status)");
    }
    out->push_back(c);
  }
  return true;
}

}  // namespace sg::viewer
