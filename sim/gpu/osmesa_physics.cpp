// The tools' GPU physics context: a headless OSMesa 4.5 core context of its own (gl_physics.h).
#include <memory>

#include "sim/gpu/gl_physics.h"
#include "sim/gpu/osmesa_host.h"

namespace sg::gpu {

std::unique_ptr<ParticleDeviceProvider> makeOsmesaPhysicsProvider(std::string* error) {
  struct Osmesa {
    void* context = nullptr;
    unsigned char buffer[4 * 4 * 4] = {};
  };
  auto osmesa = std::make_shared<Osmesa>();
  osmesa->context = createOsmesaCoreContext(4, 5, 0, osmesa->buffer, 4, error);
  if (!osmesa->context) return nullptr;
  GlContextHooks hooks;
  hooks.makeCurrent = [osmesa] { makeOsmesaContextCurrent(osmesa->context, osmesa->buffer, 4); };
  hooks.destroy = [osmesa] { destroyOsmesaContext(osmesa->context); };
  return makeGlPhysicsProvider(std::move(hooks), "", error);
}

}  // namespace sg::gpu
