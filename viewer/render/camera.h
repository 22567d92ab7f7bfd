// A first-person camera: position, yaw and pitch, perspective projection (60 degrees vertical by
// default). Yaw 0 looks along +z, yaw 90 along +x; pitch > 0 looks up. Matrices are column-major
// float[16], as OpenGL takes them.
#pragma once

#include <array>
#include <cmath>

namespace sg::viewer {

using Mat4 = std::array<float, 16>;  ///< column-major: m[col * 4 + row]

inline Mat4 identity4() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

inline Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      float s = 0;
      for (int k = 0; k < 4; ++k) s += a[size_t(k) * 4 + size_t(row)] * b[size_t(c) * 4 + size_t(k)];
      r[size_t(c) * 4 + size_t(row)] = s;
    }
  return r;
}

struct Camera {
  float x = 0, y = 1.7f, z = 0;  ///< eye position (m)
  float yawDegrees = 0;          ///< 0: looking along +z; 90: along +x
  float pitchDegrees = 0;        ///< > 0: looking up
  float fovYDegrees = 60;
  float nearPlane = 0.1f, farPlane = 4000.0f;

  static constexpr float kRadians = 3.14159265358979f / 180.0f;

  /// Unit viewing direction.
  std::array<float, 3> forward() const {
    const float yaw = yawDegrees * kRadians, pitch = pitchDegrees * kRadians;
    return {std::sin(yaw) * std::cos(pitch), std::sin(pitch), std::cos(yaw) * std::cos(pitch)};
  }

  /// A camera at (x, y, z) looking at (tx, ty, tz).
  static Camera lookingAt(float x, float y, float z, float tx, float ty, float tz) {
    Camera c;
    c.x = x;
    c.y = y;
    c.z = z;
    const float dx = tx - x, dy = ty - y, dz = tz - z;
    const float horizontal = std::sqrt(dx * dx + dz * dz);
    c.yawDegrees = std::atan2(dx, dz) / kRadians;
    c.pitchDegrees = std::atan2(dy, horizontal) / kRadians;
    return c;
  }

  /// World to eye: right-handed eye space looking along -z.
  Mat4 view() const {
    const auto f = forward();
    // right = normalise(f x up), up' = right x f.
    float rx = -f[2], rz = f[0];  // f x (0,1,0) = (-f.z, 0, f.x)
    const float rl = std::sqrt(rx * rx + rz * rz);
    if (rl < 1e-6f) {  // looking straight up or down: right from the yaw alone
      rx = -std::cos(yawDegrees * kRadians);
      rz = std::sin(yawDegrees * kRadians);
    } else {
      rx /= rl;
      rz /= rl;
    }
    const float ux = -rz * f[1], uy = rz * f[0] - rx * f[2], uz = rx * f[1];  // right x f
    Mat4 m = identity4();
    m[0] = rx, m[4] = 0, m[8] = rz;
    m[1] = ux, m[5] = uy, m[9] = uz;
    m[2] = -f[0], m[6] = -f[1], m[10] = -f[2];
    m[12] = -(rx * x + rz * z);
    m[13] = -(ux * x + uy * y + uz * z);
    m[14] = f[0] * x + f[1] * y + f[2] * z;
    return m;
  }

  Mat4 projection(float aspect) const {
    const float t = 1.0f / std::tan(0.5f * fovYDegrees * kRadians);
    Mat4 m{};
    m[0] = t / aspect;
    m[5] = t;
    m[10] = (farPlane + nearPlane) / (nearPlane - farPlane);
    m[11] = -1;
    m[14] = 2 * farPlane * nearPlane / (nearPlane - farPlane);
    return m;
  }
};

}  // namespace sg::viewer
