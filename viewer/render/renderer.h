// The OpenGL 3.3 core renderer, shared by the offscreen host and the interactive viewer. Draws a
// Scene (scene.h: plain float data) from a Camera into the bound framebuffer:
//   1. sky: a full-screen triangle, gradient from the horizon to the zenith plus a sun glow;
//   2. ground: the terrain grid, textured with the tiling ground texture (atlas.h), lit by its
//      normals, with soft contact shadows under the bodies;
//   3. bodies: unit spheres and cubes per part under their pose, Lambert + ambient (a football
//      gets dark pentagons);
//   4. tufts: two crossed quads per tuft (simulated and edge ring), built by the vertex shader
//      with their bottom corners on the terrain, culled on the CPU to the view frustum and the
//      fog distance, sorted front to back; alpha test at 0.5 without MSAA, sharpened alpha to
//      coverage with it; all normals up; darker and flatter where a body pressed them (trail);
//      optionally tinted by their divergence heat;
//   5. the debug overlay (lines and points of Scene::debug), over everything.
// Tufts and ground share a large-scale colour variation. Everything is fogged toward the horizon
// colour. With SSAO on, a prepass renders depth and normals (tufts only where their alpha passes;
// the terrain receives but does not occlude), an occlusion pass at half resolution and a
// depth-aware blur darken steps 2-4. Steep ground blends to a rock texture. Bodies naming an
// OBJ mesh draw it instead of their primitives (docs/rendering.md). A GL context (3.3 core or later) with loaded
// entry points must be current for the whole life of a Renderer and a RenderTarget.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "viewer/render/atlas.h"
#include "viewer/render/camera.h"
#include "viewer/render/scene.h"

namespace sg::viewer {

struct Lighting {
  std::array<float, 3> sunDirection{0.45f, 0.80f, 0.40f};  ///< towards the sun (normalised on use)
  std::array<float, 3> sunColour{0.80f, 0.78f, 0.70f};
  std::array<float, 3> ambient{0.42f, 0.45f, 0.50f};
  std::array<float, 3> zenith{0.26f, 0.46f, 0.78f};
  std::array<float, 3> horizon{0.74f, 0.83f, 0.92f};  ///< also the fog colour
  float fogDensity = 1.0f / 170.0f;                   ///< 1/m (exp2 fog)
  float groundTileMetres = 3.0f;                      ///< one ground-texture repeat
  float groundShade = 0.9f;                           ///< the ground lies in the tufts' shade
  /// Slopes (degrees) where the ground blends from grass to rock: starts, complete. Gentle by
  /// default because the repository's hills (hilly-meadow) peak at 15 degrees; real meadows grow
  /// on 30 degrees, so a rougher terrain may want {30, 45}.
  std::array<float, 2> rockSlopeDegrees{9.0f, 14.0f};
  float ssaoRadius = 0.5f;    ///< m: the SSAO neighbourhood
  float ssaoStrength = 1.2f;  ///< 1: all samples occluded -> no ambient
  /// Share of the sun light the AO darkens too. The thesis multiplied its image by the AO; on
  /// ambient light alone (40 % of the grass' light here) the effect was ~5/255, invisible.
  float ssaoDirect = 0.6f;
  float ssaoBlurDepthTolerance = 0.1f;  ///< relative view depth beyond which the blur ignores a neighbour
  float colourVariation = 1.0f;         ///< amplitude of the meadow's large-scale colour variation (0: none)
  /// Width of each of a tuft's two crossed quads relative to the thesis' one quad (2 x scaleXZ).
  /// At 0.5 the pair covers about the screen area of the thesis' quad, so it costs about as much
  /// to fill on a software rasteriser (whose cost is the tufts' fragments), and a tuft is a
  /// clump 0.5 m across instead of a 1 m card.
  float crossWidth = 0.5f;
  float trailFlatten = 0.5f;  ///< share of its height a just-pressed tuft loses
  float trailDarken = 0.3f;   ///< share of its brightness a just-pressed tuft loses
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

/// What to draw and how (the defaults reproduce the golden images).
struct RenderOptions {
  bool alphaToCoverage = true;  ///< needs a multisampled framebuffer, else alpha test
  bool ssao = false;            ///< screen-space ambient occlusion; tufts write depth by their alpha
  bool rockBlend = true;        ///< rock texture on steep terrain
  bool heatMap = false;         ///< tint tufts by TuftInstance::heat (divergence overlay)
  bool cull = true;             ///< skip tufts outside the view frustum or past cullDistance()
  DebugFlags debug;             ///< layers of Scene::debug to draw
  /// Draw Scene::debug whatever the layers: what a host put there itself (the viewer's outline
  /// of the selected body) shows without turning a debug layer on.
  bool overlay = false;
};

/// What the last draw did with the tufts.
struct FrameStats {
  size_t tufts = 0;           ///< in the scene
  size_t drawn = 0;           ///< uploaded and drawn (two crossed quads each)
  size_t frustumCulled = 0;   ///< wholly outside the view frustum
  size_t distanceCulled = 0;  ///< farther than cullDistance()
  double cullAndSortMs = 0;   ///< CPU: culling, the front-to-back sort and the upload
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
  /// The same with every option (draw(..., bool) is draw(..., RenderOptions{alphaToCoverage})).
  void draw(const Scene& scene, const Camera& camera, int width, int height, const RenderOptions& options);

  /// Where relative mesh paths of BodyPartDraw::mesh are resolved (the scenario file's directory;
  /// default: the working directory). Meshes are loaded once per resolved path and cached.
  void setAssetDirectory(const std::string& directory);
  /// The one-line error of the last mesh that failed to load ("" if none); such a body is drawn
  /// as its primitives.
  const std::string& lastAssetError() const;

  /// The last frame's blurred ambient occlusion (half resolution, grey: 255 = open, 0 = fully
  /// occluded), or with `blurred` false the occlusion pass' output before the blur; an empty image
  /// when that frame had SSAO off. For tests and inspection. Half-resolution pixel (x, y) (top row
  /// first) stands for full-resolution pixel (2x, 2y + 1) (top row first; an even height).
  Image readAmbientOcclusion(bool blurred = true);

  /// The atlas in use (generated on the first draw).
  const TuftAtlas* atlas() const;

  /// Tufts farther than this from the camera are not drawn (m): where the fog leaves less than
  /// 1/255 of their colour, sqrt(ln 255) / fogDensity (400 m at the default density), so they
  /// cannot change an 8-bit pixel (and a 0.6 m tuft there is under a pixel tall at 800 x 600).
  float cullDistance() const;
  const FrameStats& lastFrameStats() const;

  /// Every tuft vertex as the tuft vertex shader places it (transform feedback, nothing drawn;
  /// the ground grid of `scene` uploaded first): per tuft in scene order (no culling), per quad of
  /// the cross, the corners bottom-left, bottom-right, top-left, top-right; x, y, z in metres.
  std::vector<std::array<float, 3>> captureTuftCorners(const Scene& scene);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Lighting lighting_;
};

/// "renderer, version" of the current context (GL_RENDERER, GL_VERSION).
std::string glDescription();

}  // namespace sg::viewer
