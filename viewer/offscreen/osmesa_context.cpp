#include "viewer/offscreen/osmesa_context.h"

#include <GL/glew.h>
// osmesa.h wants GLAPI, which GLEW's header leaves undefined.
#ifndef GLAPI
#define GLAPI extern
#endif
#include <GL/osmesa.h>
#include <dlfcn.h>

#include <chrono>
#include <stdexcept>

#include "sim/world/world.h"
#include "viewer/render/renderer.h"
#include "viewer/render/scene.h"

// Debian's libGLEW is built for GLX: glewInit fetches every entry point through
// glXGetProcAddressARB. This definition, exported by the executable, comes before libGL's in the
// dynamic symbol lookup: while an OSMesa context is current it hands out OSMesa's functions,
// otherwise it forwards to the next definition (libGL's), so a GLX host linked into the same
// program keeps working.
extern "C" __attribute__((visibility("default"))) void* glXGetProcAddressARB(const unsigned char* name) {
  if (OSMesaGetCurrentContext() != nullptr)
    return reinterpret_cast<void*>(OSMesaGetProcAddress(reinterpret_cast<const char*>(name)));
  using Fn = void* (*)(const unsigned char*);
  static const Fn next = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, "glXGetProcAddressARB"));
  return next ? next(name) : nullptr;
}

// Mesa 22's OSMesa leaks its framebuffer bookkeeping (480 bytes in 5 blocks from
// OSMesaMakeCurrent, even for a bare create / make current / destroy): LeakSanitizer ignores
// leaks allocated inside libOSMesa, so ours are still reported. (Defined here, in the one
// library that opens OSMesa; an executable may define these hooks only once.)
#if defined(__SANITIZE_ADDRESS__)
#define SIMGRASS_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SIMGRASS_ASAN 1
#endif
#endif
#ifdef SIMGRASS_ASAN
extern "C" __attribute__((visibility("default"), used)) const char* __lsan_default_suppressions() {
  return "leak:libOSMesa.so\n";
}
// ... and quietly: the suppression report would be stderr output of every successful run.
extern "C" __attribute__((visibility("default"), used)) const char* __lsan_default_options() {
  return "print_suppressions=0";
}
#endif

namespace sg::viewer {

std::unique_ptr<OsmesaContext> OsmesaContext::create(std::string* error) {
  const int attributes[] = {OSMESA_FORMAT,
                            OSMESA_RGBA,
                            OSMESA_DEPTH_BITS,
                            24,
                            OSMESA_PROFILE,
                            OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION,
                            3,
                            OSMESA_CONTEXT_MINOR_VERSION,
                            3,
                            0};
  OSMesaContext ctx = OSMesaCreateContextAttribs(attributes, nullptr);
  if (!ctx) {
    if (error) *error = "OSMesa: cannot create an OpenGL 3.3 core context (OSMesaCreateContextAttribs failed)";
    return nullptr;
  }
  std::unique_ptr<OsmesaContext> c(new OsmesaContext());
  c->context_ = ctx;
  // The default framebuffer is never drawn to (the renderer uses its own FBOs): keep it tiny.
  constexpr int kSide = 4;  // (makeCurrent() uses the same size)
  c->buffer_ = std::make_unique<unsigned char[]>(size_t(kSide) * kSide * 4);
  if (!OSMesaMakeCurrent(ctx, c->buffer_.get(), GL_UNSIGNED_BYTE, kSide, kSide)) {
    if (error) *error = "OSMesa: OSMesaMakeCurrent failed";
    return nullptr;  // the destructor destroys the context
  }
  glewExperimental = GL_TRUE;
  const GLenum glew = glewInit();
  // GLEW_ERROR_GLX_VERSION_11_ONLY (3): GLEW loaded GL, then found no GLX display. Expected here.
  if (glew != GLEW_OK && glew != 3) {
    if (error)
      *error = std::string("OSMesa: glewInit failed: ") + reinterpret_cast<const char*>(glewGetErrorString(glew));
    return nullptr;
  }
  while (glGetError() != GL_NO_ERROR) {
  }
  if (!glGenFramebuffers || !glDrawArraysInstanced || !glVertexAttribDivisor || !glBlitFramebuffer) {
    if (error) *error = "OSMesa: the context lacks OpenGL 3.3 entry points (" + glDescription() + ")";
    return nullptr;
  }
  GLint samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &samples);
  c->maxSamples_ = samples;
  return c;
}

OsmesaContext::~OsmesaContext() {
  if (context_) {
    if (OSMesaGetCurrentContext() == static_cast<OSMesaContext>(context_)) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
    OSMesaDestroyContext(static_cast<OSMesaContext>(context_));
  }
}

std::string OsmesaContext::describe() const { return glDescription(); }

void OsmesaContext::makeCurrent() {
  if (OSMesaGetCurrentContext() != static_cast<OSMesaContext>(context_))
    OSMesaMakeCurrent(static_cast<OSMesaContext>(context_), buffer_.get(), GL_UNSIGNED_BYTE, 4, 4);
}

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
