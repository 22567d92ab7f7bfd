#include "viewer/app/camera_controller.h"

#include <algorithm>
#include <cmath>

namespace sg::viewer {

void CameraController::place(float x, float y, float z, float yaw, float pitch,
                             const std::function<float(float, float)>& ground) {
  camera.x = x;
  camera.z = z;
  camera.yawDegrees = yaw;
  camera.pitchDegrees = pitch;
  const float g = ground(x, z);
  eyeHeight = std::max(tune.minEyeHeight, y - g);
  camera.y = free ? y : g + eyeHeight;
}

void CameraController::look(float dxPixels, float dyPixels) {
  camera.yawDegrees -= dxPixels * tune.lookDegreesPerPixel;
  camera.pitchDegrees = std::clamp(camera.pitchDegrees - dyPixels * tune.lookDegreesPerPixel, -89.0f, 89.0f);
}

void CameraController::groundAxes(float* fx, float* fz, float* rx, float* rz) const {
  const float yaw = camera.yawDegrees * Camera::kRadians;
  *fx = std::sin(yaw);
  *fz = std::cos(yaw);
  *rx = -std::cos(yaw);
  *rz = std::sin(yaw);
}

void CameraController::update(const MoveKeys& k, float dt, const std::function<float(float, float)>& ground) {
  const float speed = tune.walkSpeed * (k.fast ? 4.0f : 1.0f) * dt;
  float fx, fz, rx, rz;
  groundAxes(&fx, &fz, &rx, &rz);
  if (free) {
    // Fly where the camera looks; Q/E straight down/up. Never below the minimum eye height.
    const auto f = camera.forward();
    camera.x += (k.forward * f[0] + k.right * rx) * speed;
    camera.y += (k.forward * f[1] + k.up) * speed;
    camera.z += (k.forward * f[2] + k.right * rz) * speed;
    const float g = ground(camera.x, camera.z);
    camera.y = std::max(camera.y, g + tune.minEyeHeight);
    eyeHeight = camera.y - g;
    return;
  }
  camera.x += (k.forward * fx + k.right * rx) * speed;
  camera.z += (k.forward * fz + k.right * rz) * speed;
  eyeHeight = std::max(tune.minEyeHeight, eyeHeight + k.up * speed);
  camera.y = ground(camera.x, camera.z) + eyeHeight;
}

}  // namespace sg::viewer
