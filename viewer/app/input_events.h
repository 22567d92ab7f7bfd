// Keyboard and mouse input of the viewer as events, not per-frame polling: GLFW's callbacks put
// every press and release into a queue, so a tap shorter than a frame (2-5 s per frame on
// llvmpipe) is seen; and each event goes to exactly one of ImGui or the app, so a key typed into a
// panel never also drives a body and Tab never moves ImGui's focus while the app selects a body.
//
// Routing (InputRouter::route): a key goes to ImGui while ImGui is using the keyboard (a text
// field or a slider being edited: io.WantTextInput, or an active item); otherwise to the app. Its
// release goes where its press went (no key stuck down on either side). Mouse buttons go to ImGui
// over a panel (io.WantCaptureMouse), else to the app. Characters go to ImGui only while it takes
// text. Scripts feed the same queue (App::runCommand), so tests drive the code the keyboard does.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>

namespace sg::viewer {

/// GLFW's key and button codes are small non-negative ints; anything outside is ignored.
inline constexpr int kKeySlots = 512;
inline constexpr int kMouseButtons = 8;

struct InputEvent {
  enum class Kind : uint8_t { Key, MouseButton } kind = Kind::Key;
  int code = 0;       ///< GLFW key or mouse button
  bool down = false;  ///< press (or repeat) / release
  bool repeat = false;
  int mods = 0;  ///< GLFW_MOD_* bits
};

/// The app's side of the input: the events it was given this frame and which keys are held.
class InputState {
 public:
  /// Applies an event routed to the app (kept in order for the frame's toggles).
  void push(const InputEvent& e);
  /// The events of this frame, oldest first; takeEvents() empties the queue.
  std::deque<InputEvent> takeEvents();
  /// Held now (pressed and not yet released).
  bool down(int key) const { return valid(key) && keys_[size_t(key)]; }
  /// Held at any time during this frame: held now, or pressed since the last endFrame() (a tap
  /// shorter than a frame still drives a body for the frame's ticks).
  bool heldThisFrame(int key) const { return valid(key) && (keys_[size_t(key)] || tapped_[size_t(key)]); }
  bool mouseDown(int button) const { return button >= 0 && button < kMouseButtons && buttons_[size_t(button)]; }
  /// Releases everything (the window lost focus, or a script's world was replaced).
  void releaseAll();
  /// Forgets this frame's taps (call once a frame, after the frame's ticks have run).
  void endFrame() { tapped_.fill(false); }

 private:
  static bool valid(int key) { return key >= 0 && key < kKeySlots; }
  std::array<bool, kKeySlots> keys_{}, tapped_{};
  std::array<bool, kMouseButtons> buttons_{};
  std::deque<InputEvent> queue_;
};

/// Where each key's and button's press went, so its release goes there too.
class InputRouter {
 public:
  enum class Owner : uint8_t { None, App, Ui };
  /// Decides the owner of an event. `uiWantsKeys`: ImGui is editing (text or an active item);
  /// `uiWantsMouse`: the mouse is over a panel or dragging one of its widgets.
  Owner route(const InputEvent& e, bool uiWantsKeys, bool uiWantsMouse);

 private:
  std::array<Owner, kKeySlots> keyOwner_{};
  std::array<Owner, kMouseButtons> buttonOwner_{};
};

}  // namespace sg::viewer
