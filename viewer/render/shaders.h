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

vec3 lit(vec3 albedo, vec3 n) {
  return albedo * (uAmbient + uSunColour * max(dot(n, uSunDir), 0.0));
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

inline constexpr const char* kTuftVertex = R"GLSL(#version 330 core
layout(location = 0) in vec4 aRoot;  // root x, y, z; half width
layout(location = 1) in vec4 aTop;   // top y; tip offset x, z; angle (rad)
layout(location = 2) in vec2 aTile;  // atlas variant, brightness level
uniform mat4 uViewProj;
uniform vec4 uTiles[68];             // (variants + 1) * levels tile rects: u0, v0 (top), u1, v1
uniform int uLevels;
out vec2 vUv;
out float vUp;                       // 0 at the root, 1 at the top
out vec3 vWorld;
void main() {
  // Triangle strip 0..3: bottom-left, bottom-right, top-left, top-right (thesis §2 vertices).
  int corner = gl_VertexID;
  float side = (corner & 1) == 0 ? -1.0 : 1.0;
  bool top = corner >= 2;
  vec3 along = vec3(cos(aTop.w), 0.0, -sin(aTop.w)) * aRoot.w;
  vec3 p = aRoot.xyz + side * along;
  if (top) p = vec3(p.x + aTop.y, aTop.x, p.z + aTop.z);
  vec4 tile = uTiles[int(aTile.x + 0.5) * uLevels + int(aTile.y + 0.5)];
  vUv = vec2(side < 0.0 ? tile.x : tile.z, top ? tile.y : tile.w);
  vUp = top ? 1.0 : 0.0;
  vWorld = p;
  gl_Position = uViewProj * vec4(p, 1.0);
}
)GLSL";

inline constexpr const char* kTuftFragment = R"GLSL(
uniform sampler2D uAtlas;
uniform vec2 uAtlasSize;
uniform bool uAlphaToCoverage;
in vec2 vUv;
in float vUp;
in vec3 vWorld;
out vec4 fragColour;
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
  // All normals up (thesis §2): both faces light alike. Darker toward the root stands in for the
  // thesis' SSAO (the lower part of a tuft sits in the others' shade).
  vec3 c = lit(t.rgb, vec3(0.0, 1.0, 0.0)) * mix(0.42, 1.0, vUp) * shadowAt(vWorld);
  fragColour = vec4(fogged(c, vWorld), a);
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
in vec3 vWorld;
in vec3 vNormal;
out vec4 fragColour;
void main() {
  // Two lookups at unrelated scales and angles hide the texture's repeat at a distance.
  vec3 near = texture(uGround, vWorld.xz / uGroundTile).rgb;
  vec3 far = texture(uGround, mat2(0.8, -0.6, 0.6, 0.8) * vWorld.xz / (2.7 * uGroundTile) + vec2(0.31, 0.57)).rgb;
  vec3 albedo = mix(near, far, 0.45) * uGroundShade;
  vec3 c = lit(albedo, normalize(vNormal)) * shadowAt(vWorld);
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

}  // namespace sg::viewer::shaders
