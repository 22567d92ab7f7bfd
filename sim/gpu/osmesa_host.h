// An OpenGL core context without a display, from OSMesa (llvmpipe: the CPU), with GL loaded
// through GLEW. Shared by the GPU physics path (gl_physics.cpp, a 4.5 context for compute
// shaders) and the viewer's offscreen renderer (viewer/offscreen/osmesa_context.cpp, 3.3).
//
// Debian's GLEW is built for GLX and asks glXGetProcAddressARB for every entry point;
// osmesa_host.cpp exports a glXGetProcAddressARB that forwards to OSMesaGetProcAddress while an
// OSMesa context is current (to the real GLX one otherwise), after which glewInit loads
// everything and returns GLEW_ERROR_GLX_VERSION_11_ONLY, treated as success. Link order
// matters: the executable must find libOSMesa's gl* before libGL's.
#pragma once

#include <string>

namespace sg::gpu {

/// Creates an OSMesa core-profile context of at least GL major.minor (with a depth buffer of
/// `depthBits`), makes it current over `buffer` (side x side RGBA bytes, which the caller keeps
/// alive) and loads GL. Returns the OSMesaContext, or nullptr with *error set ("OSMesa: ...").
void* createOsmesaCoreContext(int major, int minor, int depthBits, unsigned char* buffer, int side, std::string* error);
/// Makes `context` current over `buffer` (a no-op when it is).
void makeOsmesaContextCurrent(void* context, unsigned char* buffer, int side);
/// Releases and destroys `context`.
void destroyOsmesaContext(void* context);

}  // namespace sg::gpu
