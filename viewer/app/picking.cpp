#include "viewer/app/picking.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/world/sim_world.h"

namespace sg::viewer {
namespace {
float dot(const Vec3f& a, const Vec3f& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3f column(const Mat4& m, int c) { return {m[size_t(c) * 4], m[size_t(c) * 4 + 1], m[size_t(c) * 4 + 2]}; }
Vec3f centreOf(const Mat4& m) { return {m[12], m[13], m[14]}; }
float length(const Vec3f& v) { return std::sqrt(dot(v, v)); }

/// Entry distance of the ray into a sphere of radius r at c (0 from inside), or -1.
float raySphere(const Vec3f& o, const Vec3f& d, const Vec3f& c, float r) {
  const Vec3f oc = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
  const float b = dot(oc, d), q = dot(oc, oc) - r * r;
  if (q <= 0) return 0;  // inside
  const float disc = b * b - q;
  if (b > 0 || disc < 0) return -1;
  return -b - std::sqrt(disc);
}

/// Entry distance into the box `model` maps the unit cube to (slabs along its three axes), or -1.
float rayBox(const Vec3f& o, const Vec3f& d, const Mat4& model) {
  const Vec3f c = centreOf(model);
  const Vec3f oc = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
  float enter = 0, leave = std::numeric_limits<float>::infinity();
  for (int a = 0; a < 3; ++a) {
    const Vec3f axis = column(model, a);
    const float half = length(axis);
    if (!(half > 0)) return -1;
    const Vec3f u = {axis[0] / half, axis[1] / half, axis[2] / half};
    const float start = dot(oc, u), speed = dot(d, u);
    if (std::fabs(speed) < 1e-12f) {
      if (std::fabs(start) > half) return -1;
      continue;
    }
    float t0 = (-half - start) / speed, t1 = (half - start) / speed;
    if (t0 > t1) std::swap(t0, t1);
    enter = std::max(enter, t0);
    leave = std::min(leave, t1);
    if (enter > leave) return -1;
  }
  return enter;
}

/// A part's volume up to a common factor (4/3 pi r^3 and 8 hx hy hz: the simulation's weights).
float volumeOf(const PickPart& p) {
  const float sx = length(column(p.model, 0)), sy = length(column(p.model, 1)), sz = length(column(p.model, 2));
  return p.shape == BodyPartDraw::Shape::Sphere ? 4.18879020f * sx * sx * sx : 8.0f * sx * sy * sz;
}
}  // namespace

std::vector<PickPart> pickParts(const Scene& scene, const SimWorld& world, const Scenario& scenario) {
  std::vector<PickPart> parts;
  const int64_t bodies = world.counts().bodies;
  size_t draw = 0;
  for (int64_t b = 0; b < bodies && draw < scene.bodyParts.size(); ++b) {
    const BodyPartDraw& first = scene.bodyParts[draw];
    if (first.shape == BodyPartDraw::Shape::Mesh) {  // its primitives are the proxies
      for (uint32_t k = 0; k < first.proxyCount && first.firstProxy + k < scene.meshProxies.size(); ++k) {
        const BodyPartDraw& p = scene.meshProxies[first.firstProxy + k];
        parts.push_back({int(b), p.shape, p.model});
      }
      ++draw;
      continue;
    }
    const int32_t spec = world.bodyTemplate(b);
    const size_t count = spec >= 0 && size_t(spec) < scenario.bodies.list.size()
                             ? scenario.bodies.list[size_t(spec)].parts.size()
                             : size_t(1);
    for (size_t k = 0; k < count && draw < scene.bodyParts.size(); ++k, ++draw)
      parts.push_back({int(b), scene.bodyParts[draw].shape, scene.bodyParts[draw].model});
  }
  return parts;
}

bool bodyCentre(const std::vector<PickPart>& parts, int body, Vec3f* centre) {
  double sum[3] = {0, 0, 0}, total = 0;
  for (const PickPart& p : parts) {
    if (p.body != body) continue;
    const double v = volumeOf(p);
    for (size_t a = 0; a < 3; ++a) sum[a] += v * double(p.model[12 + a]);
    total += v;
  }
  if (!(total > 0)) return false;
  for (size_t a = 0; a < 3; ++a) (*centre)[a] = float(sum[a] / total);
  return true;
}

void cursorRay(const Camera& camera, int width, int height, double px, double py, Vec3f* origin, Vec3f* direction) {
  const auto f = camera.forward();
  // The view's right and up axes, as Camera::view builds them.
  float rx = -f[2], rz = f[0];
  const float rl = std::sqrt(rx * rx + rz * rz);
  if (rl < 1e-6f) {
    rx = -std::cos(camera.yawDegrees * Camera::kRadians);
    rz = std::sin(camera.yawDegrees * Camera::kRadians);
  } else {
    rx /= rl;
    rz /= rl;
  }
  const Vec3f up = {-rz * f[1], rz * f[0] - rx * f[2], rx * f[1]};
  const float aspect = float(width) / float(std::max(1, height));
  const float t = std::tan(0.5f * camera.fovYDegrees * Camera::kRadians);
  const float nx = float(2.0 * px / double(std::max(1, width)) - 1.0);
  const float ny = float(1.0 - 2.0 * py / double(std::max(1, height)));
  // The right axis is (rx, 0, rz) looking along f; screen x grows to the right.
  Vec3f d = {f[0] + nx * t * aspect * rx + ny * t * up[0], f[1] + ny * t * up[1],
             f[2] + nx * t * aspect * rz + ny * t * up[2]};
  const float len = length(d);
  for (float& c : d) c /= len;
  *origin = {camera.x, camera.y, camera.z};
  *direction = d;
}

PickHit pickBody(const std::vector<PickPart>& parts, const Vec3f& origin, const Vec3f& direction) {
  PickHit best;
  for (const PickPart& p : parts) {
    const float t = p.shape == BodyPartDraw::Shape::Sphere
                        ? raySphere(origin, direction, centreOf(p.model), length(column(p.model, 0)))
                        : rayBox(origin, direction, p.model);
    if (t < 0 || (best.body >= 0 && t >= best.distance)) continue;
    best.body = p.body;
    best.distance = t;
    for (size_t a = 0; a < 3; ++a) best.point[a] = origin[a] + t * direction[a];
  }
  return best;
}

bool rayPlane(const Vec3f& origin, const Vec3f& direction, const Vec3f& point, const Vec3f& normal, Vec3f* hit) {
  const float denom = dot(direction, normal);
  if (std::fabs(denom) < 1e-6f) return false;
  const Vec3f op = {point[0] - origin[0], point[1] - origin[1], point[2] - origin[2]};
  const float t = dot(op, normal) / denom;
  if (t < 0) return false;
  for (size_t a = 0; a < 3; ++a) (*hit)[a] = origin[a] + t * direction[a];
  return true;
}

}  // namespace sg::viewer
