#include "sim/gpu/osmesa_host.h"

#include <GL/glew.h>
// osmesa.h wants GLAPI, which GLEW's header leaves undefined.
#ifndef GLAPI
#define GLAPI extern
#endif
#include <GL/osmesa.h>
#include <dlfcn.h>

// Debian's libGLEW is built for GLX: glewInit fetches every entry point through
// glXGetProcAddressARB. This definition, exported by the executable, comes before libGL's in the
// dynamic symbol lookup: while an OSMesa context is current it hands out OSMesa's functions,
// otherwise it forwards to the next definition (libGL's), so a GLX host linked into the same
// program keeps working. (In this file because every OSMesa host calls createOsmesaCoreContext,
// so a static link always pulls it in.)
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

namespace sg::gpu {

void* createOsmesaCoreContext(int major, int minor, int depthBits, unsigned char* buffer, int side,
                              std::string* error) {
  const int attributes[] = {OSMESA_FORMAT,
                            OSMESA_RGBA,
                            OSMESA_DEPTH_BITS,
                            depthBits,
                            OSMESA_PROFILE,
                            OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION,
                            major,
                            OSMESA_CONTEXT_MINOR_VERSION,
                            minor,
                            0};
  OSMesaContext ctx = OSMesaCreateContextAttribs(attributes, nullptr);
  if (!ctx) {
    if (error)
      *error = "OSMesa: cannot create an OpenGL " + std::to_string(major) + "." + std::to_string(minor) +
               " core context (OSMesaCreateContextAttribs failed)";
    return nullptr;
  }
  if (!OSMesaMakeCurrent(ctx, buffer, GL_UNSIGNED_BYTE, side, side)) {
    if (error) *error = "OSMesa: OSMesaMakeCurrent failed";
    OSMesaDestroyContext(ctx);
    return nullptr;
  }
  glewExperimental = GL_TRUE;
  const GLenum glew = glewInit();
  // GLEW_ERROR_GLX_VERSION_11_ONLY (3): GLEW loaded GL, then found no GLX display. Expected here.
  if (glew != GLEW_OK && glew != 3) {
    if (error)
      *error = std::string("OSMesa: glewInit failed: ") + reinterpret_cast<const char*>(glewGetErrorString(glew));
    OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
    OSMesaDestroyContext(ctx);
    return nullptr;
  }
  while (glGetError() != GL_NO_ERROR) {
  }
  return ctx;
}

void makeOsmesaContextCurrent(void* context, unsigned char* buffer, int side) {
  if (OSMesaGetCurrentContext() != static_cast<OSMesaContext>(context))
    OSMesaMakeCurrent(static_cast<OSMesaContext>(context), buffer, GL_UNSIGNED_BYTE, side, side);
}

void destroyOsmesaContext(void* context) {
  if (!context) return;
  if (OSMesaGetCurrentContext() == static_cast<OSMesaContext>(context)) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
  OSMesaDestroyContext(static_cast<OSMesaContext>(context));
}

}  // namespace sg::gpu
