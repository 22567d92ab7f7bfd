// GLSL 3.30 core sources of the renderer (docs/rendering.md). Lighting: one directional sun,
// Lambert + ambient; exponential-squared fog toward the sky's horizon colour.
#pragma once

namespace sg::viewer::shaders {

/// Shared by every fragment shader that is lit and fogged.
inline constexpr const char* kLightingFunctions = R"GLSL(
uniform vec3 uCameraPos;
uniform vec3 uSunDir;      // towards the sun, unit
uniform vec3 uSunColour;
uniform vec3 uAmbient;
uniform vec3 uFogColour;
uniform float uFogDensity; // 1/m
uniform vec4 uShadows[16]; // body shadow discs: x, z, radius, height of the body's bottom
uniform int uShadowCount;
uniform bool uSsao;        // screen-space ambient occlusion on: uAo holds it for this frame
uniform sampler2D uAo;     // blurred AO (1 = open), half resolution, covers the viewport
uniform vec2 uViewport;    // pixels
uniform float uAoDirect;   // share of the sun light the AO also takes (the thesis darkened the image)

// The ambient light reaching this pixel: the sky's, less what the neighbourhood occludes (SSAO).
float ambientOcclusion() {
  return uSsao ? texture(uAo, gl_FragCoord.xy / uViewport).r : 1.0;
}
vec3 lit(vec3 albedo, vec3 n) {
  float ao = ambientOcclusion();
  return albedo * (uAmbient * ao + uSunColour * max(dot(n, uSunDir), 0.0) * mix(1.0, ao, uAoDirect));
}
vec3 fogged(vec3 colour, vec3 world) {
  float d = distance(world, uCameraPos) * uFogDensity;
  return mix(uFogColour, colour, exp(-d * d));
}
// Soft contact shadows under bodies (no shadow maps): a darkening disc under each body part,
// fading with its height above the point.
float shadowAt(vec3 world) {
  float s = 1.0;
  for (int i = 0; i < uShadowCount; ++i) {
    vec4 b = uShadows[i];
    float above = b.w - world.y;
    if (above < -0.05) continue;
    float r = b.z * (1.0 + 0.3 * max(above, 0.0));
    float d = length(world.xz - b.xy) / r;
    s *= mix(0.45, 1.0, smoothstep(0.55, 1.1, d));
  }
  return s;
}
)GLSL";

/// Large-scale colour variation of the meadow (tufts and ground alike): a deterministic function
/// of the world position (x, z), so every tuft of a patch of meadow shares it and it never moves.
/// Two octaves of value noise on an integer hash (no sin(): its precision differs between GPUs).
inline constexpr const char* kMeadowTint = R"GLSL(
uniform float uVariation;  // 0: none, 1: the full amplitude (Lighting::colourVariation)
float latticeNoise(ivec2 c) {
  uint h = uint(c.x + 65536) * 0x8da6b343u ^ uint(c.y + 65536) * 0xd8163841u;
  h = (h ^ (h >> 16u)) * 0x7feb352du;
  h = (h ^ (h >> 15u)) * 0x846ca68bu;
  h ^= h >> 16u;
  return float(h >> 8u) / 16777216.0;
}
float valueNoise(vec2 p) {
  vec2 c = floor(p), f = p - c, u = f * f * (3.0 - 2.0 * f);
  ivec2 i = ivec2(c);
  return mix(mix(latticeNoise(i), latticeNoise(i + ivec2(1, 0)), u.x),
             mix(latticeNoise(i + ivec2(0, 1)), latticeNoise(i + ivec2(1, 1)), u.x), u.y);
}
// Brightness from two octaves (wavelengths 14 m and 6 m: several swathes across a 40 m meadow), a
// hue from a third, independent one (18 m) between lush blue-green and dry yellow-green.
vec3 meadowTint(vec2 xz) {
  float b = 0.6 * valueNoise(xz / 14.0) + 0.4 * valueNoise(xz / 6.0 + vec2(17.3, 5.9));
  float h = smoothstep(0.2, 0.8, valueNoise(xz / 18.0 + vec2(-7.7, 31.1)));
  vec3 hue = mix(vec3(0.88, 1.00, 1.08), vec3(1.18, 1.06, 0.72), h);
  return mix(vec3(1.0), hue * (0.70 + 0.60 * b), uVariation);
}
)GLSL";

inline constexpr const char* kTuftVertex = R"GLSL(
layout(location = 0) in vec4 aRoot;  // root x, y, z; half width
layout(location = 1) in vec4 aTop;   // top y; tip offset x, z; angle (rad)
layout(location = 2) in vec4 aTile;  // atlas variant, brightness level, divergence heat 0..255, trail 0..255
// The GPU physics path (docs/gpu-physics.md): the tuft's slot in uTops, the device's patch buffer,
// which then holds its top y, tip offset x and z and brightness level (aTop.xyz and aTile.y are
// placeholders); -1: the tuft's own values (the edge ring).
layout(location = 3) in int aSlot;
uniform bool uDeviceTops;
uniform samplerBuffer uTops;
// Display interpolation between ticks (interpolateScene): the previous tick's buffer, and how
// far toward uTops' values the top, tip x and z are drawn, as the host blends its own.
uniform bool uTopsLerp;
uniform samplerBuffer uPreviousTops;
uniform float uTopsAlpha;
uniform mat4 uViewProj;
uniform vec4 uTiles[68];             // (variants + 1) * levels tile rects: u0, v0 (top), u1, v1
uniform int uLevels;
uniform float uTrailFlatten;         // share of its height a just-pressed tuft loses
uniform float uCrossWidth;           // each crossed quad's width over the thesis' single quad's
uniform int uMarkingVariant;         // the atlas column of the white marking tuft
// The terrain under the tufts: heights of the ground grid's inner part (texel (i, j) at
// uHeightOrigin + (i, j) * uHeightStep, m), triangulated as the ground mesh and the simulation.
uniform bool uHasHeights;
uniform sampler2D uHeights;
uniform vec2 uHeightOrigin;
uniform vec2 uHeightStep;
uniform ivec2 uHeightCells;          // texels - 1 along x and z
out vec2 vUv;
out float vUp;                       // 0 at the root, 1 at the top
out vec3 vWorld;
out float vHeat;                     // 0..1
out vec3 vShade;                     // albedo factor: colour variation, root shade, trail
out float vFog;                      // share of the tuft's colour the fog leaves (1: none)
uniform vec3 uCameraPos;
uniform float uFogDensity;           // 1/m
uniform float uTrailDarken;          // share of its brightness a just-pressed tuft loses
float terrainAt(vec2 xz) {
  vec2 g = (xz - uHeightOrigin) / uHeightStep;
  vec2 c = clamp(floor(g), vec2(0.0), vec2(uHeightCells - 1));
  vec2 f = clamp(g - c, 0.0, 1.0);
  ivec2 i = ivec2(c);
  float h00 = texelFetch(uHeights, i, 0).r, h10 = texelFetch(uHeights, i + ivec2(1, 0), 0).r;
  float h01 = texelFetch(uHeights, i + ivec2(0, 1), 0).r, h11 = texelFetch(uHeights, i + ivec2(1, 1), 0).r;
  // Split from (i + 1, j) to (i, j + 1), as the ground mesh (and Terrain::heightAt).
  return f.x + f.y <= 1.0 ? h00 + f.x * (h10 - h00) + f.y * (h01 - h00)
                          : h11 + (1.0 - f.x) * (h01 - h11) + (1.0 - f.y) * (h10 - h11);
}
void main() {
  vec4 top4 = aTop, tile4 = aTile;
  if (uDeviceTops && aSlot >= 0) {
    vec4 d = texelFetch(uTops, aSlot);
    if (uTopsLerp) {  // a + (b - a) t, as interpolateScene
      vec3 before = texelFetch(uPreviousTops, aSlot).xyz;
      d.xyz = before + (d.xyz - before) * uTopsAlpha;
    }
    top4.xyz = d.xyz;
    // The brightness level, plus 4 x the trample level (0..255) where the blades are trampled
    // (ParticleDevice::patchDrawBuffer): the trail shows the larger of it and the host's.
    tile4.y = mod(d.w, 4.0);
    tile4.w = max(tile4.w, floor(d.w * 0.25));
  }
  // Two instances per tuft (the attributes advance every second instance): the crossed quads,
  // the second turned 90 degrees and showing the tile mirrored, each uCrossWidth as wide as the
  // thesis' quad. Each is a triangle strip 0..3: bottom-left, bottom-right, top-left, top-right
  // (thesis §2 vertices).
  int quad = gl_InstanceID & 1;
  int corner = gl_VertexID;
  float side = (corner & 1) == 0 ? -1.0 : 1.0;
  bool top = corner >= 2;
  float angle = top4.w + (quad == 1 ? 1.5707963 : 0.0);
  vec3 along = vec3(cos(angle), 0.0, -sin(angle)) * aRoot.w * uCrossWidth;
  vec3 p = aRoot.xyz + side * along;
  // Terrain-following: each bottom corner lies as far above the terrain under it as the root does
  // above its own, and the top edge keeps the tuft's height above it (the blades grow up from the
  // slope). Without a ground grid (synthetic scenes), the flat quad.
  float lift = uHasHeights ? terrainAt(p.xz) - terrainAt(aRoot.xz) : 0.0;
  float trail = tile4.w / 255.0;
  if (top) p = vec3(p.x + top4.y, aRoot.y + (top4.x - aRoot.y) * (1.0 - uTrailFlatten * trail), p.z + top4.z);
  p.y += lift;
  vec4 tile = uTiles[int(tile4.x + 0.5) * uLevels + int(tile4.y + 0.5)];
  bool left = (side < 0.0) != (quad == 1);
  vUv = vec2(left ? tile.x : tile.z, top ? tile.y : tile.w);
  vUp = top ? 1.0 : 0.0;
  vHeat = tile4.z / 255.0;
  // Per vertex, as all of it is linear along the quad or constant over it (the fragment shader is
  // what llvmpipe pays for, twice per tuft): darker toward the root, a stand-in for the thesis'
  // SSAO (the lower part of a tuft sits in the others' shade); a pressed tuft (a body's trail)
  // darker, its blades lying in each other's shade; fog over at most a metre of quad.
  // (Painted marking tufts keep their white: paint does not vary with the meadow.)
  vec3 tint = int(tile4.x + 0.5) == uMarkingVariant ? vec3(1.0) : meadowTint(aRoot.xz);
  vShade = tint * (top ? 1.0 : 0.42) * (1.0 - uTrailDarken * trail);
  float d = distance(p, uCameraPos) * uFogDensity;
  vFog = exp(-d * d);
  vWorld = p;
  gl_Position = uViewProj * vec4(p, 1.0);
}
)GLSL";

inline constexpr const char* kTuftFragment = R"GLSL(
uniform sampler2D uAtlas;
uniform vec2 uAtlasSize;
uniform bool uAlphaToCoverage;
uniform bool uHeatMap;
in vec2 vUv;
in float vUp;
in vec3 vWorld;
in float vHeat;
in vec3 vShade;
in float vFog;
out vec4 fragColour;
// Divergence heat: blue (small) - yellow - red (full scale).
vec3 heatColour(float h) {
  return h < 0.5 ? mix(vec3(0.15, 0.35, 1.0), vec3(1.0, 0.9, 0.1), 2.0 * h)
                 : mix(vec3(1.0, 0.9, 0.1), vec3(1.0, 0.08, 0.04), 2.0 * h - 1.0);
}
void main() {
  vec4 t = texture(uAtlas, vUv);
  // Mipmaps average the blades' alpha away with distance; scale it back up by the mip level so
  // far grass keeps its coverage.
  vec2 tx = dFdx(vUv * uAtlasSize), ty = dFdy(vUv * uAtlasSize);
  float mip = max(0.0, 0.5 * log2(max(dot(tx, tx), dot(ty, ty))));
  float a = t.a * (1.0 + 0.25 * mip);
  if (uAlphaToCoverage) {
    // Sharpened alpha to coverage: a crisp edge, antialiased over about one pixel.
    a = (a - 0.5) / max(fwidth(a), 1e-4) + 0.5;
    if (a <= 0.0) discard;
    a = min(a, 1.0);
  } else {
    if (a < 0.5) discard;  // thesis: alpha test GL_GREATER with a mid reference
    a = 1.0;
  }
  // All normals up (thesis §2): both faces light alike, so the light is the vertex shader's
  // (vShade); only the AO and the contact shadows vary within a quad.
  vec3 c = lit(t.rgb * vShade, vec3(0.0, 1.0, 0.0));
  if (uShadowCount > 0) c *= shadowAt(vWorld);
  if (uHeatMap && vHeat > 0.0) c = mix(c, heatColour(vHeat) * mix(0.55, 1.0, vUp), 0.85);
  fragColour = vec4(mix(uFogColour, c, vFog), a);
}
)GLSL";

inline constexpr const char* kGroundVertex = R"GLSL(#version 330 core
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
uniform mat4 uViewProj;
out vec3 vWorld;
out vec3 vNormal;
void main() {
  vWorld = aPosition;
  vNormal = aNormal;
  gl_Position = uViewProj * vec4(aPosition, 1.0);
}
)GLSL";

inline constexpr const char* kGroundFragment = R"GLSL(
uniform sampler2D uGround;
uniform float uGroundTile;  // m per texture repeat
uniform float uGroundShade; // the ground is the shaded floor under the tufts
uniform sampler2D uRock;
uniform bool uRockBlend;    // rock on steep slopes
uniform vec2 uRockCos;      // cos of the slopes where the rock starts and where it is complete
in vec3 vWorld;
in vec3 vNormal;
out vec4 fragColour;
void main() {
  // Two lookups at unrelated scales and angles hide the texture's repeat at a distance.
  vec3 near = texture(uGround, vWorld.xz / uGroundTile).rgb;
  vec3 far = texture(uGround, mat2(0.8, -0.6, 0.6, 0.8) * vWorld.xz / (2.7 * uGroundTile) + vec2(0.31, 0.57)).rgb;
  vec3 albedo = mix(near, far, 0.45) * uGroundShade * meadowTint(vWorld.xz);
  vec3 n = normalize(vNormal);
  // Rock from the slope uRockCos.x to uRockCos.y (cosines: n.y = cos(slope)); flat ground keeps
  // the grass texture exactly. Sampled on the two horizontal planes the slope faces most
  // (triplanar without the top plane), so steep faces do not show stretched texels.
  // (Sampled outside the branch: mipmapped lookups need derivatives in uniform control flow.)
  vec3 w = abs(n) + 1e-4;
  vec2 scale = vec2(1.0 / (1.3 * uGroundTile));
  vec3 rx = texture(uRock, vWorld.zy * scale + vec2(0.17, 0.43)).rgb;
  vec3 rz = texture(uRock, vWorld.xy * scale + vec2(0.61, 0.09)).rgb;
  vec3 ry = texture(uRock, vWorld.xz * scale).rgb;
  float rock = uRockBlend ? 1.0 - smoothstep(uRockCos.y, uRockCos.x, n.y) : 0.0;
  if (rock > 0.0) albedo = mix(albedo, (rx * w.x + ry * w.y + rz * w.z) / (w.x + w.y + w.z), rock);
  vec3 c = lit(albedo, n) * shadowAt(vWorld);
  fragColour = vec4(fogged(c, vWorld), 1.0);
}
)GLSL";

inline constexpr const char* kBodyVertex = R"GLSL(#version 330 core
layout(location = 0) in vec3 aPosition;  // unit sphere or cube (-1..1)
layout(location = 1) in vec3 aNormal;
uniform mat4 uViewProj;
uniform mat4 uModel;
out vec3 vWorld;
out vec3 vNormal;
out vec3 vLocal;
void main() {
  vec4 w = uModel * vec4(aPosition, 1.0);
  vWorld = w.xyz;
  vNormal = transpose(inverse(mat3(uModel))) * aNormal;
  vLocal = aPosition;
  gl_Position = uViewProj * w;
}
)GLSL";

inline constexpr const char* kBodyFragment = R"GLSL(
uniform vec3 uAlbedo;
uniform bool uFootball;
in vec3 vWorld;
in vec3 vNormal;
in vec3 vLocal;
out vec4 fragColour;
// Football: dark pentagons around the 12 icosahedron vertices. A point lies in the pentagon of
// its nearest vertex v when dot(p, v) beats every other vertex by more than a margin (the
// boundary planes between neighbouring vertices cut the sphere in pentagons).
const float PHI = 1.618034;
const vec3 ICO[12] = vec3[12](
  vec3(0, 1, PHI), vec3(0, -1, PHI), vec3(0, 1, -PHI), vec3(0, -1, -PHI),
  vec3(1, PHI, 0), vec3(-1, PHI, 0), vec3(1, -PHI, 0), vec3(-1, -PHI, 0),
  vec3(PHI, 0, 1), vec3(-PHI, 0, 1), vec3(PHI, 0, -1), vec3(-PHI, 0, -1));
void main() {
  vec3 albedo = uAlbedo;
  if (uFootball) {
    vec3 p = normalize(vLocal);
    float best = -2.0, second = -2.0;
    for (int i = 0; i < 12; ++i) {
      float d = dot(p, normalize(ICO[i]));
      if (d > best) { second = best; best = d; } else if (d > second) { second = d; }
    }
    if (best - second > 0.25) albedo = vec3(0.06);
  }
  vec3 c = lit(albedo, normalize(vNormal) * (gl_FrontFacing ? 1.0 : -1.0));
  fragColour = vec4(fogged(c, vWorld), 1.0);
}
)GLSL";

inline constexpr const char* kSkyVertex = R"GLSL(#version 330 core
out vec2 vNdc;
void main() {
  // One triangle covering the screen.
  vec2 p = vec2((gl_VertexID == 1) ? 3.0 : -1.0, (gl_VertexID == 2) ? 3.0 : -1.0);
  vNdc = p;
  gl_Position = vec4(p, 1.0, 1.0);
}
)GLSL";

inline constexpr const char* kSkyFragment = R"GLSL(#version 330 core
uniform mat4 uInvViewProj;
uniform vec3 uCameraPos;
uniform vec3 uSunDir;
uniform vec3 uZenith;
uniform vec3 uHorizon;
in vec2 vNdc;
out vec4 fragColour;
void main() {
  vec4 far = uInvViewProj * vec4(vNdc, 1.0, 1.0);
  vec3 dir = normalize(far.xyz / far.w - uCameraPos);
  float up = max(dir.y, 0.0);
  vec3 c = mix(uHorizon, uZenith, pow(up, 0.6));
  float toSun = max(dot(dir, uSunDir), 0.0);
  c += vec3(1.0, 0.95, 0.8) * (pow(toSun, 600.0) * 0.8 + pow(toSun, 12.0) * 0.12);
  fragColour = vec4(min(c, vec3(1.0)), 1.0);
}
)GLSL";

// ---- SSAO (docs/rendering.md): a depth + normal prepass, the occlusion at half resolution, a
// depth-aware 4x4 blur; lit() then scales the ambient term (and uAoDirect of the sun's) by it.
// ------------------------------------------

/// Prepass of ground, bodies and meshes: view-space normal (encoded 0..1), depth by the depth test,
/// and in alpha whether the surface occludes (the terrain does not: it only receives, so hills and
/// the grazing far ground never darken themselves). The normal is turned toward the camera: a
/// visible surface's occlusion is on its visible side, whatever the mesh's winding.
inline constexpr const char* kPrepassSolidFragment = R"GLSL(#version 330 core
uniform mat4 uView;
uniform vec3 uCameraPos;
uniform float uOccluder;  // alpha: 1 for bodies (occlude), 0 for the ground (only receives)
in vec3 vWorld;
in vec3 vNormal;
out vec4 fragNormal;
void main() {
  vec3 n = normalize(vNormal);
  if (dot(n, uCameraPos - vWorld) < 0.0) n = -n;
  fragNormal = vec4(normalize(mat3(uView) * n) * 0.5 + 0.5, uOccluder);
}
)GLSL";

/// Prepass of the tufts: depth only where the atlas alpha passes the main pass' alpha test, so
/// the gaps between blades do not occlude (no quad-shaped occlusion). Normals up, as lit.
inline constexpr const char* kPrepassTuftFragment = R"GLSL(#version 330 core
uniform mat4 uView;
uniform sampler2D uAtlas;
uniform vec2 uAtlasSize;
in vec2 vUv;
out vec4 fragNormal;
void main() {
  vec4 t = texture(uAtlas, vUv);
  vec2 tx = dFdx(vUv * uAtlasSize), ty = dFdy(vUv * uAtlasSize);
  float mip = max(0.0, 0.5 * log2(max(dot(tx, tx), dot(ty, ty))));
  if (t.a * (1.0 + 0.25 * mip) < 0.5) discard;
  fragNormal = vec4(normalize(mat3(uView) * vec3(0.0, 1.0, 0.0)) * 0.5 + 0.5, 1.0);
}
)GLSL";

inline constexpr const char* kFullscreenVertex = R"GLSL(#version 330 core
out vec2 vUv;
void main() {
  vec2 p = vec2((gl_VertexID == 1) ? 3.0 : -1.0, (gl_VertexID == 2) ? 3.0 : -1.0);
  vUv = p * 0.5 + 0.5;
  gl_Position = vec4(p, 0.0, 1.0);
}
)GLSL";

/// Normal-oriented hemisphere SSAO (Crytek / Chapman): 16 kernel samples within uRadius metres,
/// turned per pixel by one of 16 angles in a 4x4 pattern (the blur removes the pattern); a sample
/// counts as occluded when the depth buffer holds an occluder (grass or a body, not the terrain) in
/// front of it, weighted down when that surface is much farther than the radius (a range check:
/// no dark halos at silhouettes).
inline constexpr const char* kSsaoFragment = R"GLSL(#version 330 core
uniform sampler2D uDepth;
uniform sampler2D uNormal;
uniform mat4 uProj;
uniform mat4 uInvProj;
uniform vec3 uKernel[16];
uniform float uRadius;    // m
uniform float uStrength;  // 1: fully occluded samples give AO 0
in vec2 vUv;
out vec4 fragAo;
vec3 viewPos(vec2 uv) {
  float d = texture(uDepth, uv).r;
  vec4 p = uInvProj * vec4(vec3(uv, d) * 2.0 - 1.0, 1.0);
  return p.xyz / p.w;
}
void main() {
  // The full-resolution texel this pixel stands for (the blur reads the same one: its depth and
  // this AO belong to the same surface, also along silhouettes).
  ivec2 texel = min(2 * ivec2(gl_FragCoord.xy), textureSize(uDepth, 0) - 1);
  vec2 uv = (vec2(texel) + 0.5) / vec2(textureSize(uDepth, 0));
  float depth = texelFetch(uDepth, texel, 0).r;
  if (depth >= 1.0) { fragAo = vec4(1.0); return; }  // sky
  vec4 v = uInvProj * vec4(vec3(uv, depth) * 2.0 - 1.0, 1.0);
  vec3 p = v.xyz / v.w;
  vec3 n = normalize(texelFetch(uNormal, texel, 0).xyz * 2.0 - 1.0);
  ivec2 q = ivec2(gl_FragCoord.xy) & 3;
  const int bayer[16] = int[16](0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5);
  float angle = 6.2831853 * (float(bayer[q.y * 4 + q.x]) + 0.5) / 16.0;
  vec3 r = vec3(cos(angle), sin(angle), 0.0);
  vec3 t = r - n * dot(r, n);
  t = dot(t, t) > 1e-6 ? normalize(t) : normalize(cross(n, vec3(0.0, 0.0, 1.0)));
  mat3 tbn = mat3(t, cross(n, t), n);
  float occlusion = 0.0;
  for (int i = 0; i < 16; ++i) {
    vec3 s = p + tbn * uKernel[i] * uRadius;
    vec4 o = uProj * vec4(s, 1.0);
    vec2 suv = o.xy / o.w * 0.5 + 0.5;
    if (any(lessThan(suv, vec2(0.0))) || any(greaterThan(suv, vec2(1.0)))) continue;
    if (texture(uNormal, suv).a < 0.5) continue;  // the terrain occludes nothing
    float sceneZ = viewPos(suv).z;
    float range = smoothstep(0.0, 1.0, uRadius / max(abs(p.z - sceneZ), 1e-4));
    occlusion += (sceneZ >= s.z + 0.02 * uRadius ? 1.0 : 0.0) * range;
  }
  float ao = clamp(1.0 - uStrength * occlusion / 16.0, 0.0, 1.0);
  // Far away a pixel spans more than the radius and depth precision fails: fade out (40-80 m).
  fragAo = vec4(vec3(mix(ao, 1.0, smoothstep(40.0, 80.0, -p.z))), 1.0);
}
)GLSL";

/// Edge-preserving (depth-aware, bilateral) 4x4 blur of the AO, the size of the rotation pattern
/// it removes: a neighbour counts by how close its view depth is to this pixel's (weight 1 at the
/// same depth, 0 beyond uDepthTolerance of it, relative), so the grass' occlusion does not bleed
/// onto the far ground or the sky behind a silhouette, nor the open ground's onto the grass.
inline constexpr const char* kBlurFragment = R"GLSL(#version 330 core
uniform sampler2D uSource;  // raw AO, half resolution
uniform sampler2D uDepth;   // prepass depth, full resolution
uniform mat4 uInvProj;
uniform float uDepthTolerance;
out vec4 fragAo;
// View depth (m) of the full-resolution texel the occlusion pass used for half-resolution pixel
// `cell` (the sky: the far plane).
float viewDepth(ivec2 cell) {
  ivec2 full = textureSize(uDepth, 0);
  ivec2 texel = min(2 * cell, full - 1);
  vec2 uv = (vec2(texel) + 0.5) / vec2(full);
  vec4 p = uInvProj * vec4(vec3(uv, texelFetch(uDepth, texel, 0).r) * 2.0 - 1.0, 1.0);
  return -p.z / p.w;
}
void main() {
  ivec2 size = textureSize(uSource, 0);
  ivec2 c = ivec2(gl_FragCoord.xy);
  float zc = viewDepth(c);
  float sum = 0.0, weights = 0.0;
  for (int y = -2; y < 2; ++y)
    for (int x = -2; x < 2; ++x) {
      ivec2 q = clamp(c + ivec2(x, y), ivec2(0), size - 1);
      float w = max(0.0, 1.0 - abs(viewDepth(q) - zc) / (uDepthTolerance * zc));
      sum += texelFetch(uSource, q, 0).r * w;
      weights += w;
    }
  fragAo = vec4(vec3(weights > 0.0 ? sum / weights : texelFetch(uSource, c, 0).r), 1.0);
}
)GLSL";

/// The fragment shader of the tuft-vertex capture (transform feedback with rasterisation off:
/// never runs, but a program needs one).
inline constexpr const char* kCaptureFragment = R"GLSL(#version 330 core
out vec4 fragColour;
void main() { fragColour = vec4(1.0); }
)GLSL";

// ---- debug overlay ----------------------------------------------------------------------------

inline constexpr const char* kDebugVertex = R"GLSL(#version 330 core
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aColour;
layout(location = 2) in float aSize;  // point size, pixels
uniform mat4 uViewProj;
out vec3 vColour;
void main() {
  vColour = aColour;
  gl_PointSize = aSize;
  gl_Position = uViewProj * vec4(aPosition, 1.0);
}
)GLSL";

inline constexpr const char* kDebugFragment = R"GLSL(#version 330 core
in vec3 vColour;
out vec4 fragColour;
void main() { fragColour = vec4(vColour, 1.0); }
)GLSL";

}  // namespace sg::viewer::shaders
