#include "viewer/app/input_events.h"

#include <utility>

namespace sg::viewer {

void InputState::push(const InputEvent& e) {
  if (e.kind == InputEvent::Kind::MouseButton) {
    if (e.code >= 0 && e.code < kMouseButtons) buttons_[size_t(e.code)] = e.down;
  } else if (valid(e.code)) {
    keys_[size_t(e.code)] = e.down;
    if (e.down) tapped_[size_t(e.code)] = true;
  }
  // A key held down repeats at ~30 Hz: only the first press is a toggle; repeats are dropped
  // (the held state above already says the key is down).
  if (!e.repeat) queue_.push_back(e);
}

std::deque<InputEvent> InputState::takeEvents() { return std::exchange(queue_, {}); }

void InputState::releaseAll() {
  keys_.fill(false);
  buttons_.fill(false);
}

InputRouter::Owner InputRouter::route(const InputEvent& e, bool uiWantsKeys, bool uiWantsMouse) {
  const bool mouse = e.kind == InputEvent::Kind::MouseButton;
  const int limit = mouse ? kMouseButtons : kKeySlots;
  if (e.code < 0 || e.code >= limit) return Owner::None;
  Owner& owner = mouse ? buttonOwner_[size_t(e.code)] : keyOwner_[size_t(e.code)];
  if (!e.down) {  // a release goes where the press went (a key pressed before the window had focus: the UI)
    const Owner to = owner == Owner::None ? Owner::Ui : owner;
    owner = Owner::None;
    return to;
  }
  if (e.repeat && owner != Owner::None) return owner;
  owner = (mouse ? uiWantsMouse : uiWantsKeys) ? Owner::Ui : Owner::App;
  return owner;
}

}  // namespace sg::viewer
