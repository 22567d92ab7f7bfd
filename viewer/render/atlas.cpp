// The procedural tuft atlas and ground texture (see atlas.h).
//
// Colour handling: blades are painted and composited in linear RGB with premultiplied alpha
// (float), then every tile is stored as straight (not premultiplied) alpha with sRGB-encoded
// colour bytes, as PNG expects. Randomness is a splitmix64 stream seeded from (seed, tile):
// the images depend on the arguments only.
#include "viewer/render/atlas.h"

#include <stb/stb_image_write.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "replay/output_file.h"

namespace sg::viewer {
namespace {

constexpr float kPi = 3.14159265358979f;

// ---- randomness ----------------------------------------------------------------------------

uint64_t splitmix64(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// One hash of a few integers (a splitmix64 step per value).
uint64_t hashOf(uint64_t seed, uint64_t a, uint64_t b = 0, uint64_t c = 0) {
  uint64_t state = seed;
  uint64_t h = splitmix64(state);
  for (uint64_t v : {a, b, c}) {
    state ^= v + 0x632BE59BD9B4E019ull + (h << 6) + (h >> 2);
    h ^= splitmix64(state);
  }
  return h;
}

struct Rng {
  uint64_t state;
  explicit Rng(uint64_t seed) : state(seed) {}
  /// Uniform in [0, 1) with 24 bits.
  float unit() { return float(splitmix64(state) >> 40) * (1.0f / 16777216.0f); }
  float uniform(float lo, float hi) { return lo + (hi - lo) * unit(); }
  /// Roughly normal in [-1, 1] (sum of three uniforms), mean 0.
  float centred() { return (unit() + unit() + unit()) * (2.0f / 3.0f) - 1.0f; }
  int below(int n) { return int(splitmix64(state) % uint64_t(n)); }
};

// ---- colour --------------------------------------------------------------------------------

struct Rgb {
  float r = 0, g = 0, b = 0;
};
Rgb operator*(Rgb c, float k) { return {c.r * k, c.g * k, c.b * k}; }
Rgb operator+(Rgb a, Rgb b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }
Rgb lerp(Rgb a, Rgb b, float t) { return a * (1.0f - t) + b * t; }
float luminance(Rgb c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

float srgbToLinear(float s) { return s <= 0.04045f ? s / 12.92f : std::pow((s + 0.055f) / 1.055f, 2.4f); }
float linearToSrgb(float l) { return l <= 0.0031308f ? l * 12.92f : 1.055f * std::pow(l, 1.0f / 2.4f) - 0.055f; }
Rgb fromSrgb(float r, float g, float b) { return {srgbToLinear(r), srgbToLinear(g), srgbToLinear(b)}; }

uint8_t toByte(float unit) { return uint8_t(std::lround(std::clamp(unit, 0.0f, 1.0f) * 255.0f)); }

/// sRGB byte -> linear, tabulated.
const std::array<float, 256>& decodeTable() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[size_t(i)] = srgbToLinear(float(i) / 255.0f);
    return t;
  }();
  return table;
}

/// Linear 0..1 -> sRGB byte (nearest).
uint8_t encodeSrgb(float linear) {
  linear = std::clamp(linear, 0.0f, 1.0f);
  return toByte(linearToSrgb(linear));
}

void storeTexel(uint8_t* px, Rgb c, float alpha) {
  px[0] = encodeSrgb(c.r);
  px[1] = encodeSrgb(c.g);
  px[2] = encodeSrgb(c.b);
  px[3] = toByte(alpha);
}

/// Brightness level 0..3: a bent tuft shows more of its lit side, brighter and a little yellower
/// (`yellowing` 1 for grass; paint stays whiter).
Rgb levelColour(Rgb c, int level, float yellowing) {
  const float l = float(level);
  const float k = 1.0f + 0.2f * l;
  return {std::min(1.0f, c.r * k * (1.0f + 0.07f * yellowing * l)), std::min(1.0f, c.g * k),
          std::min(1.0f, c.b * k * (1.0f - 0.08f * yellowing * l))};
}

// ---- one tuft, painted in linear premultiplied RGBA ----------------------------------------

struct Vec2 {
  float x = 0, y = 0;
};

struct Blade {
  Vec2 p0, p1, p2;  ///< quadratic Bézier, base -> tip (tile texels, y down)
  float halfWidth;  ///< at the base
  Rgb base, tip;    ///< linear colours
  float litSide;    ///< +1 / -1: the side facing the light
};

/// A tuft: premultiplied linear RGBA floats, tileSize x tileSize, row 0 at the top.
struct TuftLayer {
  int size = 0;
  std::vector<float> rgba;
};

struct TuftStyle {
  Rgb base, tip;      ///< linear colours at a blade's base and tip
  float hueJitter;    ///< per-blade red/blue jitter (linear)
  float valueJitter;  ///< per-blade relative brightness jitter
  float depthShade;   ///< how much darker the backmost blade is than the frontmost
};

constexpr int kSegments = 20;

void paintBlade(TuftLayer& layer, const Blade& blade) {
  const int n = layer.size;
  std::array<Vec2, kSegments + 1> pts{};
  std::array<float, kSegments + 1> hw{};
  for (int i = 0; i <= kSegments; ++i) {
    const float t = float(i) / float(kSegments);
    const float a = (1 - t) * (1 - t), b = 2 * (1 - t) * t, c = t * t;
    pts[size_t(i)] = {a * blade.p0.x + b * blade.p1.x + c * blade.p2.x,
                      a * blade.p0.y + b * blade.p1.y + c * blade.p2.y};
    // Widest a little above the base, pointed tip.
    hw[size_t(i)] = blade.halfWidth * (0.85f + 0.15f * std::min(1.0f, t / 0.2f)) * std::pow(1.0f - t, 0.7f);
  }
  float minX = 1e9f, maxX = -1e9f, minY = 1e9f, maxY = -1e9f;
  for (const Vec2& p : pts) {
    minX = std::min(minX, p.x), maxX = std::max(maxX, p.x);
    minY = std::min(minY, p.y), maxY = std::max(maxY, p.y);
  }
  const float margin = blade.halfWidth + 1.5f;
  const int x0 = std::max(0, int(std::floor(minX - margin))), x1 = std::min(n - 1, int(std::ceil(maxX + margin)));
  const int y0 = std::max(0, int(std::floor(minY - margin))), y1 = std::min(n - 1, int(std::ceil(maxY + margin)));
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const Vec2 p{float(x) + 0.5f, float(y) + 0.5f};
      // The segment the texel lies deepest inside (largest w - d), not the first to cover it.
      float bestDepth = -1e9f, bestT = 0, bestSide = 0;
      for (int i = 0; i < kSegments; ++i) {
        const Vec2 a = pts[size_t(i)], b = pts[size_t(i) + 1];
        const float dx = b.x - a.x, dy = b.y - a.y;
        const float len2 = dx * dx + dy * dy;
        float s = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0.0f;
        s = std::clamp(s, 0.0f, 1.0f);
        const float qx = p.x - (a.x + s * dx), qy = p.y - (a.y + s * dy);
        const float d = std::sqrt(qx * qx + qy * qy);
        const float w = hw[size_t(i)] + s * (hw[size_t(i) + 1] - hw[size_t(i)]);
        if (w - d > bestDepth) {
          bestDepth = w - d;
          bestT = (float(i) + s) / float(kSegments);
          const float cross = dx * qy - dy * qx;  // which side of the midrib
          bestSide = (cross >= 0 ? 1.0f : -1.0f) * std::min(1.0f, d / std::max(w, 0.5f));
        }
      }
      const float best = std::clamp(bestDepth + 0.5f, 0.0f, 1.0f);  // coverage
      if (best <= 0) continue;
      // Darker base, lighter tip; the lit half of the blade brighter, the edges a little darker.
      Rgb c = lerp(blade.base, blade.tip, std::pow(bestT, 0.8f));
      const float side = bestSide * blade.litSide;
      c = c * ((1.0f + 0.16f * side) * (1.0f - 0.18f * bestSide * bestSide * std::fabs(bestSide)));
      float* dst = layer.rgba.data() + (size_t(y) * size_t(n) + size_t(x)) * 4;
      const float keep = 1.0f - best;
      dst[0] = c.r * best + dst[0] * keep;
      dst[1] = c.g * best + dst[1] * keep;
      dst[2] = c.b * best + dst[2] * keep;
      dst[3] = best + dst[3] * keep;
    }
  }
}

TuftLayer paintTuft(uint64_t seed, int size, const TuftStyle& style) {
  TuftLayer layer{size, std::vector<float>(size_t(size) * size_t(size) * 4, 0.0f)};
  Rng rng(seed);
  const float n = float(size);
  const int blades = 30 + rng.below(11);  // 30..40
  const float lightFromLeft = rng.unit() < 0.5f ? 1.0f : -1.0f;
  for (int i = 0; i < blades; ++i) {
    Blade blade{};
    // Back blades first (darker: they sit in the tuft's shadow), front blades last.
    const float depth = float(i) / float(blades - 1);
    const float offset = rng.centred() * 0.2f;  // base position, tile widths from the centre
    blade.p0 = {n * (0.5f + offset), n + 1.0f};
    float lean = offset * 2.6f + rng.centred() * 0.5f;
    lean = std::clamp(lean, -0.95f, 0.95f);
    const float height = n * rng.uniform(0.5f, 0.97f) * (1.0f - 0.25f * std::fabs(lean));
    const float droop = rng.uniform(0.0f, 0.45f);  // extra bend toward the tip
    const float tipAngle = lean * (1.0f + droop);
    Vec2 tip{blade.p0.x + height * std::sin(tipAngle), blade.p0.y - height * std::cos(tipAngle)};
    tip.x = std::clamp(tip.x, 3.0f, n - 4.0f);
    tip.y = std::max(tip.y, 2.0f);
    const float ctrlAngle = lean * rng.uniform(0.2f, 0.5f);
    const float ctrlLen = height * 0.55f;
    blade.p1 = {blade.p0.x + ctrlLen * std::sin(ctrlAngle), blade.p0.y - ctrlLen * std::cos(ctrlAngle)};
    blade.p2 = tip;
    blade.halfWidth = n * rng.uniform(0.014f, 0.03f);
    const float value = (1.0f + style.valueJitter * rng.centred()) * (1.0f - style.depthShade * (1.0f - depth));
    const float hue = style.hueJitter * rng.centred();
    const Rgb shift{hue, 0.0f, -0.5f * hue};
    blade.base = (style.base + shift * 0.4f) * value;
    blade.tip = (style.tip + shift) * value;
    blade.litSide = lightFromLeft;
    paintBlade(layer, blade);
  }
  return layer;
}

TuftStyle grassStyle(uint64_t seed) {
  Rng rng(seed);
  // A variant's overall tint: fresher / yellower / bluer green.
  const float yellow = rng.centred() * 0.6f;
  const float value = 1.0f + rng.centred() * 0.12f;
  TuftStyle s{};
  s.base = fromSrgb(0.15f + 0.04f * yellow, 0.27f, 0.07f) * value;
  s.tip = fromSrgb(0.45f + 0.12f * yellow, 0.66f + 0.03f * yellow, 0.20f - 0.05f * yellow) * value;
  s.hueJitter = 0.04f;
  s.valueJitter = 0.12f;
  s.depthShade = 0.38f;
  return s;
}

TuftStyle markingStyle() {
  TuftStyle s{};
  s.base = fromSrgb(0.87f, 0.89f, 0.85f);  // paint over green: a trace of green at the base
  s.tip = fromSrgb(0.98f, 0.98f, 0.97f);
  s.hueJitter = 0.01f;
  s.valueJitter = 0.04f;
  s.depthShade = 0.12f;
  return s;
}

/// Copies a tuft into the atlas at level `level`: straight alpha, sRGB bytes; transparent texels
/// get the tuft's mean colour (what filtering and mipmaps blend with), the padding the tile's
/// edge colour at alpha 0.
void storeTile(Image& image, int x0, int y0, int padding, const TuftLayer& layer, int level, float yellowing) {
  const int n = layer.size;
  double sum[3] = {0, 0, 0}, weight = 0;
  for (size_t i = 0; i < layer.rgba.size(); i += 4) {
    sum[0] += layer.rgba[i], sum[1] += layer.rgba[i + 1], sum[2] += layer.rgba[i + 2];
    weight += layer.rgba[i + 3];
  }
  const Rgb mean = weight > 0 ? Rgb{float(sum[0] / weight), float(sum[1] / weight), float(sum[2] / weight)} : Rgb{};
  const Rgb meanAtLevel = levelColour(mean, level, yellowing);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const float* src = layer.rgba.data() + (size_t(y) * size_t(n) + size_t(x)) * 4;
      const float a = src[3];
      // Alpha at or below 1/510 rounds to 0: such texels take the fill colour.
      const Rgb c =
          a > 0.5f / 255.0f ? levelColour(Rgb{src[0] / a, src[1] / a, src[2] / a}, level, yellowing) : meanAtLevel;
      storeTexel(image.at(x0 + x, y0 + y), c, a);
    }
  }
  // Padding: clamp-to-edge copies of the border texels, alpha 0.
  for (int y = -padding; y < n + padding; ++y) {
    for (int x = -padding; x < n + padding; ++x) {
      if (x >= 0 && x < n && y >= 0 && y < n) continue;
      const uint8_t* edge = image.at(x0 + std::clamp(x, 0, n - 1), y0 + std::clamp(y, 0, n - 1));
      uint8_t* dst = image.at(x0 + x, y0 + y);
      dst[0] = edge[0], dst[1] = edge[1], dst[2] = edge[2], dst[3] = 0;
    }
  }
}

int nextPowerOfTwo(int v) {
  int p = 1;
  while (p < v) p *= 2;
  return p;
}

// ---- tiling value noise --------------------------------------------------------------------

float smooth(float t) { return t * t * (3.0f - 2.0f * t); }

/// Value noise with lattice cells of `cell` texels that wraps every `size` texels (cell divides
/// size: both powers of two). In [0, 1).
float tilingNoise(uint64_t seed, int x, int y, int cell, int size) {
  const int period = std::max(1, size / cell);
  const int ix = x / cell, iy = y / cell;
  const float fx = smooth((float(x % cell) + 0.5f) / float(cell)), fy = smooth((float(y % cell) + 0.5f) / float(cell));
  auto lattice = [&](int i, int j) {
    return float(hashOf(seed, uint64_t(i % period), uint64_t(j % period)) >> 40) * (1.0f / 16777216.0f);
  };
  const float a = lattice(ix, iy), b = lattice(ix + 1, iy), c = lattice(ix, iy + 1), d = lattice(ix + 1, iy + 1);
  return (a + (b - a) * fx) * (1 - fy) + (c + (d - c) * fx) * fy;
}

/// Octaves from `largest` texels down to 4, amplitude halving; in [0, 1), mean about 0.5.
float tilingFbm(uint64_t seed, int x, int y, int largest, int size) {
  float sum = 0, total = 0, amp = 1;
  int octave = 0;
  for (int cell = std::min(largest, size); cell >= 4; cell /= 2, amp *= 0.5f, ++octave) {
    sum += amp * tilingNoise(hashOf(seed, uint64_t(octave)), x, y, cell, size);
    total += amp;
  }
  return total > 0 ? sum / total : 0.5f;
}

float stretch(float n, float k) { return std::clamp((n - 0.5f) * k + 0.5f, 0.0f, 1.0f); }

}  // namespace

// ---- TuftAtlas -----------------------------------------------------------------------------

TuftAtlas::Rect TuftAtlas::tile(int variant, int level) const {
  if (variant < 0 || variant > variants || level < 0 || level >= levels)
    throw std::out_of_range("TuftAtlas::tile: no tile (" + std::to_string(variant) + ", " + std::to_string(level) +
                            ")");
  const int cell = tileSize + 2 * padding;
  const float x = float(variant * cell + padding), y = float(level * cell + padding);
  const float w = float(image.width), h = float(image.height);
  return {x / w, y / h, (x + float(tileSize)) / w, (y + float(tileSize)) / h};
}

std::array<float, 3> TuftAtlas::meanColour(int variant, int level) const {
  if (variant < 0 || variant > variants || level < 0 || level >= levels)
    throw std::out_of_range("TuftAtlas::meanColour: no tile (" + std::to_string(variant) + ", " +
                            std::to_string(level) + ")");
  const auto& decode = decodeTable();
  const int cell = tileSize + 2 * padding;
  const int x0 = variant * cell + padding, y0 = level * cell + padding;
  double sum[3] = {0, 0, 0};
  size_t count = 0;
  for (int y = y0; y < y0 + tileSize; ++y) {
    for (int x = x0; x < x0 + tileSize; ++x) {
      const uint8_t* px = image.at(x, y);
      if (px[3] <= 127) continue;
      for (int c = 0; c < 3; ++c) sum[c] += decode[px[c]];
      ++count;
    }
  }
  if (count == 0) return {0, 0, 0};
  return {float(sum[0] / double(count)), float(sum[1] / double(count)), float(sum[2] / double(count))};
}

TuftAtlas makeTuftAtlas(int variants, uint64_t seed, int tileSize, int padding) {
  if (variants < 1 || variants > 16)
    throw std::invalid_argument("makeTuftAtlas: variants must be 1..16, got " + std::to_string(variants));
  if (tileSize < 16 || tileSize > 1024)
    throw std::invalid_argument("makeTuftAtlas: tileSize must be 16..1024, got " + std::to_string(tileSize));
  if (padding < 0 || padding > tileSize)
    throw std::invalid_argument("makeTuftAtlas: padding must be 0..tileSize, got " + std::to_string(padding));
  TuftAtlas atlas;
  atlas.variants = variants;
  atlas.levels = 4;
  atlas.tileSize = tileSize;
  atlas.padding = padding;
  const int cell = tileSize + 2 * padding;
  atlas.image.width = nextPowerOfTwo((variants + 1) * cell);
  atlas.image.height = nextPowerOfTwo(atlas.levels * cell);
  atlas.image.rgba.assign(size_t(atlas.image.width) * size_t(atlas.image.height) * 4, 0);

  for (int v = 0; v <= variants; ++v) {
    const bool marking = v == variants;
    const uint64_t tuftSeed = hashOf(seed, marking ? 0x4D41524Bull /* "MARK" */ : uint64_t(v), 1);
    const TuftLayer layer =
        paintTuft(tuftSeed, tileSize, marking ? markingStyle() : grassStyle(hashOf(seed, uint64_t(v), 2)));
    for (int l = 0; l < atlas.levels; ++l)
      storeTile(atlas.image, v * cell + padding, l * cell + padding, padding, layer, l, marking ? 0.25f : 1.0f);
  }
  // The area outside the grid (power-of-two rounding): transparent, level-0 grass colour, so the
  // smallest mipmaps are not darkened by it.
  const auto fill = atlas.meanColour(0, 0);
  const uint8_t fillPx[4] = {encodeSrgb(fill[0]), encodeSrgb(fill[1]), encodeSrgb(fill[2]), 0};
  for (int y = 0; y < atlas.image.height; ++y)
    for (int x = 0; x < atlas.image.width; ++x)
      if (x >= (variants + 1) * cell || y >= atlas.levels * cell) std::memcpy(atlas.image.at(x, y), fillPx, 4);
  return atlas;
}

// ---- ground --------------------------------------------------------------------------------

Image makeGroundTexture(const TuftAtlas& atlas, uint64_t seed, int size) {
  if (size < 4 || size > 8192 || (size & (size - 1)) != 0)
    throw std::invalid_argument("makeGroundTexture: size must be a power of two in 4..8192, got " +
                                std::to_string(size));
  std::vector<Rgb> palette;
  for (int v = 0; v < atlas.variants; ++v) {
    const auto m = atlas.meanColour(v, 0);
    palette.push_back({m[0], m[1], m[2]});
  }
  const Rgb soilRef = fromSrgb(0.40f, 0.30f, 0.19f);
  const float soilLum = luminance(soilRef);
  const uint64_t seedVariant = hashOf(seed, 0x47524E44ull, 1), seedLight = hashOf(seed, 0x47524E44ull, 2),
                 seedSoil = hashOf(seed, 0x47524E44ull, 3);
  const size_t texels = size_t(size) * size_t(size);
  std::vector<Rgb> colour(texels);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      // Which variant's colour: broad patches, blended between neighbours.
      const float nv = stretch(tilingFbm(seedVariant, x, y, size / 4, size), 2.0f) * float(palette.size() - 1);
      const size_t i0 = std::min(palette.size() - 1, size_t(nv));
      const size_t i1 = std::min(palette.size() - 1, i0 + 1);
      const Rgb grass = lerp(palette[i0], palette[i1], nv - float(i0));
      // Darkening: the ground is the shadowed bottom of the sward, kGroundDarkening on average.
      const float nl = stretch(tilingFbm(seedLight, x, y, size / 8, size), 2.2f);
      const Rgb dark = grass * (kGroundDarkening * (0.45f + 1.1f * nl));
      // Patches of bare soil, at the same brightness as the grass around them.
      const float ns = tilingFbm(seedSoil, x, y, size / 4, size);
      const float soil = 0.7f * std::clamp((ns - 0.52f) / 0.2f, 0.0f, 1.0f);
      const Rgb soilColour = soilRef * (luminance(dark) / soilLum);
      colour[size_t(y) * size_t(size) + size_t(x)] = lerp(dark, soilColour, smooth(soil));
    }
  }
  // Fine detail: short light and dark strokes (fallen blades, stems), wrapping at the edges.
  std::vector<float> shade(texels, 1.0f);
  Rng rng(hashOf(seed, 0x47524E44ull, 4));
  for (size_t i = 0; i < texels / 5; ++i) {
    const float x = rng.uniform(0.0f, float(size)), y = rng.uniform(0.0f, float(size));
    const float angle = rng.uniform(0.0f, 2.0f * kPi), length = rng.uniform(2.0f, 5.0f);
    const float f = rng.unit() < 0.5f ? rng.uniform(0.68f, 0.85f) : rng.uniform(1.15f, 1.32f);
    const float dx = std::cos(angle), dy = std::sin(angle);
    for (float t = 0; t <= length; t += 0.5f) {
      const int px = (int(std::floor(x + t * dx)) % size + size) % size;
      const int py = (int(std::floor(y + t * dy)) % size + size) % size;
      shade[size_t(py) * size_t(size) + size_t(px)] = f;
    }
  }
  Image img;
  img.width = img.height = size;
  img.rgba.assign(texels * 4, 255);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const size_t i = size_t(y) * size_t(size) + size_t(x);
      storeTexel(img.at(x, y), colour[i] * shade[i], 1.0f);
    }
  return img;
}

Image makeRockTexture(uint64_t seed, int size) {
  if (size < 4 || size > 8192 || (size & (size - 1)) != 0)
    throw std::invalid_argument("makeRockTexture: size must be a power of two in 4..8192, got " + std::to_string(size));
  const Rgb light = fromSrgb(0.56f, 0.54f, 0.50f), dark = fromSrgb(0.36f, 0.34f, 0.31f);
  const Rgb lichen = fromSrgb(0.50f, 0.50f, 0.36f);
  const uint64_t seedTone = hashOf(seed, 0x524F434Bull /* "ROCK" */, 1), seedCrack = hashOf(seed, 0x524F434Bull, 2),
                 seedLichen = hashOf(seed, 0x524F434Bull, 3), seedGrain = hashOf(seed, 0x524F434Bull, 4);
  Image img;
  img.width = img.height = size;
  img.rgba.assign(size_t(size) * size_t(size) * 4, 255);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      // Broad tone variation, then cracks where a second noise crosses its median (ridged: dark
      // thin lines), lichen blotches and a fine grain. Every noise wraps, so the texture tiles.
      const float tone = stretch(tilingFbm(seedTone, x, y, size / 4, size), 1.8f);
      Rgb c = lerp(dark, light, tone);
      const float ridge = std::fabs(tilingFbm(seedCrack, x, y, size / 8, size) - 0.5f);
      c = c * (0.55f + 0.45f * smooth(std::clamp(ridge / 0.025f, 0.0f, 1.0f)));
      const float l = std::clamp((tilingFbm(seedLichen, x, y, size / 8, size) - 0.6f) / 0.1f, 0.0f, 1.0f);
      c = lerp(c, lichen * (luminance(c) / luminance(lichen)), 0.6f * smooth(l));
      const float grain = tilingNoise(seedGrain, x, y, 4, size);
      storeTexel(img.at(x, y), c * (0.88f + 0.24f * grain), 1.0f);
    }
  return img;
}

// ---- PNG -----------------------------------------------------------------------------------

bool encodePng(const Image& image, std::vector<uint8_t>* png, std::string* error) {
  if (image.width <= 0 || image.height <= 0 || image.rgba.size() != size_t(image.width) * size_t(image.height) * 4) {
    if (error)
      *error = "not a valid RGBA image (" + std::to_string(image.width) + " x " + std::to_string(image.height) + ")";
    return false;
  }
  png->clear();
  auto append = [](void* context, void* data, int size) {
    auto* out = static_cast<std::vector<uint8_t>*>(context);
    const auto* bytes = static_cast<const uint8_t*>(data);
    out->insert(out->end(), bytes, bytes + size);
  };
  if (stbi_write_png_to_func(append, png, image.width, image.height, 4, image.rgba.data(), image.width * 4) == 0) {
    if (error) *error = "cannot encode the PNG";
    return false;
  }
  return true;
}

bool writePng(const std::string& path, const Image& image, std::string* error) {
  // Encoded in memory, then written atomically with every write checked (a full disk is an
  // error, never a truncated PNG left behind).
  std::vector<uint8_t> png;
  std::string why;
  if (!encodePng(image, &png, &why)) {
    if (error) *error = path + ": " + why;
    return false;
  }
  std::string e;
  if (!writeFileAtomic(path, png, &e)) {
    if (error) *error = e;
    return false;
  }
  return true;
}

}  // namespace sg::viewer
