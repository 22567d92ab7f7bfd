// Mouse picking: the ray under the cursor and the nearest body it hits, from the drawn scene (the
// bodies' primitive parts, posed as the renderer draws them). Viewer-side floats only: what the
// simulation sees of a pick is the recorded command it leads to (DragTo's target, a selection).
#pragma once

#include <array>
#include <vector>

#include "viewer/render/camera.h"
#include "viewer/render/scene.h"

namespace sg {
struct Scenario;
class SimWorld;
}  // namespace sg

namespace sg::viewer {

using Vec3f = std::array<float, 3>;

/// One primitive part of one body, as drawn: `model` maps the unit sphere or the unit cube
/// (-1..1) to the world (rotation times the radius or half extents, then the part's centre).
struct PickPart {
  int body = 0;
  BodyPartDraw::Shape shape = BodyPartDraw::Shape::Sphere;  ///< Sphere or Box
  Mat4 model = identity4();
};

/// The bodies' primitive parts of `scene` (a mesh body's collision proxies stand for its mesh),
/// each with its body index: extractScene writes every body's parts in body order, a mesh body as
/// one mesh draw whose primitives are its proxies.
std::vector<PickPart> pickParts(const Scene& scene, const SimWorld& world, const Scenario& scenario);

/// Centre of mass of body `body` (m): its parts' centres weighted by their volumes, as the
/// simulation weighs them (sim/bodies/rigid_body.cpp). False when it has no parts.
bool bodyCentre(const std::vector<PickPart>& parts, int body, Vec3f* centre);

/// The ray from the camera through pixel (px, py) of a width x height view (y down, pixel
/// centres at +0.5): origin at the eye, unit direction.
void cursorRay(const Camera& camera, int width, int height, double px, double py, Vec3f* origin, Vec3f* direction);

struct PickHit {
  int body = -1;     ///< -1: nothing hit
  float distance{};  ///< m along the ray
  Vec3f point{};     ///< where the ray enters the body
};

/// The nearest part the ray enters (a ray starting inside a part hits it at distance 0).
PickHit pickBody(const std::vector<PickPart>& parts, const Vec3f& origin, const Vec3f& direction);

/// Where the ray meets the plane through `point` with normal `normal`; false when it runs
/// parallel to it or the plane is behind the eye.
bool rayPlane(const Vec3f& origin, const Vec3f& direction, const Vec3f& point, const Vec3f& normal, Vec3f* hit);

}  // namespace sg::viewer
