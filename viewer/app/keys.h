// Every key and mouse control of the viewer, in one table: the help overlay (F1) draws it,
// `simgrass-viewer --keys` prints it, and docs/viewer.md's Controls table is checked against it
// (tests/viewer_test.cpp), so the three never disagree.
#pragma once

namespace sg::viewer {

struct KeyHelp {
  const char* keys;  ///< as written in docs/viewer.md's table
  const char* what;
};

inline constexpr KeyHelp kKeyHelp[] = {
    {"W / A / S / D", "walk forward / left / back / right along the camera's ground axes (4 m/s, x4 with Shift)"},
    {"Q / E", "lower / raise the eye (first person: kept that high above the terrain)"},
    {"right mouse button + mouse", "look around"},
    {"C", "first-person / free camera"},
    {"L", "follow the selected body (the camera keeps its offset and looks at it)"},
    {"left click", "select the body under the cursor"},
    {"left drag", "pull the body under the cursor (DragTo: a recorded spring toward the cursor)"},
    {"Tab", "select the next body"},
    {"T / F / G / H", "drive the selected body forward / left / back / right"},
    {"U / J", "drive it up / down"},
    {"P", "velocity mode (AddVelocity) / position mode (Displace)"},
    {"M", "the selected body's mower blade off / on"},
    {"Z or Backspace", "reset the selected body to its start state"},
    {"N", "spawn a copy of the selected body 3 m in front of the camera"},
    {"B", "shoot a copy of the selected body from the camera at 15 m/s (Spawn + AddVelocity)"},
    {"R", "start / stop recording the session (from tick 0)"},
    {"Space", "pause / resume (live session and playback)"},
    {". (period)", "pause and step one tick forward"},
    {", (comma)", "pause and step one tick back (live: through the session's history)"},
    {"Home", "restart: a live session back to tick 0, fresh; playback: seek to tick 0"},
    {"Page Down / Page Up", "open the next / previous scene of the scene browser"},
    {"V", "A/B: side by side / divergence overlay"},
    {"F1 or ?", "this help"},
    {"F2", "hide / show the panels"},
    {"F3", "grass follows the camera / the simulated window stays where it stands"},
    {"F12", "screenshot (simgrass-<scene>-<tick>.png in the working folder)"},
    {"Esc", "cancel a seek; else quit"},
};

}  // namespace sg::viewer
