// Mowing (World<S>): a mower body's parts cut every tuft whose point at the blade height lies
// inside them. Cuts live in a persistent ordered map keyed by lattice coordinates (saved, hashed)
// and survive the level-of-detail window moving away and back.
#include <algorithm>

#include "sim/world/world.h"

namespace sg {

template <class S>
void World<S>::mowGrass() {
  // A mower part cuts every tuft whose point at the blade height (root + mowerCutHeight) lies
  // inside it. Cuts are keyed by lattice coordinates and never undone.
  const S invSpacing = S(1) / lattice_.spacing;
  for (const RigidBody<S>& body : bodies_) {
    if (!body.mower || !body.bladeOn) continue;  // a switched-off blade still collides, but cuts nothing
    for (size_t part = 0; part < body.parts.size(); ++part) {
      const BodyPart<S>& shape = body.parts[part];
      const Pose<S> pose = body.partPose(part);
      const S reach = shape.boundingRadius + lattice_.jitterAmplitude + lattice_.spacing;
      // floorOfProduct: a mower far from the lattice has an index beyond fx16's range (a mower
      // 2 km off a 5 cm lattice: 40,000 > 32,767); the product overflowed there and raised a
      // fault for a mower that cuts nothing.
      const int64_t i0 =
          std::max<int64_t>(0, floorOfProduct(S(pose.position.x() - reach - lattice_.originX), invSpacing));
      const int64_t i1 = std::min<int64_t>(
          lattice_.patchesX - 1, floorOfProduct(S(pose.position.x() + reach - lattice_.originX), invSpacing) + 1);
      const int64_t j0 =
          std::max<int64_t>(0, floorOfProduct(S(pose.position.z() - reach - lattice_.originZ), invSpacing));
      const int64_t j1 = std::min<int64_t>(
          lattice_.patchesZ - 1, floorOfProduct(S(pose.position.z() + reach - lattice_.originZ), invSpacing) + 1);
      // Roots come from the lattice, not the window: a mower cuts wherever it drives.
      for (int64_t j = j0; j <= j1; ++j)
        for (int64_t i = i0; i <= i1; ++i) {
          if (cuts_.count({i, j})) continue;
          S rootX, rootZ;
          lattice_.rootXZ(i, j, &rootX, &rootZ);
          const Vec3<S> blade(rootX, terrain_.heightAt(rootX, rootZ) + mowerCutHeight_, rootZ);
          bool inside;
          if (shape.type == ShapeType::Sphere) {
            const Vec3<S> d = blade - pose.position;
            inside = abs(d.x()) < shape.radius && abs(d.y()) < shape.radius && abs(d.z()) < shape.radius &&
                     length3(d.x(), d.y(), d.z()) < shape.radius;
          } else {
            const Vec3<S> local = pose.toLocal(blade);
            inside = abs(local.x()) < shape.halfExtents.x() && abs(local.y()) < shape.halfExtents.y() &&
                     abs(local.z()) < shape.halfExtents.z();
          }
          if (!inside) continue;
          if (patchWindow_.contains(i, j)) {
            patches_.cut[patchWindow_.storageIndex(i, j)] = 1;
            ++patchInputsRevision_;
          }
          cuts_.emplace(std::make_pair(i, j), uint8_t(1));
        }
    }
  }
}

#define SG_INSTANTIATE_MOWING(S) template void World<S>::mowGrass();

SG_FOR_EACH_SCALAR(SG_INSTANTIATE_MOWING)

}  // namespace sg
