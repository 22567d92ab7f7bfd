// The offscreen host: an OpenGL 3.3+ core context from OSMesa (software, llvmpipe), no display
// needed. Used by `simgrass render` and the golden-image tests (docs/rendering.md).
//
// GL is loaded with GLEW. Debian's GLEW is built for GLX and asks glXGetProcAddressARB for every
// entry point; osmesa_context.cpp exports a glXGetProcAddressARB that forwards to
// OSMesaGetProcAddress while an OSMesa context is current (and to the real GLX one otherwise),
// after which glewInit loads everything and returns GLEW_ERROR_GLX_VERSION_11_ONLY, treated as
// success. Link order matters: the executable must find libOSMesa's gl* before libGL's (GLVND
// would dispatch them to no context); the CMake target links libOSMesa and libGLEW only.
#pragma once

#include <memory>
#include <string>

#include "viewer/render/atlas.h"
#include "viewer/render/camera.h"
#include "viewer/render/renderer.h"

namespace sg {
class SimWorld;
struct Scenario;
}  // namespace sg

namespace sg::viewer {

class Renderer;
class RenderTarget;
struct Scene;

/// An OSMesa core-profile context, current on the calling thread from creation to destruction.
class OsmesaContext {
 public:
  /// Creates the context and loads GL. Returns nullptr with *error set ("OSMesa: ...") on failure.
  static std::unique_ptr<OsmesaContext> create(std::string* error);
  ~OsmesaContext();
  OsmesaContext(const OsmesaContext&) = delete;
  OsmesaContext& operator=(const OsmesaContext&) = delete;

  /// GL_RENDERER and GL_VERSION, e.g. "llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile) Mesa 22.3.6".
  std::string describe() const;
  int maxSamples() const { return maxSamples_; }
  /// Makes this context current on the calling thread (a no-op when it is).
  void makeCurrent();

 private:
  OsmesaContext() = default;
  void* context_ = nullptr;                  ///< OSMesaContext
  std::unique_ptr<unsigned char[]> buffer_;  ///< the (tiny) default framebuffer; we draw into FBOs
  int maxSamples_ = 0;
};

/// One frame of a world, offscreen: context, renderer and render target in one object.
class OffscreenRenderer {
 public:
  /// `msaa`: 0 (alpha test) or a sample count (alpha to coverage); clamped to what GL offers.
  /// Returns nullptr with *error set when no context can be created.
  static std::unique_ptr<OffscreenRenderer> create(int width, int height, int msaa, std::string* error);
  ~OffscreenRenderer();

  /// Renders the world's current state (see scene.h for what is drawn) and reads it back.
  Image render(const SimWorld& world, const Scenario& scenario, const Camera& camera);
  /// Renders a prepared scene (tests: a sky-only scene).
  Image render(const Scene& scene, const Camera& camera);
  /// Like render(), but also returns how long the GL part took (draw + glFinish + read back), ms.
  Image render(const Scene& scene, const Camera& camera, double* renderMs);

  Scene& scene() { return *scene_; }  ///< the scene render(world, ...) extracts into (reused)
  /// What render() draws (SSAO, rock, heat map, debug overlay). alphaToCoverage applies only with
  /// samples() > 0 (false: alpha test even on the multisampled target). Defaults: the goldens.
  RenderOptions& options() { return options_; }
  Renderer& renderer();  ///< e.g. setAssetDirectory(), lastAssetError(), readAmbientOcclusion()
  const OsmesaContext& context() const { return *context_; }
  OsmesaContext& context() { return *context_; }
  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return samples_; }

 private:
  OffscreenRenderer();
  int width_ = 0, height_ = 0, samples_ = 0;
  std::unique_ptr<OsmesaContext> context_;
  std::unique_ptr<Renderer> renderer_;
  std::unique_ptr<RenderTarget> target_;
  std::unique_ptr<Scene> scene_;
  RenderOptions options_;
};

}  // namespace sg::viewer
