// The OpenGL 3.3 core renderer, shared by the offscreen host and the interactive viewer. Draws a
// Scene (scene.h: plain float data) from a Camera into the bound framebuffer:
//   1. sky: a full-screen triangle, gradient from the horizon to the zenith plus a sun glow;
//   2. ground: the terrain grid, textured with the tiling ground texture (atlas.h), lit by its
//      normals, with soft contact shadows under the bodies;
//   3. bodies: unit spheres and cubes per part under their pose, Lambert + ambient (a football
//      gets dark pentagons);
//   4. tufts: one instance per tuft (simulated and edge ring), the vertex shader builds the quad;
//      alpha test at 0.5 without MSAA, sharpened alpha to coverage with it; all normals up.
// Everything is fogged toward the horizon colour. A GL context (3.3 core or later) with loaded
// entry points must be current for the whole life of a Renderer and a RenderTarget.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "viewer/render/atlas.h"
#include "viewer/render/camera.h"
#include "viewer/render/scene.h"

namespace sg::viewer {

struct Lighting {
  std::array<float, 3> sunDirection{0.45f, 0.80f, 0.40f};  ///< towards the sun (normalised on use)
  std::array<float, 3> sunColour{0.80f, 0.78f, 0.70f};
  std::array<float, 3> ambient{0.42f, 0.45f, 0.50f};
  std::array<float, 3> zenith{0.26f, 0.46f, 0.78f};
  std::array<float, 3> horizon{0.74f, 0.83f, 0.92f};        ///< also the fog colour
  float fogDensity = 1.0f / 170.0f;                         ///< 1/m (exp2 fog)
  float groundTileMetres = 3.0f;                            ///< one ground-texture repeat
  float groundShade = 0.9f;                                 ///< the ground lies in the tufts' shade
};

/// An offscreen framebuffer: colour + depth, multisampled when samples > 0 (resolved on read).
class RenderTarget {
 public:
  /// Throws std::runtime_error when the framebuffer is incomplete.
  RenderTarget(int width, int height, int samples);
  ~RenderTarget();
  RenderTarget(const RenderTarget&) = delete;
  RenderTarget& operator=(const RenderTarget&) = delete;
  void bind();
  /// Resolves (if multisampled) and reads the pixels back, top row first.
  Image read();
  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return samples_; }

 private:
  void release();
  int width_, height_, samples_;
  unsigned drawFbo_ = 0, colour_ = 0, depth_ = 0;
  unsigned resolveFbo_ = 0, resolveColour_ = 0;
};

class Renderer {
 public:
  /// Compiles the shaders and builds the meshes. Throws std::runtime_error with the GL log.
  Renderer();
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  Lighting& lighting() { return lighting_; }

  /// Draws `scene` into the bound framebuffer (viewport width x height). `alphaToCoverage`
  /// needs a multisampled framebuffer; otherwise the tufts are alpha tested. The atlas and ground
  /// texture are generated for the scene's atlas variants and seed (cached), the ground grid is
  /// uploaded when its revision changes.
  void draw(const Scene& scene, const Camera& camera, int width, int height, bool alphaToCoverage);

  /// The atlas in use (generated on the first draw).
  const TuftAtlas* atlas() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Lighting lighting_;
};

/// "renderer, version" of the current context (GL_RENDERER, GL_VERSION).
std::string glDescription();

}  // namespace sg::viewer
