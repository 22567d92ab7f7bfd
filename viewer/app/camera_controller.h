// The user's camera: first person (walks on the terrain, keeps its eye height above the ground)
// or free (flies along the view direction; C toggles). Works on plain key states so scripted runs
// drive it exactly like the keyboard; the simulation only ever sees its quantised position.
#pragma once

#include <functional>

#include "viewer/render/camera.h"

namespace sg::viewer {

/// Controls (docs/viewer.md).
struct Tuning {
  float walkSpeed = 4.0f;  ///< m/s (x4 with shift)
  float lookDegreesPerPixel = 0.15f;
  float bodyAcceleration = 8.0f;  ///< m/s^2 while a drive key is held (velocity mode)
  float bodySpeed = 2.0f;         ///< m/s while a drive key is held (position mode)
  float minEyeHeight = 0.3f;      ///< m above the terrain
};

/// Movement keys held this frame (+1 / -1 / 0 per axis).
struct MoveKeys {
  float forward = 0, right = 0, up = 0;
  bool fast = false;
};

class CameraController {
 public:
  Camera camera;
  float eyeHeight = 1.7f;  ///< m above the terrain (first person)
  bool free = false;       ///< free camera: no terrain following, W/S along the view direction
  Tuning tune;

  /// Places the camera; in first person the eye height becomes y minus the ground there.
  void place(float x, float y, float z, float yaw, float pitch, const std::function<float(float, float)>& ground);
  /// Mouse look by a cursor movement in pixels.
  void look(float dxPixels, float dyPixels);
  /// Moves for `dt` seconds. `ground(x, z)`: terrain height (m).
  void update(const MoveKeys& keys, float dt, const std::function<float(float, float)>& ground);
  /// Unit vectors on the ground: forward (sin yaw, 0, cos yaw), right (-cos yaw, 0, sin yaw).
  void groundAxes(float* fx, float* fz, float* rx, float* rz) const;
};

}  // namespace sg::viewer
