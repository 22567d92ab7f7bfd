#include "viewer/offscreen/osmesa_context.h"

#include <GL/glew.h>

#include <chrono>
#include <stdexcept>

#include "sim/gpu/osmesa_host.h"
#include "sim/world/world.h"
#include "viewer/render/renderer.h"
#include "viewer/render/scene.h"

namespace sg::viewer {

std::unique_ptr<OsmesaContext> OsmesaContext::create(std::string* error) {
  std::unique_ptr<OsmesaContext> c(new OsmesaContext());
  // The default framebuffer is never drawn to (the renderer uses its own FBOs): keep it tiny.
  constexpr int kSide = 4;  // (makeCurrent() uses the same size)
  c->buffer_ = std::make_unique<unsigned char[]>(size_t(kSide) * kSide * 4);
  c->context_ = gpu::createOsmesaCoreContext(3, 3, 24, c->buffer_.get(), kSide, error);
  if (!c->context_) return nullptr;
  if (!glGenFramebuffers || !glDrawArraysInstanced || !glVertexAttribDivisor || !glBlitFramebuffer) {
    if (error) *error = "OSMesa: the context lacks OpenGL 3.3 entry points (" + glDescription() + ")";
    return nullptr;
  }
  GLint samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &samples);
  c->maxSamples_ = samples;
  return c;
}

OsmesaContext::~OsmesaContext() { gpu::destroyOsmesaContext(context_); }

std::string OsmesaContext::describe() const { return glDescription(); }

void OsmesaContext::makeCurrent() { gpu::makeOsmesaContextCurrent(context_, buffer_.get(), 4); }

// ---- OffscreenRenderer -----------------------------------------------------------------------

std::unique_ptr<OffscreenRenderer> OffscreenRenderer::create(int width, int height, int msaa, std::string* error) {
  std::unique_ptr<OffscreenRenderer> r(new OffscreenRenderer());
  r->context_ = OsmesaContext::create(error);
  if (!r->context_) return nullptr;
  try {
    r->width_ = width;
    r->height_ = height;
    r->samples_ = msaa > 0 ? std::min(msaa, r->context_->maxSamples()) : 0;
    r->renderer_ = std::make_unique<Renderer>();
    r->target_ = std::make_unique<RenderTarget>(width, height, r->samples_);
    r->scene_ = std::make_unique<Scene>();
  } catch (const std::runtime_error& e) {
    if (error) *error = e.what();
    return nullptr;
  }
  return r;
}

OffscreenRenderer::OffscreenRenderer() = default;

Renderer& OffscreenRenderer::renderer() { return *renderer_; }

OffscreenRenderer::~OffscreenRenderer() {
  // GL objects go first, while the context is current (another renderer may have taken it).
  if (context_) context_->makeCurrent();
  scene_.reset();
  target_.reset();
  renderer_.reset();
  context_.reset();
}

Image OffscreenRenderer::render(const SimWorld& world, const Scenario& scenario, const Camera& camera) {
  extractScene(world, scenario, scene_.get());
  return render(*scene_, camera, nullptr);
}

Image OffscreenRenderer::render(const Scene& scene, const Camera& camera) { return render(scene, camera, nullptr); }

Image OffscreenRenderer::render(const Scene& scene, const Camera& camera, double* renderMs) {
  const auto start = std::chrono::steady_clock::now();
  context_->makeCurrent();  // several offscreen renderers may live in one program (tests)
  target_->bind();
  RenderOptions options = options_;
  options.alphaToCoverage = options_.alphaToCoverage && samples_ > 0;  // needs the MSAA target
  renderer_->draw(scene, camera, width_, height_, options);
  Image image = target_->read();  // glReadPixels waits for the frame
  if (renderMs) *renderMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return image;
}

}  // namespace sg::viewer
