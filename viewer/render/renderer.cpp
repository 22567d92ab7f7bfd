#include "viewer/render/renderer.h"

#include <GL/glew.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <vector>

#include "viewer/render/obj_mesh.h"
#include "viewer/render/shaders.h"

namespace sg::viewer {
namespace {

constexpr int kMaxShadows = 16;
constexpr int kMaxTiles = 68;  // (16 variants + marking tuft) * 4 levels

/// A shader's or program's info log (getIv / getLog: the glGetShader* or glGetProgram* pair).
template <class GetIv, class GetLog>
std::string infoLog(GLuint object, GetIv getIv, GetLog getLog) {
  GLint n = 0;
  getIv(object, GL_INFO_LOG_LENGTH, &n);
  std::string log(size_t(std::max(n, 1)), '\0');
  getLog(object, n, nullptr, log.data());
  return log.c_str();
}

GLuint compile(GLenum type, const std::string& source, const char* name) {
  const GLuint s = glCreateShader(type);
  const char* text = source.c_str();
  glShaderSource(s, 1, &text, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    const std::string log = infoLog(s, glGetShaderiv, glGetShaderInfoLog);
    glDeleteShader(s);
    throw std::runtime_error(std::string("renderer: shader '") + name + "' does not compile: " + log);
  }
  return s;
}

/// Compiles and links a program; `captured` names vertex outputs to record by transform feedback
/// (interleaved), set before linking as GL requires.
GLuint link(const std::string& vertex, const std::string& fragment, const char* name,
            const std::vector<const char*>& captured = {}) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex, name);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment, name);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  const GLuint p = glCreateProgram();
  glAttachShader(p, vs);
  glAttachShader(p, fs);
  if (!captured.empty())
    glTransformFeedbackVaryings(p, GLsizei(captured.size()), captured.data(), GL_INTERLEAVED_ATTRIBS);
  glLinkProgram(p);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    const std::string log = infoLog(p, glGetProgramiv, glGetProgramInfoLog);
    glDeleteProgram(p);
    throw std::runtime_error(std::string("renderer: program '") + name + "' does not link: " + log);
  }
  return p;
}

std::string litFragment(const char* body) {
  return std::string("#version 330 core\n") + shaders::kLightingFunctions + shaders::kMeadowTint + body;
}

/// The tuft vertex shader (it tints by the meadow's colour variation).
std::string tuftVertex() { return std::string("#version 330 core\n") + shaders::kMeadowTint + shaders::kTuftVertex; }

GLint loc(GLuint program, const char* name) { return glGetUniformLocation(program, name); }
void set3(GLuint p, const char* name, const std::array<float, 3>& v) { glUniform3f(loc(p, name), v[0], v[1], v[2]); }
void set3(GLuint p, const char* name, float x, float y, float z) { glUniform3f(loc(p, name), x, y, z); }
void setMat(GLuint p, const char* name, const Mat4& m) { glUniformMatrix4fv(loc(p, name), 1, GL_FALSE, m.data()); }

/// Inverse of a general 4x4 (column-major; cofactor expansion).
Mat4 inverse4(const Mat4& m) {
  Mat4 inv{};
  inv[0] = m[5] * m[10] * m[15] - m[5] * m[11] * m[14] - m[9] * m[6] * m[15] + m[9] * m[7] * m[14] +
           m[13] * m[6] * m[11] - m[13] * m[7] * m[10];
  inv[4] = -m[4] * m[10] * m[15] + m[4] * m[11] * m[14] + m[8] * m[6] * m[15] - m[8] * m[7] * m[14] -
           m[12] * m[6] * m[11] + m[12] * m[7] * m[10];
  inv[8] = m[4] * m[9] * m[15] - m[4] * m[11] * m[13] - m[8] * m[5] * m[15] + m[8] * m[7] * m[13] +
           m[12] * m[5] * m[11] - m[12] * m[7] * m[9];
  inv[12] = -m[4] * m[9] * m[14] + m[4] * m[10] * m[13] + m[8] * m[5] * m[14] - m[8] * m[6] * m[13] -
            m[12] * m[5] * m[10] + m[12] * m[6] * m[9];
  inv[1] = -m[1] * m[10] * m[15] + m[1] * m[11] * m[14] + m[9] * m[2] * m[15] - m[9] * m[3] * m[14] -
           m[13] * m[2] * m[11] + m[13] * m[3] * m[10];
  inv[5] = m[0] * m[10] * m[15] - m[0] * m[11] * m[14] - m[8] * m[2] * m[15] + m[8] * m[3] * m[14] +
           m[12] * m[2] * m[11] - m[12] * m[3] * m[10];
  inv[9] = -m[0] * m[9] * m[15] + m[0] * m[11] * m[13] + m[8] * m[1] * m[15] - m[8] * m[3] * m[13] -
           m[12] * m[1] * m[11] + m[12] * m[3] * m[9];
  inv[13] = m[0] * m[9] * m[14] - m[0] * m[10] * m[13] - m[8] * m[1] * m[14] + m[8] * m[2] * m[13] +
            m[12] * m[1] * m[10] - m[12] * m[2] * m[9];
  inv[2] = m[1] * m[6] * m[15] - m[1] * m[7] * m[14] - m[5] * m[2] * m[15] + m[5] * m[3] * m[14] + m[13] * m[2] * m[7] -
           m[13] * m[3] * m[6];
  inv[6] = -m[0] * m[6] * m[15] + m[0] * m[7] * m[14] + m[4] * m[2] * m[15] - m[4] * m[3] * m[14] -
           m[12] * m[2] * m[7] + m[12] * m[3] * m[6];
  inv[10] = m[0] * m[5] * m[15] - m[0] * m[7] * m[13] - m[4] * m[1] * m[15] + m[4] * m[3] * m[13] +
            m[12] * m[1] * m[7] - m[12] * m[3] * m[5];
  inv[14] = -m[0] * m[5] * m[14] + m[0] * m[6] * m[13] + m[4] * m[1] * m[14] - m[4] * m[2] * m[13] -
            m[12] * m[1] * m[6] + m[12] * m[2] * m[5];
  inv[3] = -m[1] * m[6] * m[11] + m[1] * m[7] * m[10] + m[5] * m[2] * m[11] - m[5] * m[3] * m[10] - m[9] * m[2] * m[7] +
           m[9] * m[3] * m[6];
  inv[7] = m[0] * m[6] * m[11] - m[0] * m[7] * m[10] - m[4] * m[2] * m[11] + m[4] * m[3] * m[10] + m[8] * m[2] * m[7] -
           m[8] * m[3] * m[6];
  inv[11] = -m[0] * m[5] * m[11] + m[0] * m[7] * m[9] + m[4] * m[1] * m[11] - m[4] * m[3] * m[9] - m[8] * m[1] * m[7] +
            m[8] * m[3] * m[5];
  inv[15] = m[0] * m[5] * m[10] - m[0] * m[6] * m[9] - m[4] * m[1] * m[10] + m[4] * m[2] * m[9] + m[8] * m[1] * m[6] -
            m[8] * m[2] * m[5];
  float det = m[0] * inv[0] + m[1] * inv[4] + m[2] * inv[8] + m[3] * inv[12];
  if (det == 0) return identity4();
  det = 1.0f / det;
  for (float& v : inv) v *= det;
  return inv;
}

/// The six planes (a, b, c, d; inside: a x + b y + c z + d >= 0, (a, b, c) unit) of the frustum
/// of a view-projection matrix (Gribb and Hartmann: the rows' sums and differences).
std::array<std::array<float, 4>, 6> frustumPlanes(const Mat4& m) {
  auto row = [&m](int r) {
    return std::array<float, 4>{m[size_t(r)], m[size_t(4 + r)], m[size_t(8 + r)], m[size_t(12 + r)]};
  };
  const std::array<float, 4> r0 = row(0), r1 = row(1), r2 = row(2), r3 = row(3);
  std::array<std::array<float, 4>, 6> planes{};
  for (int k = 0; k < 4; ++k) {
    planes[0][size_t(k)] = r3[size_t(k)] + r0[size_t(k)];  // left
    planes[1][size_t(k)] = r3[size_t(k)] - r0[size_t(k)];  // right
    planes[2][size_t(k)] = r3[size_t(k)] + r1[size_t(k)];  // bottom
    planes[3][size_t(k)] = r3[size_t(k)] - r1[size_t(k)];  // top
    planes[4][size_t(k)] = r3[size_t(k)] + r2[size_t(k)];  // near
    planes[5][size_t(k)] = r3[size_t(k)] - r2[size_t(k)];  // far
  }
  for (auto& p : planes) {
    const float l = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    if (l > 0)
      for (float& v : p) v /= l;
  }
  return planes;
}

/// An indexed triangle mesh of position + normal (6 floats per vertex).
struct Mesh {
  GLuint vao = 0, vbo = 0, ebo = 0;
  GLsizei indices = 0;

  void upload(const std::vector<float>& vertices, const std::vector<uint32_t>& index) {
    if (!vao) {
      glGenVertexArrays(1, &vao);
      glGenBuffers(1, &vbo);
      glGenBuffers(1, &ebo);
    }
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(float)), vertices.data(), GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(index.size() * sizeof(uint32_t)), index.data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                          reinterpret_cast<const void*>(3 * sizeof(float)));
    glBindVertexArray(0);
    indices = GLsizei(index.size());
  }
  void draw() const {
    glBindVertexArray(vao);
    glDrawElements(GL_TRIANGLES, indices, GL_UNSIGNED_INT, nullptr);
  }
  void release() {
    if (ebo) glDeleteBuffers(1, &ebo);
    if (vbo) glDeleteBuffers(1, &vbo);
    if (vao) glDeleteVertexArrays(1, &vao);
    vao = vbo = ebo = 0;
  }
};

void sphereMesh(Mesh* mesh) {
  constexpr int kSlices = 32, kStacks = 16;
  const float pi = 3.14159265358979f;
  std::vector<float> v;
  std::vector<uint32_t> idx;
  for (int s = 0; s <= kStacks; ++s) {
    const float phi = pi * float(s) / kStacks;  // from +y down
    for (int a = 0; a <= kSlices; ++a) {
      const float theta = 2 * pi * float(a) / kSlices;
      const float x = std::sin(phi) * std::cos(theta), y = std::cos(phi), z = std::sin(phi) * std::sin(theta);
      v.insert(v.end(), {x, y, z, x, y, z});
    }
  }
  for (int s = 0; s < kStacks; ++s)
    for (int a = 0; a < kSlices; ++a) {
      const uint32_t i0 = uint32_t(s * (kSlices + 1) + a), i1 = i0 + 1, i2 = i0 + kSlices + 1, i3 = i2 + 1;
      idx.insert(idx.end(), {i0, i2, i1, i1, i2, i3});
    }
  mesh->upload(v, idx);
}

void cubeMesh(Mesh* mesh) {
  std::vector<float> v;
  std::vector<uint32_t> idx;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign = -1; sign <= 1; sign += 2) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      const uint32_t base = uint32_t(v.size() / 6);
      for (int c = 0; c < 4; ++c) {
        float p[3], n[3] = {0, 0, 0};
        p[axis] = float(sign);
        p[u] = (c & 1) ? 1.0f : -1.0f;
        p[w] = (c & 2) ? 1.0f : -1.0f;
        n[axis] = float(sign);
        v.insert(v.end(), {p[0], p[1], p[2], n[0], n[1], n[2]});
      }
      idx.insert(idx.end(), {base, base + 1, base + 2, base + 1, base + 3, base + 2});
    }
  mesh->upload(v, idx);
}

GLuint uploadTexture(const Image& image, bool repeat) {
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_2D, t);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  // Row 0 (the image's top) goes to t = 0, so the atlas' v coordinates (v0 at the top) apply as is.
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, image.width, image.height, 0, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  const GLint wrap = repeat ? GL_REPEAT : GL_CLAMP_TO_EDGE;
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap);
  return t;
}

/// A single-sampled texture to render into: nearest filtering, clamped (read by texelFetch or
/// at matching resolution).
GLuint renderTexture(GLenum internalFormat, GLenum format, GLenum type, int width, int height) {
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_2D, t);
  glTexImage2D(GL_TEXTURE_2D, 0, GLint(internalFormat), width, height, 0, format, type, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return t;
}

GLuint framebufferOf(GLuint colour, GLuint depth) {
  GLuint f = 0;
  glGenFramebuffers(1, &f);
  glBindFramebuffer(GL_FRAMEBUFFER, f);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colour, 0);
  if (depth) glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth, 0);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    glDeleteFramebuffers(1, &f);
    throw std::runtime_error("renderer: the SSAO framebuffer is incomplete");
  }
  return f;
}

/// SSAO sample kernel: 16 points in the unit hemisphere around +z, on a golden-angle spiral
/// (evenly spread directions), lengths growing quadratically from 0.1 so most samples test the
/// near neighbourhood. Fixed (no random numbers): the same image on every run.
std::vector<float> ssaoKernel() {
  std::vector<float> k;
  constexpr int n = 16;
  for (int i = 0; i < n; ++i) {
    const float z = 1.0f - (float(i) + 0.5f) / float(n);  // cos of the angle from the normal
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 2.39996323f * float(i);
    const float f = float(i + 1) / float(n), length = 0.1f + 0.9f * f * f;
    k.insert(k.end(), {r * std::cos(phi) * length, r * std::sin(phi) * length, std::max(z, 0.15f) * length});
  }
  return k;
}

}  // namespace

// ---- RenderTarget ----------------------------------------------------------------------------

RenderTarget::RenderTarget(int width, int height, int samples) : width_(width), height_(height), samples_(samples) {
  glGenFramebuffers(1, &drawFbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, drawFbo_);
  glGenRenderbuffers(1, &colour_);
  glBindRenderbuffer(GL_RENDERBUFFER, colour_);
  if (samples > 0)
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
  else
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_);
  glGenRenderbuffers(1, &depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_);
  if (samples > 0)
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width, height);
  else
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
  bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  if (samples > 0 && complete) {
    glGenFramebuffers(1, &resolveFbo_);
    glBindFramebuffer(GL_FRAMEBUFFER, resolveFbo_);
    glGenRenderbuffers(1, &resolveColour_);
    glBindRenderbuffer(GL_RENDERBUFFER, resolveColour_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolveColour_);
    complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  }
  glBindRenderbuffer(GL_RENDERBUFFER, 0);
  if (!complete) {
    release();
    throw std::runtime_error("renderer: the " + std::to_string(width) + "x" + std::to_string(height) +
                             " framebuffer (" + std::to_string(samples) + " samples) is incomplete");
  }
  bind();
}

RenderTarget::~RenderTarget() { release(); }

void RenderTarget::release() {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  for (GLuint* f : {&drawFbo_, &resolveFbo_})
    if (*f) glDeleteFramebuffers(1, f), *f = 0;
  for (GLuint* r : {&colour_, &depth_, &resolveColour_})
    if (*r) glDeleteRenderbuffers(1, r), *r = 0;
}

void RenderTarget::bind() {
  glBindFramebuffer(GL_FRAMEBUFFER, drawFbo_);
  glViewport(0, 0, width_, height_);
}

Image RenderTarget::read() {
  if (samples_ > 0) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, drawFbo_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolveFbo_);
    glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, resolveFbo_);
  } else {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, drawFbo_);
  }
  Image raw;
  raw.width = width_;
  raw.height = height_;
  raw.rgba.resize(size_t(width_) * size_t(height_) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, raw.rgba.data());
  // GL's row 0 is the bottom; PNG's is the top.
  Image out = raw;
  const size_t row = size_t(width_) * 4;
  for (int y = 0; y < height_; ++y)
    std::memcpy(out.rgba.data() + size_t(y) * row, raw.rgba.data() + size_t(height_ - 1 - y) * row, row);
  for (size_t i = 3; i < out.rgba.size(); i += 4) out.rgba[i] = 255;
  bind();
  return out;
}

// ---- Renderer --------------------------------------------------------------------------------

struct Renderer::Impl {
  GLuint tuftProgram = 0, groundProgram = 0, bodyProgram = 0, skyProgram = 0;
  GLuint prepassGround = 0, prepassBody = 0, prepassTuft = 0, ssaoProgram = 0, blurProgram = 0, debugProgram = 0;
  GLuint captureProgram = 0;  ///< the tuft vertex shader with transform feedback of vWorld
  GLuint tuftVao = 0, tuftBuffer = 0, emptyVao = 0, debugVao = 0, debugBuffer = 0;
  size_t tuftCapacity = 0;
  // The GPU physics path: per drawn tuft its slot in the device's patch buffer (attribute 3),
  // and that buffer seen as a buffer texture (Scene::deviceTops).
  GLuint slotBuffer = 0, deviceTopTexture = 0, previousTopTexture = 0;
  std::vector<GLint> slots;

  /// Binds the device's tops (or none) for the tuft programs' next draws of instances whose
  /// slots are `slots` (unit 5: the atlas, heights, AO and rock use lower ones).
  void bindDeviceTops(const Scene& scene) {
    glBindVertexArray(tuftVao);
    if (scene.deviceTops == 0) {
      glDisableVertexAttribArray(3);
      return;
    }
    glBindBuffer(GL_ARRAY_BUFFER, slotBuffer);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(slots.size() * sizeof(GLint)), slots.data(), GL_STREAM_DRAW);
    glEnableVertexAttribArray(3);
    glActiveTexture(GL_TEXTURE0 + kDeviceTopsUnit);
    glBindTexture(GL_TEXTURE_BUFFER, deviceTopTexture);
    glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32F, scene.deviceTops);
    if (scene.deviceTopsPrevious != 0) {  // display interpolation: the tick before, too
      glActiveTexture(GL_TEXTURE0 + kPreviousTopsUnit);
      glBindTexture(GL_TEXTURE_BUFFER, previousTopTexture);
      glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32F, scene.deviceTopsPrevious);
    }
    glActiveTexture(GL_TEXTURE0);
  }
  void deviceTopUniforms(GLuint p, const Scene& scene) const {
    glUniform1i(loc(p, "uDeviceTops"), scene.deviceTops != 0 ? 1 : 0);
    glUniform1i(loc(p, "uTops"), kDeviceTopsUnit);
    glUniform1i(loc(p, "uTopsLerp"), scene.deviceTops != 0 && scene.deviceTopsPrevious != 0 ? 1 : 0);
    glUniform1i(loc(p, "uPreviousTops"), kPreviousTopsUnit);
    glUniform1f(loc(p, "uTopsAlpha"), scene.deviceTopsAlpha);
  }
  static constexpr GLint kDeviceTopsUnit = 5, kPreviousTopsUnit = 6;
  Mesh sphere, cube, ground;
  uint64_t groundRevision = 0;
  // The terrain under the tufts: the ground grid's inner heights as a float texture.
  GLuint heightTexture = 0;
  bool hasHeights = false;
  float heightOrigin[2] = {0, 0}, heightStep[2] = {1, 1};
  int heightCells[2] = {1, 1};
  FrameStats stats;
  GLuint atlasTexture = 0, groundTexture = 0, rockTexture = 0;
  // SSAO targets (created for the viewport size on first use).
  int ssaoWidth = 0, ssaoHeight = 0;
  GLuint prepassFbo = 0, prepassNormal = 0, prepassDepth = 0;
  GLuint aoFbo[2] = {0, 0}, aoTexture[2] = {0, 0};  ///< raw, blurred (half resolution)
  bool aoValid = false;                             ///< the last frame computed SSAO
  std::vector<float> kernel = ssaoKernel();
  /// Meshes by resolved path; a failed load keeps its error (no retry every frame).
  struct LoadedMesh {
    Mesh mesh;
    std::string error;
  };
  std::map<std::string, LoadedMesh> meshes;
  std::unique_ptr<TuftAtlas> atlas;
  std::vector<TuftInstance> sorted;  ///< tufts front to back (scratch)
  std::vector<std::pair<float, uint32_t>> order;
  int atlasVariants = -1;
  uint64_t atlasSeed = 0;
  std::string assetDirectory, lastAssetError;

  void ensureAtlas(int variants, uint64_t seed) {
    if (atlas && variants == atlasVariants && seed == atlasSeed) return;
    if (atlasTexture) glDeleteTextures(1, &atlasTexture);
    if (groundTexture) glDeleteTextures(1, &groundTexture);
    atlas = std::make_unique<TuftAtlas>(makeTuftAtlas(variants, seed));
    if (rockTexture) glDeleteTextures(1, &rockTexture);
    atlasTexture = uploadTexture(atlas->image, false);
    groundTexture = uploadTexture(makeGroundTexture(*atlas, seed), true);
    rockTexture = uploadTexture(makeRockTexture(seed), true);
    atlasVariants = variants;
    atlasSeed = seed;
  }

  void uploadGround(const GroundGrid& g) {
    const size_t nx = g.xs.size(), nz = g.zs.size();
    std::vector<float> v;
    std::vector<uint32_t> idx;
    if (nx >= 2 && nz >= 2 && g.heights.size() == nx * nz) {
      v.reserve(nx * nz * 6);
      auto h = [&](size_t i, size_t j) { return g.heights[j * nx + i]; };
      for (size_t j = 0; j < nz; ++j)
        for (size_t i = 0; i < nx; ++i) {
          // Normal from central differences: (-dh/dx, 1, -dh/dz).
          const size_t i0 = i > 0 ? i - 1 : i, i1 = i + 1 < nx ? i + 1 : i;
          const size_t j0 = j > 0 ? j - 1 : j, j1 = j + 1 < nz ? j + 1 : j;
          const float dhdx = (h(i1, j) - h(i0, j)) / std::max(1e-6f, g.xs[i1] - g.xs[i0]);
          const float dhdz = (h(i, j1) - h(i, j0)) / std::max(1e-6f, g.zs[j1] - g.zs[j0]);
          const float nl = std::sqrt(dhdx * dhdx + 1 + dhdz * dhdz);
          v.insert(v.end(), {g.xs[i], h(i, j), g.zs[j], -dhdx / nl, 1 / nl, -dhdz / nl});
        }
      for (size_t j = 0; j + 1 < nz; ++j)
        for (size_t i = 0; i + 1 < nx; ++i) {
          // Split along b-c, from (i + 1, j) to (i, j + 1): the simulation's ground triangles.
          const uint32_t a = uint32_t(j * nx + i), b = a + 1, c = uint32_t(a + nx), d = c + 1;
          idx.insert(idx.end(), {a, c, b, b, c, d});
        }
    }
    ground.upload(v, idx);
    groundRevision = g.revision;
    uploadHeights(g);
  }

  /// The inner part of the grid (without the skirt lines) as an R32F texture: the tuft vertex
  /// shader puts each bottom corner on it. Its lines are evenly spaced (gridLines).
  void uploadHeights(const GroundGrid& g) {
    const size_t nx = g.xs.size(), nz = g.zs.size();
    hasHeights = nx >= 4 && nz >= 4 && g.heights.size() == nx * nz;
    if (!hasHeights) return;
    const size_t ix = nx - 2, iz = nz - 2;  // inner lines 1 .. n - 2
    std::vector<float> inner(ix * iz);
    for (size_t j = 0; j < iz; ++j)
      for (size_t i = 0; i < ix; ++i) inner[j * ix + i] = g.heights[(j + 1) * nx + i + 1];
    heightOrigin[0] = g.xs[1];
    heightOrigin[1] = g.zs[1];
    heightStep[0] = (g.xs[nx - 2] - g.xs[1]) / float(ix - 1);
    heightStep[1] = (g.zs[nz - 2] - g.zs[1]) / float(iz - 1);
    heightCells[0] = int(ix - 1);
    heightCells[1] = int(iz - 1);
    if (!heightTexture) glGenTextures(1, &heightTexture);
    glBindTexture(GL_TEXTURE_2D, heightTexture);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, GLsizei(ix), GLsizei(iz), 0, GL_RED, GL_FLOAT, inner.data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  }

  /// The height texture on unit 3 and its uniforms, for a program running the tuft vertex shader.
  void heightUniforms(GLuint p) const {
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, hasHeights ? heightTexture : 0);
    glUniform1i(loc(p, "uHeights"), 3);
    glUniform1i(loc(p, "uHasHeights"), hasHeights ? 1 : 0);
    glUniform2f(loc(p, "uHeightOrigin"), heightOrigin[0], heightOrigin[1]);
    glUniform2f(loc(p, "uHeightStep"), heightStep[0], heightStep[1]);
    glUniform2i(loc(p, "uHeightCells"), heightCells[0], heightCells[1]);
    glActiveTexture(GL_TEXTURE0);
  }

  /// The mesh for `path` (resolved against `directory`), loading it on first use; null with
  /// *error set when it does not load.
  const Mesh* meshFor(const std::string& path, const std::string& directory, std::string* error) {
    std::filesystem::path resolved(path);
    if (resolved.is_relative() && !directory.empty()) resolved = std::filesystem::path(directory) / resolved;
    const std::string key = resolved.lexically_normal().string();
    auto it = meshes.find(key);
    if (it == meshes.end()) {
      LoadedMesh& m = meshes[key];
      ObjMesh obj;
      if (loadObjMesh(key, &obj, &m.error)) {
        std::vector<float> v;
        v.reserve(obj.positions.size() * 2);
        for (size_t i = 0; i < obj.positions.size(); i += 3)
          v.insert(v.end(), {obj.positions[i], obj.positions[i + 1], obj.positions[i + 2], obj.normals[i],
                             obj.normals[i + 1], obj.normals[i + 2]});
        m.mesh.upload(v, obj.indices);
      }
      it = meshes.find(key);
    }
    if (!it->second.error.empty()) {
      *error = it->second.error;
      return nullptr;
    }
    return &it->second.mesh;
  }

  void ensureSsaoTargets(int width, int height) {
    if (prepassFbo && width == ssaoWidth && height == ssaoHeight) return;
    releaseSsaoTargets();
    ssaoWidth = width;
    ssaoHeight = height;
    prepassNormal = renderTexture(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, width, height);
    prepassDepth = renderTexture(GL_DEPTH_COMPONENT24, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, width, height);
    prepassFbo = framebufferOf(prepassNormal, prepassDepth);
    const int hw = std::max(1, width / 2), hh = std::max(1, height / 2);
    for (int i = 0; i < 2; ++i) {
      aoTexture[i] = renderTexture(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, hw, hh);
      aoFbo[i] = framebufferOf(aoTexture[i], 0);
    }
    // The blurred AO is read at full resolution: filter it.
    glBindTexture(GL_TEXTURE_2D, aoTexture[1]);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  }

  void releaseSsaoTargets() {
    for (GLuint* f : {&prepassFbo, &aoFbo[0], &aoFbo[1]})
      if (*f) glDeleteFramebuffers(1, f), *f = 0;
    for (GLuint* t : {&prepassNormal, &prepassDepth, &aoTexture[0], &aoTexture[1]})
      if (*t) glDeleteTextures(1, t), *t = 0;
    aoValid = false;
  }

  ~Impl() {
    for (GLuint p : {tuftProgram, groundProgram, bodyProgram, skyProgram, prepassGround, prepassBody, prepassTuft,
                     ssaoProgram, blurProgram, debugProgram, captureProgram})
      if (p) glDeleteProgram(p);
    for (GLuint* b : {&tuftBuffer, &debugBuffer, &slotBuffer})
      if (*b) glDeleteBuffers(1, b);
    if (deviceTopTexture) glDeleteTextures(1, &deviceTopTexture);
    if (previousTopTexture) glDeleteTextures(1, &previousTopTexture);
    for (GLuint* a : {&tuftVao, &emptyVao, &debugVao})
      if (*a) glDeleteVertexArrays(1, a);
    sphere.release();
    cube.release();
    ground.release();
    for (auto& [path, m] : meshes) m.mesh.release();
    releaseSsaoTargets();
    for (GLuint* t : {&atlasTexture, &groundTexture, &rockTexture, &heightTexture})
      if (*t) glDeleteTextures(1, t);
  }
};

Renderer::Renderer() : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.tuftProgram = link(tuftVertex(), litFragment(shaders::kTuftFragment), "tuft");
  r.groundProgram = link(shaders::kGroundVertex, litFragment(shaders::kGroundFragment), "ground");
  r.bodyProgram = link(shaders::kBodyVertex, litFragment(shaders::kBodyFragment), "body");
  r.skyProgram = link(shaders::kSkyVertex, shaders::kSkyFragment, "sky");
  r.prepassGround = link(shaders::kGroundVertex, shaders::kPrepassSolidFragment, "prepass ground");
  r.prepassBody = link(shaders::kBodyVertex, shaders::kPrepassSolidFragment, "prepass body");
  r.prepassTuft = link(tuftVertex(), shaders::kPrepassTuftFragment, "prepass tuft");
  r.captureProgram = link(tuftVertex(), shaders::kCaptureFragment, "tuft capture", {"vWorld"});
  r.ssaoProgram = link(shaders::kFullscreenVertex, shaders::kSsaoFragment, "ssao");
  r.blurProgram = link(shaders::kFullscreenVertex, shaders::kBlurFragment, "ssao blur");
  r.debugProgram = link(shaders::kDebugVertex, shaders::kDebugFragment, "debug");
  glGenVertexArrays(1, &r.debugVao);
  glGenBuffers(1, &r.debugBuffer);
  glBindVertexArray(r.debugVao);
  glBindBuffer(GL_ARRAY_BUFFER, r.debugBuffer);
  for (GLuint a = 0; a < 3; ++a) {  // position, colour, point size: 7 floats a vertex
    glEnableVertexAttribArray(a);
    glVertexAttribPointer(a, a == 2 ? 1 : 3, GL_FLOAT, GL_FALSE, 7 * sizeof(float),
                          reinterpret_cast<const void*>(size_t(a) * 3 * sizeof(float)));
  }
  glGenVertexArrays(1, &r.emptyVao);
  glGenVertexArrays(1, &r.tuftVao);
  glGenBuffers(1, &r.tuftBuffer);
  glBindVertexArray(r.tuftVao);
  glBindBuffer(GL_ARRAY_BUFFER, r.tuftBuffer);
  static_assert(sizeof(TuftInstance) == 36, "TuftInstance is uploaded as is");
  const GLsizei stride = sizeof(TuftInstance);
  // Divisor 2: each tuft is two instances, the crossed quads (gl_InstanceID & 1 picks one).
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(offsetof(TuftInstance, x)));
  glVertexAttribDivisor(0, 2);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(offsetof(TuftInstance, topY)));
  glVertexAttribDivisor(1, 2);
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 4, GL_UNSIGNED_BYTE, GL_FALSE, stride,  // variant, level, heat, trail
                        reinterpret_cast<const void*>(offsetof(TuftInstance, variant)));
  glVertexAttribDivisor(2, 2);
  glGenBuffers(1, &r.slotBuffer);
  glGenTextures(1, &r.deviceTopTexture);
  glGenTextures(1, &r.previousTopTexture);
  glBindBuffer(GL_ARRAY_BUFFER, r.slotBuffer);
  glVertexAttribIPointer(3, 1, GL_INT, sizeof(GLint), nullptr);
  glVertexAttribDivisor(3, 2);
  glBindVertexArray(0);
  sphereMesh(&r.sphere);
  cubeMesh(&r.cube);
}

Renderer::~Renderer() = default;

const TuftAtlas* Renderer::atlas() const { return impl_->atlas.get(); }

float Renderer::cullDistance() const { return std::sqrt(std::log(255.0f)) / lighting_.fogDensity; }

const FrameStats& Renderer::lastFrameStats() const { return impl_->stats; }

std::vector<std::array<float, 3>> Renderer::captureTuftCorners(const Scene& scene) {
  Impl& r = *impl_;
  std::vector<std::array<float, 3>> out;
  const size_t n = scene.tufts.size();
  if (n == 0) return out;
  r.ensureAtlas(std::clamp(scene.atlasVariants, 1, 16), scene.atlasSeed);
  if (r.groundRevision != scene.ground.revision) r.uploadGround(scene.ground);
  const size_t vertices = n * 2 * 4;  // two quads of four corners per tuft
  GLuint feedback = 0;
  glGenBuffers(1, &feedback);
  glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, feedback);
  glBufferData(GL_TRANSFORM_FEEDBACK_BUFFER, GLsizeiptr(vertices * 3 * sizeof(float)), nullptr, GL_STATIC_READ);
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, feedback);
  glBindVertexArray(r.tuftVao);
  glBindBuffer(GL_ARRAY_BUFFER, r.tuftBuffer);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(n * sizeof(TuftInstance)), scene.tufts.data(), GL_STREAM_DRAW);
  r.tuftCapacity = n;
  r.slots.resize(n);  // in scene order
  for (size_t i = 0; i < n; ++i) r.slots[i] = i < scene.simulatedTufts ? GLint(i) : -1;
  r.bindDeviceTops(scene);
  GLuint p = r.captureProgram;
  glUseProgram(p);
  r.heightUniforms(p);
  r.deviceTopUniforms(p, scene);
  glUniform1f(loc(p, "uTrailFlatten"), lighting_.trailFlatten);
  glUniform1f(loc(p, "uCrossWidth"), lighting_.crossWidth);
  glUniform1f(loc(p, "uVariation"), lighting_.colourVariation);
  const Mat4 identity = identity4();
  setMat(p, "uViewProj", identity);
  std::vector<float> tiles;
  for (int v = 0; v <= r.atlas->variants; ++v)
    for (int l = 0; l < r.atlas->levels; ++l) {
      const TuftAtlas::Rect t = r.atlas->tile(v, l);
      tiles.insert(tiles.end(), {t.u0, t.v0, t.u1, t.v1});
    }
  glUniform4fv(loc(p, "uTiles"), GLsizei(std::min<size_t>(tiles.size() / 4, kMaxTiles)), tiles.data());
  glUniform1i(loc(p, "uLevels"), r.atlas->levels);
  // Points, not the strip: each vertex is recorded once, in gl_VertexID order per instance.
  glEnable(GL_RASTERIZER_DISCARD);
  glBeginTransformFeedback(GL_POINTS);
  glDrawArraysInstanced(GL_POINTS, 0, 4, GLsizei(2 * n));
  glEndTransformFeedback();
  glDisable(GL_RASTERIZER_DISCARD);
  std::vector<float> raw(vertices * 3);
  glGetBufferSubData(GL_TRANSFORM_FEEDBACK_BUFFER, 0, GLsizeiptr(raw.size() * sizeof(float)), raw.data());
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0);
  glDeleteBuffers(1, &feedback);
  glBindVertexArray(0);
  glUseProgram(0);
  out.resize(vertices);
  for (size_t i = 0; i < vertices; ++i) out[i] = {raw[3 * i], raw[3 * i + 1], raw[3 * i + 2]};
  return out;
}

void Renderer::draw(const Scene& scene, const Camera& camera, int width, int height, bool alphaToCoverage) {
  RenderOptions options;
  options.alphaToCoverage = alphaToCoverage;
  draw(scene, camera, width, height, options);
}

void Renderer::setAssetDirectory(const std::string& directory) { impl_->assetDirectory = directory; }

const std::string& Renderer::lastAssetError() const { return impl_->lastAssetError; }

Image Renderer::readAmbientOcclusion(bool blurred) {
  Impl& r = *impl_;
  Image img;
  if (!r.aoValid) return img;
  GLint previous = 0;
  glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &previous);
  img.width = std::max(1, r.ssaoWidth / 2);
  img.height = std::max(1, r.ssaoHeight / 2);
  std::vector<uint8_t> raw(size_t(img.width) * size_t(img.height) * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, r.aoFbo[blurred ? 1 : 0]);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, img.width, img.height, GL_RGBA, GL_UNSIGNED_BYTE, raw.data());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, GLuint(previous));
  img.rgba.resize(raw.size());
  const size_t row = size_t(img.width) * 4;  // GL's row 0 is the bottom
  for (int y = 0; y < img.height; ++y)
    std::memcpy(img.rgba.data() + size_t(y) * row, raw.data() + size_t(img.height - 1 - y) * row, row);
  return img;
}

void Renderer::draw(const Scene& scene, const Camera& camera, int width, int height, const RenderOptions& options) {
  Impl& r = *impl_;
  const bool alphaToCoverage = options.alphaToCoverage;
  const Lighting& L = lighting_;
  r.ensureAtlas(std::clamp(scene.atlasVariants, 1, 16), scene.atlasSeed);
  if (r.groundRevision != scene.ground.revision) r.uploadGround(scene.ground);

  const float aspect = float(width) / float(std::max(height, 1));
  const Mat4 view = camera.view(), projection = camera.projection(aspect);
  const Mat4 viewProj = multiply(projection, view);
  std::array<float, 3> sun = L.sunDirection;
  const float sl = std::sqrt(sun[0] * sun[0] + sun[1] * sun[1] + sun[2] * sun[2]);
  for (float& c : sun) c /= sl;

  // What each body draws: a loaded mesh, else its primitives (a mesh that fails to load falls
  // back to the collision proxies, with the error recorded).
  struct Draw {
    const BodyPartDraw* part;
    const Mesh* mesh;
  };
  std::vector<Draw> draws;
  std::vector<const BodyPartDraw*> primitives;  // for the shadow discs
  r.lastAssetError.clear();
  for (const BodyPartDraw& b : scene.bodyParts) {
    if (b.shape != BodyPartDraw::Shape::Mesh) {
      draws.push_back({&b, b.shape == BodyPartDraw::Shape::Sphere ? &r.sphere : &r.cube});
      primitives.push_back(&b);
      continue;
    }
    std::string error;
    const Mesh* mesh = r.meshFor(b.mesh, r.assetDirectory, &error);
    if (mesh)
      draws.push_back({&b, mesh});
    else
      r.lastAssetError = error;
    for (uint32_t i = b.firstProxy; i < b.firstProxy + b.proxyCount && i < scene.meshProxies.size(); ++i) {
      const BodyPartDraw& proxy = scene.meshProxies[i];
      if (!mesh) draws.push_back({&proxy, proxy.shape == BodyPartDraw::Shape::Sphere ? &r.sphere : &r.cube});
      primitives.push_back(&proxy);
    }
  }

  // Tufts: culled to the view frustum and the fog distance, then front to back (the depth test
  // then rejects most hidden tuft fragments before shading; a software rasteriser pays for every
  // shaded fragment). Uploaded once for both passes.
  const auto cullStart = std::chrono::steady_clock::now();
  r.stats = {};
  r.stats.tufts = scene.tufts.size();
  const std::array<std::array<float, 4>, 6> planes = frustumPlanes(viewProj);
  const float cullDistance = this->cullDistance();
  r.order.clear();
  r.order.reserve(scene.tufts.size());
  for (size_t i = 0; i < scene.tufts.size(); ++i) {
    const TuftInstance& t = scene.tufts[i];
    const float dx = t.x - camera.x, dz = t.z - camera.z;
    if (options.cull) {
      // A sphere around both quads: centred half way up, reaching the tip-shifted top corners;
      // plus one half width for the terrain lift of the bottom corners (slopes up to 45 degrees).
      // A tuft whose top is on the device (no copy back) stands straight here, its tip anywhere
      // within deviceTipReach of the root (the rod keeps it there).
      const bool onDevice = scene.deviceTops != 0 && i < scene.simulatedTufts;
      const float h = std::fabs(t.topY - t.y);
      const float tip = onDevice ? scene.deviceTipReach : std::sqrt(t.tipX * t.tipX + t.tipZ * t.tipZ);
      const float cx = t.x + 0.5f * t.tipX, cy = t.y + 0.5f * h, cz = t.z + 0.5f * t.tipZ;
      const float across = t.halfWidth + (onDevice ? tip : 0.5f * tip), up = 0.5f * h + t.halfWidth;
      const float radius = std::sqrt(across * across + up * up);
      const float ex = cx - camera.x, ey = cy - camera.y, ez = cz - camera.z;
      if (std::sqrt(ex * ex + ey * ey + ez * ez) - radius > cullDistance) {
        ++r.stats.distanceCulled;
        continue;
      }
      bool outside = false;
      for (const auto& pl : planes) outside = outside || pl[0] * cx + pl[1] * cy + pl[2] * cz + pl[3] < -radius;
      if (outside) {
        ++r.stats.frustumCulled;
        continue;
      }
    }
    r.order.push_back({dx * dx + dz * dz, uint32_t(i)});
  }
  std::sort(r.order.begin(), r.order.end());
  const size_t n = r.order.size();
  r.stats.drawn = n;
  if (n > 0) {
    r.sorted.resize(n);
    for (size_t i = 0; i < n; ++i) r.sorted[i] = scene.tufts[r.order[i].second];
    if (scene.deviceTops != 0) {
      r.slots.resize(n);
      for (size_t i = 0; i < n; ++i)
        r.slots[i] = r.order[i].second < scene.simulatedTufts ? GLint(r.order[i].second) : -1;
    }
    glBindVertexArray(r.tuftVao);
    glBindBuffer(GL_ARRAY_BUFFER, r.tuftBuffer);
    const size_t bytes = n * sizeof(TuftInstance);
    if (n > r.tuftCapacity) {
      glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(bytes), r.sorted.data(), GL_STREAM_DRAW);
      r.tuftCapacity = n;
    } else {
      glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(bytes), r.sorted.data());
    }
    r.bindDeviceTops(scene);
  }
  r.stats.cullAndSortMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - cullStart).count();
  std::vector<float> tiles;
  const TuftAtlas& atlas = *r.atlas;
  for (int v = 0; v <= atlas.variants; ++v)
    for (int l = 0; l < atlas.levels; ++l) {
      const TuftAtlas::Rect t = atlas.tile(v, l);
      tiles.insert(tiles.end(), {t.u0, t.v0, t.u1, t.v1});
    }
  auto tuftUniforms = [&](GLuint p) {
    r.heightUniforms(p);
    r.deviceTopUniforms(p, scene);
    glUniform1f(loc(p, "uTrailFlatten"), L.trailFlatten);
    glUniform1f(loc(p, "uTrailDarken"), L.trailDarken);
    glUniform1f(loc(p, "uCrossWidth"), L.crossWidth);
    glUniform1i(loc(p, "uMarkingVariant"), atlas.variants);
    glUniform1f(loc(p, "uVariation"), L.colourVariation);
    glUniform4fv(loc(p, "uTiles"), GLsizei(std::min<size_t>(tiles.size() / 4, kMaxTiles)), tiles.data());
    glUniform1i(loc(p, "uLevels"), atlas.levels);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r.atlasTexture);
    glUniform1i(loc(p, "uAtlas"), 0);
    glUniform2f(loc(p, "uAtlasSize"), float(atlas.image.width), float(atlas.image.height));
  };

  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  r.aoValid = false;
  if (options.ssao && width > 0 && height > 0) {
    // SSAO: prepass (normals + depth), occlusion at half resolution, blur; then back to the
    // host's framebuffer and viewport.
    GLint hostFbo = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &hostFbo);
    r.ensureSsaoTargets(width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, r.prepassFbo);
    glViewport(0, 0, width, height);
    glClearColor(0.5f, 0.5f, 1.0f, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    auto prepass = [&](GLuint p) {
      glUseProgram(p);
      setMat(p, "uViewProj", viewProj);
      setMat(p, "uView", view);
      set3(p, "uCameraPos", camera.x, camera.y, camera.z);
    };
    if (r.ground.indices > 0) {
      prepass(r.prepassGround);
      glUniform1f(loc(r.prepassGround, "uOccluder"), 0.0f);  // the terrain only receives
      r.ground.draw();
    }
    if (!draws.empty()) {
      prepass(r.prepassBody);
      glUniform1f(loc(r.prepassBody, "uOccluder"), 1.0f);
      for (const Draw& d : draws) {
        setMat(r.prepassBody, "uModel", d.part->model);
        d.mesh->draw();
      }
    }
    if (n > 0) {
      prepass(r.prepassTuft);
      tuftUniforms(r.prepassTuft);
      glBindVertexArray(r.tuftVao);
      glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, GLsizei(2 * n));
    }
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glViewport(0, 0, std::max(1, width / 2), std::max(1, height / 2));
    glBindFramebuffer(GL_FRAMEBUFFER, r.aoFbo[0]);
    glUseProgram(r.ssaoProgram);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r.prepassDepth);
    glUniform1i(loc(r.ssaoProgram, "uDepth"), 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, r.prepassNormal);
    glUniform1i(loc(r.ssaoProgram, "uNormal"), 1);
    setMat(r.ssaoProgram, "uProj", projection);
    setMat(r.ssaoProgram, "uInvProj", inverse4(projection));
    glUniform3fv(loc(r.ssaoProgram, "uKernel"), GLsizei(r.kernel.size() / 3), r.kernel.data());
    glUniform1f(loc(r.ssaoProgram, "uRadius"), L.ssaoRadius);
    glUniform1f(loc(r.ssaoProgram, "uStrength"), L.ssaoStrength);
    glBindVertexArray(r.emptyVao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindFramebuffer(GL_FRAMEBUFFER, r.aoFbo[1]);
    glUseProgram(r.blurProgram);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r.aoTexture[0]);
    glUniform1i(loc(r.blurProgram, "uSource"), 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, r.prepassDepth);
    glUniform1i(loc(r.blurProgram, "uDepth"), 1);
    setMat(r.blurProgram, "uInvProj", inverse4(projection));
    glUniform1f(loc(r.blurProgram, "uDepthTolerance"), L.ssaoBlurDepthTolerance);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindFramebuffer(GL_FRAMEBUFFER, GLuint(hostFbo));
    r.aoValid = true;
  }

  glViewport(0, 0, width, height);
  glClearColor(L.horizon[0], L.horizon[1], L.horizon[2], 1);
  glClearDepth(1.0);
  glDepthMask(GL_TRUE);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  // 1. Sky, behind everything (no depth test, no depth writes).
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glUseProgram(r.skyProgram);
  setMat(r.skyProgram, "uInvViewProj", inverse4(viewProj));
  set3(r.skyProgram, "uCameraPos", camera.x, camera.y, camera.z);
  set3(r.skyProgram, "uSunDir", sun);
  set3(r.skyProgram, "uZenith", L.zenith);
  set3(r.skyProgram, "uHorizon", L.horizon);
  glBindVertexArray(r.emptyVao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);

  // Body shadow discs (shared by the ground and the tufts), from the primitives.
  std::vector<float> shadows;
  for (const BodyPartDraw* b : primitives) {
    if (shadows.size() / 4 >= size_t(kMaxShadows)) break;
    const Mat4& m = b->model;
    const float ex = std::fabs(m[0]) + std::fabs(m[4]) + std::fabs(m[8]);
    const float ey = std::fabs(m[1]) + std::fabs(m[5]) + std::fabs(m[9]);
    const float ez = std::fabs(m[2]) + std::fabs(m[6]) + std::fabs(m[10]);
    // A sphere's model is a rotation times its radius: a column's length (the row sums ex, ey, ez
    // bound a box's extent and overstate a turned sphere's).
    const float sphere = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    const bool isSphere = b->shape == BodyPartDraw::Shape::Sphere;
    const float radius = isSphere ? sphere : 0.5f * (ex + ez);
    shadows.insert(shadows.end(), {m[12], m[14], radius, m[13] - (isSphere ? sphere : ey)});
  }
  // The blurred AO on unit 1 for every lit program (the textures of a pass use unit 0 and 2).
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, r.aoValid ? r.aoTexture[1] : 0);
  auto common = [&](GLuint p) {
    glUseProgram(p);
    setMat(p, "uViewProj", viewProj);
    set3(p, "uCameraPos", camera.x, camera.y, camera.z);
    set3(p, "uSunDir", sun);
    set3(p, "uSunColour", L.sunColour);
    set3(p, "uAmbient", L.ambient);
    set3(p, "uFogColour", L.horizon);
    glUniform1f(loc(p, "uFogDensity"), L.fogDensity);
    glUniform1i(loc(p, "uShadowCount"), GLint(shadows.size() / 4));
    if (!shadows.empty()) glUniform4fv(loc(p, "uShadows"), GLsizei(shadows.size() / 4), shadows.data());
    glUniform1i(loc(p, "uSsao"), r.aoValid ? 1 : 0);
    glUniform1i(loc(p, "uAo"), 1);
    glUniform1f(loc(p, "uAoDirect"), L.ssaoDirect);
    glUniform1f(loc(p, "uVariation"), L.colourVariation);
    glUniform2f(loc(p, "uViewport"), float(width), float(height));
  };

  // 2. Ground.
  if (r.ground.indices > 0) {
    common(r.groundProgram);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r.groundTexture);
    glUniform1i(loc(r.groundProgram, "uGround"), 0);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, r.rockTexture);
    glUniform1i(loc(r.groundProgram, "uRock"), 2);
    glUniform1i(loc(r.groundProgram, "uRockBlend"), options.rockBlend ? 1 : 0);
    glUniform2f(loc(r.groundProgram, "uRockCos"), std::cos(L.rockSlopeDegrees[0] * Camera::kRadians),
                std::cos(L.rockSlopeDegrees[1] * Camera::kRadians));
    glUniform1f(loc(r.groundProgram, "uGroundTile"), L.groundTileMetres);
    glUniform1f(loc(r.groundProgram, "uGroundShade"), L.groundShade);
    r.ground.draw();
  }

  // 3. Bodies.
  if (!draws.empty()) {
    common(r.bodyProgram);
    for (const Draw& d : draws) {
      const BodyPartDraw& b = *d.part;
      setMat(r.bodyProgram, "uModel", b.model);
      set3(r.bodyProgram, "uAlbedo", b.colour[0], b.colour[1], b.colour[2]);
      glUniform1i(loc(r.bodyProgram, "uFootball"), b.pattern == BodyPartDraw::Pattern::Football ? 1 : 0);
      d.mesh->draw();
    }
  }

  // 4. Tufts.
  if (n > 0) {
    common(r.tuftProgram);
    tuftUniforms(r.tuftProgram);
    glUniform1i(loc(r.tuftProgram, "uAlphaToCoverage"), alphaToCoverage ? 1 : 0);
    glUniform1i(loc(r.tuftProgram, "uHeatMap"), options.heatMap ? 1 : 0);
    glBindVertexArray(r.tuftVao);
    if (alphaToCoverage) glEnable(GL_SAMPLE_ALPHA_TO_COVERAGE);
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, GLsizei(2 * n));
    if (alphaToCoverage) glDisable(GL_SAMPLE_ALPHA_TO_COVERAGE);
  }

  // 5. Debug overlay: over everything (no depth test), unlit, unfogged.
  const DebugScene& dbg = scene.debug;
  if ((options.debug.any() || options.overlay) && (!dbg.lines.empty() || !dbg.points.empty())) {
    std::vector<float> v;
    v.reserve(dbg.lines.size() * 14 + dbg.points.size() * 7);
    for (const DebugScene::Line& l : dbg.lines) {
      v.insert(v.end(), {l.a[0], l.a[1], l.a[2], l.colour[0], l.colour[1], l.colour[2], 1.0f});
      v.insert(v.end(), {l.b[0], l.b[1], l.b[2], l.colour[0], l.colour[1], l.colour[2], 1.0f});
    }
    for (const DebugScene::Point& q : dbg.points)
      v.insert(v.end(), {q.p[0], q.p[1], q.p[2], q.colour[0], q.colour[1], q.colour[2], q.size});
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glUseProgram(r.debugProgram);
    setMat(r.debugProgram, "uViewProj", viewProj);
    glBindVertexArray(r.debugVao);
    glBindBuffer(GL_ARRAY_BUFFER, r.debugBuffer);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(v.size() * sizeof(float)), v.data(), GL_STREAM_DRAW);
    if (!dbg.lines.empty()) glDrawArrays(GL_LINES, 0, GLsizei(dbg.lines.size() * 2));
    if (!dbg.points.empty()) glDrawArrays(GL_POINTS, GLsizei(dbg.lines.size() * 2), GLsizei(dbg.points.size()));
    glDisable(GL_PROGRAM_POINT_SIZE);
    glEnable(GL_DEPTH_TEST);
  }
  glActiveTexture(GL_TEXTURE0);
  glBindVertexArray(0);
  glUseProgram(0);
}

std::string glDescription() {
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  return std::string(renderer ? renderer : "?") + ", " + (version ? version : "?");
}

}  // namespace sg::viewer
