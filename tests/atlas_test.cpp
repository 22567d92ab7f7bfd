// The procedural tuft atlas and ground texture (viewer/render/atlas.h): layout, coverage,
// padding, brightness levels, the white marking tuft, determinism, seamless ground, PNG output.
#include <gtest/gtest.h>

#include <stb/stb_image.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>

#include "viewer/render/atlas.h"

namespace sg::viewer {
namespace {

bool isPowerOfTwo(int v) { return v > 0 && (v & (v - 1)) == 0; }

float luminance(const std::array<float, 3>& c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

/// HSV saturation of a colour.
float saturation(const std::array<float, 3>& c) {
  const float hi = std::max({c[0], c[1], c[2]}), lo = std::min({c[0], c[1], c[2]});
  return hi > 0 ? (hi - lo) / hi : 0.0f;
}

/// The inner square of a tile in texels, from its UVs.
struct PixelRect {
  int x0, y0, x1, y1;  // exclusive x1, y1
};
PixelRect pixels(const TuftAtlas& atlas, int variant, int level) {
  const TuftAtlas::Rect r = atlas.tile(variant, level);
  const float w = float(atlas.image.width), h = float(atlas.image.height);
  return {int(std::lround(r.u0 * w)), int(std::lround(r.v0 * h)), int(std::lround(r.u1 * w)),
          int(std::lround(r.v1 * h))};
}

double opaqueFraction(const TuftAtlas& atlas, int variant, int level) {
  const PixelRect p = pixels(atlas, variant, level);
  size_t opaque = 0;
  for (int y = p.y0; y < p.y1; ++y)
    for (int x = p.x0; x < p.x1; ++x) opaque += atlas.image.at(x, y)[3] > 127;
  return double(opaque) / double((p.x1 - p.x0) * (p.y1 - p.y0));
}

/// Mean absolute byte difference between image columns a and b (all rows, RGB).
double columnDifference(const Image& img, int a, int b) {
  double sum = 0;
  for (int y = 0; y < img.height; ++y)
    for (int c = 0; c < 3; ++c) sum += std::abs(int(img.at(a, y)[c]) - int(img.at(b, y)[c]));
  return sum / double(img.height * 3);
}

/// The same for rows.
double rowDifference(const Image& img, int a, int b) {
  double sum = 0;
  for (int x = 0; x < img.width; ++x)
    for (int c = 0; c < 3; ++c) sum += std::abs(int(img.at(x, a)[c]) - int(img.at(x, b)[c]));
  return sum / double(img.width * 3);
}

/// Mean linear colour of an opaque image.
std::array<float, 3> meanLinear(const Image& img) {
  double sum[3] = {0, 0, 0};
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const double s = img.at(x, y)[c] / 255.0;
        sum[c] += s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
      }
  const double n = double(img.width) * double(img.height);
  return {float(sum[0] / n), float(sum[1] / n), float(sum[2] / n)};
}

const TuftAtlas& defaultAtlas() {
  static const TuftAtlas atlas = makeTuftAtlas(4, 2010);
  return atlas;
}

TEST(TuftAtlas, PowerOfTwoSidesHoldAllTiles) {
  for (int variants : {1, 4, 7, 16}) {
    const int tileSize = variants == 16 ? 32 : 64;
    const TuftAtlas atlas = makeTuftAtlas(variants, 5, tileSize, 4);
    SCOPED_TRACE("variants " + std::to_string(variants));
    EXPECT_TRUE(isPowerOfTwo(atlas.image.width)) << atlas.image.width;
    EXPECT_TRUE(isPowerOfTwo(atlas.image.height)) << atlas.image.height;
    EXPECT_EQ(atlas.image.rgba.size(), size_t(atlas.image.width) * size_t(atlas.image.height) * 4);
    EXPECT_EQ(atlas.variants, variants);
    EXPECT_EQ(atlas.levels, 4);
    const int cell = tileSize + 2 * 4;
    EXPECT_GE(atlas.image.width, (variants + 1) * cell);
    EXPECT_GE(atlas.image.height, 4 * cell);
    EXPECT_LT(atlas.image.width, 2 * (variants + 1) * cell);  // the smallest power of two
    EXPECT_LT(atlas.image.height, 2 * 4 * cell);
  }
}

TEST(TuftAtlas, TileRectsLieInsideAndDoNotOverlap) {
  const TuftAtlas& atlas = defaultAtlas();
  std::vector<TuftAtlas::Rect> rects;
  for (int v = 0; v <= atlas.variants; ++v)
    for (int l = 0; l < atlas.levels; ++l) rects.push_back(atlas.tile(v, l));
  ASSERT_EQ(rects.size(), size_t((atlas.variants + 1) * atlas.levels));
  for (size_t i = 0; i < rects.size(); ++i) {
    const auto& r = rects[i];
    EXPECT_GE(r.u0, 0.0f);
    EXPECT_GE(r.v0, 0.0f);
    EXPECT_LE(r.u1, 1.0f);
    EXPECT_LE(r.v1, 1.0f);
    EXPECT_FLOAT_EQ((r.u1 - r.u0) * float(atlas.image.width), float(atlas.tileSize));
    EXPECT_FLOAT_EQ((r.v1 - r.v0) * float(atlas.image.height), float(atlas.tileSize));
    for (size_t j = i + 1; j < rects.size(); ++j) {
      const auto& q = rects[j];
      const bool apart = r.u1 <= q.u0 || q.u1 <= r.u0 || r.v1 <= q.v0 || q.v1 <= r.v0;
      EXPECT_TRUE(apart) << "tiles " << i << " and " << j << " overlap";
    }
  }
  // Rows top to bottom are levels 0..3; columns left to right are variants, marking last.
  EXPECT_LT(atlas.tile(0, 0).v0, atlas.tile(0, 1).v0);
  EXPECT_LT(atlas.tile(0, 0).u0, atlas.tile(atlas.variants, 0).u0);
  EXPECT_THROW(atlas.tile(atlas.variants + 1, 0), std::out_of_range);
  EXPECT_THROW(atlas.tile(0, 4), std::out_of_range);
}

TEST(TuftAtlas, EveryTileIsATuftNotAQuad) {
  const TuftAtlas& atlas = defaultAtlas();
  for (int v = 0; v <= atlas.variants; ++v)
    for (int l = 0; l < atlas.levels; ++l) {
      const double f = opaqueFraction(atlas, v, l);
      EXPECT_GE(f, 0.15) << "tile " << v << "," << l;
      EXPECT_LE(f, 0.70) << "tile " << v << "," << l;
    }
}

TEST(TuftAtlas, AlphaIsBinaryExceptAntialiasedEdges) {
  const TuftAtlas& atlas = defaultAtlas();
  for (int v = 0; v <= atlas.variants; ++v) {
    const PixelRect p = pixels(atlas, v, 0);
    size_t full = 0, partial = 0, bottomRowOpaque = 0;
    for (int y = p.y0; y < p.y1; ++y)
      for (int x = p.x0; x < p.x1; ++x) {
        const uint8_t a = atlas.image.at(x, y)[3];
        full += a == 255;
        partial += a > 0 && a < 255;
        if (y == p.y1 - 1) bottomRowOpaque += a > 127;
      }
    EXPECT_GT(partial, 0u) << "no antialiased edge texels in variant " << v;
    EXPECT_LT(partial, full) << "variant " << v << ": mostly fuzz, not blades";
    EXPECT_GT(bottomRowOpaque, 0u) << "variant " << v << " does not stand on the tile's bottom edge";
    // The tuft is centred: the texels at the bottom corners are empty.
    EXPECT_EQ(atlas.image.at(p.x0, p.y1 - 1)[3], 0);
    EXPECT_EQ(atlas.image.at(p.x1 - 1, p.y1 - 1)[3], 0);
  }
}

TEST(TuftAtlas, BladesAreDarkerAtTheBaseThanAtTheTips) {
  const TuftAtlas& atlas = defaultAtlas();
  for (int v = 0; v < atlas.variants; ++v) {
    const PixelRect p = pixels(atlas, v, 0);
    const int n = p.y1 - p.y0;
    auto bandLuma = [&](int from, int to) {  // mean sRGB green of opaque texels in rows [from, to)
      double sum = 0;
      size_t count = 0;
      for (int y = p.y0 + from; y < p.y0 + to; ++y)
        for (int x = p.x0; x < p.x1; ++x)
          if (atlas.image.at(x, y)[3] > 127) sum += atlas.image.at(x, y)[1], ++count;
      return count ? sum / double(count) : 0.0;
    };
    EXPECT_LT(bandLuma(n * 7 / 8, n), bandLuma(n / 8, n / 2) - 10) << "variant " << v;
  }
}

TEST(TuftAtlas, PaddingAndUnusedAreaAreTransparent) {
  const TuftAtlas small = makeTuftAtlas(3, 9, 48, 5);
  for (const TuftAtlas* atlas : {&defaultAtlas(), &small}) {
    std::vector<bool> inner(size_t(atlas->image.width) * size_t(atlas->image.height), false);
    for (int v = 0; v <= atlas->variants; ++v)
      for (int l = 0; l < atlas->levels; ++l) {
        const PixelRect p = pixels(*atlas, v, l);
        for (int y = p.y0; y < p.y1; ++y)
          for (int x = p.x0; x < p.x1; ++x) inner[size_t(y) * size_t(atlas->image.width) + size_t(x)] = true;
      }
    size_t outside = 0, nonZero = 0;
    for (int y = 0; y < atlas->image.height; ++y)
      for (int x = 0; x < atlas->image.width; ++x)
        if (!inner[size_t(y) * size_t(atlas->image.width) + size_t(x)]) {
          ++outside;
          nonZero += atlas->image.at(x, y)[3] != 0;
        }
    EXPECT_GT(outside, 0u);
    EXPECT_EQ(nonZero, 0u) << "padding texels with alpha > 0";
    // The padding repeats the tile's edge colour (clamp to edge), so sampling does not bleed.
    const PixelRect p = pixels(*atlas, 1, 2);
    for (int k = 1; k <= atlas->padding; ++k) {
      const int y = (p.y0 + p.y1) / 2, x = (p.x0 + p.x1) / 2;
      EXPECT_EQ(0, std::memcmp(atlas->image.at(p.x0 - k, y), atlas->image.at(p.x0, y), 3));
      EXPECT_EQ(0, std::memcmp(atlas->image.at(p.x1 - 1 + k, y), atlas->image.at(p.x1 - 1, y), 3));
      EXPECT_EQ(0, std::memcmp(atlas->image.at(x, p.y0 - k), atlas->image.at(x, p.y0), 3));
      EXPECT_EQ(0, std::memcmp(atlas->image.at(x, p.y1 - 1 + k), atlas->image.at(x, p.y1 - 1), 3));
    }
  }
}

TEST(TuftAtlas, LevelsGetBrighterAndYellower) {
  const TuftAtlas& atlas = defaultAtlas();
  for (int v = 0; v < atlas.variants; ++v)
    for (int l = 0; l + 1 < atlas.levels; ++l) {
      const auto a = atlas.meanColour(v, l), b = atlas.meanColour(v, l + 1);
      EXPECT_GT(luminance(b), luminance(a) * 1.08f) << "variant " << v << " level " << l;
      EXPECT_GT(b[0] / b[1], a[0] / a[1]) << "variant " << v << " level " << l << " not yellower";
    }
  for (int l = 0; l + 1 < atlas.levels; ++l)  // the marking tuft saturates at white, but never darkens
    EXPECT_GE(luminance(atlas.meanColour(atlas.variants, l + 1)), luminance(atlas.meanColour(atlas.variants, l)));
}

TEST(TuftAtlas, MarkingTuftIsWhite) {
  const TuftAtlas& atlas = defaultAtlas();
  for (int l = 0; l < atlas.levels; ++l) {
    const auto marking = atlas.meanColour(atlas.variants, l);
    EXPECT_GT(luminance(marking), 0.7f) << "level " << l;
    EXPECT_LT(saturation(marking), 0.12f) << "level " << l;
    for (int v = 0; v < atlas.variants; ++v) {
      const auto grass = atlas.meanColour(v, l);
      EXPECT_GT(saturation(grass), 0.5f) << "variant " << v << " level " << l;
      EXPECT_GT(grass[1], grass[0]);  // green
      EXPECT_GT(grass[1], grass[2]);
      EXPECT_GT(luminance(marking), 2.0f * luminance(grass)) << "variant " << v << " level " << l;
    }
  }
}

TEST(TuftAtlas, DeterministicPerSeed) {
  const TuftAtlas a = makeTuftAtlas(4, 77, 64, 4), b = makeTuftAtlas(4, 77, 64, 4), c = makeTuftAtlas(4, 78, 64, 4);
  EXPECT_EQ(a.image.rgba, b.image.rgba);
  ASSERT_EQ(a.image.rgba.size(), c.image.rgba.size());
  EXPECT_NE(a.image.rgba, c.image.rgba);
}

TEST(TuftAtlas, VariantsDiffer) {
  const TuftAtlas& atlas = defaultAtlas();
  for (int v = 0; v <= atlas.variants; ++v)
    for (int w = v + 1; w <= atlas.variants; ++w) {
      const PixelRect p = pixels(atlas, v, 0), q = pixels(atlas, w, 0);
      size_t differ = 0;
      for (int y = 0; y < atlas.tileSize; ++y)
        for (int x = 0; x < atlas.tileSize; ++x)
          differ += (atlas.image.at(p.x0 + x, p.y0 + y)[3] > 127) != (atlas.image.at(q.x0 + x, q.y0 + y)[3] > 127);
      EXPECT_GT(double(differ) / double(atlas.tileSize * atlas.tileSize), 0.05) << "variants " << v << " and " << w;
    }
  // Levels of one variant share the shape.
  const PixelRect p = pixels(atlas, 2, 0), q = pixels(atlas, 2, 3);
  for (int y = 0; y < atlas.tileSize; ++y)
    for (int x = 0; x < atlas.tileSize; ++x)
      ASSERT_EQ(atlas.image.at(p.x0 + x, p.y0 + y)[3], atlas.image.at(q.x0 + x, q.y0 + y)[3]);
}

TEST(TuftAtlas, RejectsBadArguments) {
  EXPECT_THROW(makeTuftAtlas(0, 1), std::invalid_argument);
  EXPECT_THROW(makeTuftAtlas(17, 1), std::invalid_argument);
  EXPECT_THROW(makeTuftAtlas(4, 1, 4), std::invalid_argument);
  EXPECT_THROW(makeTuftAtlas(4, 1, 64, -1), std::invalid_argument);
}

TEST(GroundTexture, PowerOfTwoOpaqueAndDeterministic) {
  const TuftAtlas& atlas = defaultAtlas();
  const Image g = makeGroundTexture(atlas, 3, 128);
  EXPECT_EQ(g.width, 128);
  EXPECT_EQ(g.height, 128);
  for (size_t i = 3; i < g.rgba.size(); i += 4) ASSERT_EQ(g.rgba[i], 255);
  EXPECT_EQ(g.rgba, makeGroundTexture(atlas, 3, 128).rgba);
  EXPECT_NE(g.rgba, makeGroundTexture(atlas, 4, 128).rgba);
  EXPECT_THROW(makeGroundTexture(atlas, 3, 100), std::invalid_argument);
  EXPECT_THROW(makeGroundTexture(atlas, 3, 0), std::invalid_argument);
}

TEST(GroundTexture, TilesSeamlessly) {
  for (int size : {64, 256}) {
    const Image g = makeGroundTexture(defaultAtlas(), 11, size);
    SCOPED_TRACE("size " + std::to_string(size));
    double colMax = 0, colSum = 0, rowMax = 0, rowSum = 0;
    for (int i = 0; i + 1 < size; ++i) {
      const double c = columnDifference(g, i, i + 1), r = rowDifference(g, i, i + 1);
      colMax = std::max(colMax, c), colSum += c;
      rowMax = std::max(rowMax, r), rowSum += r;
    }
    const double colMean = colSum / (size - 1), rowMean = rowSum / (size - 1);
    const double colWrap = columnDifference(g, size - 1, 0), rowWrap = rowDifference(g, size - 1, 0);
    EXPECT_LE(colWrap, colMax);
    EXPECT_LE(rowWrap, rowMax);
    EXPECT_LE(colWrap, 2.0 * colMean);
    EXPECT_LE(rowWrap, 2.0 * rowMean);
    // Not trivially seamless: columns far apart differ much more than neighbours.
    EXPECT_GT(columnDifference(g, 0, size / 2), 2.0 * colMean);
    EXPECT_GT(rowDifference(g, 0, size / 2), 2.0 * rowMean);
  }
}

TEST(GroundTexture, MeanColourIsTheGrassDarkened) {
  const TuftAtlas& atlas = defaultAtlas();
  std::array<float, 3> grass{0, 0, 0};
  for (int v = 0; v < atlas.variants; ++v)
    for (int c = 0; c < 3; ++c) grass[size_t(c)] += atlas.meanColour(v, 0)[size_t(c)] / float(atlas.variants);
  const auto ground = meanLinear(makeGroundTexture(atlas, 5, 256));
  const float expected = kGroundDarkening * luminance(grass);
  EXPECT_NEAR(luminance(ground), expected, 0.15f * expected);
  EXPECT_LT(luminance(ground), luminance(grass));
  // Still greenish (soil patches shift it toward brown, not away from green).
  EXPECT_GT(ground[1], ground[0]);
  EXPECT_GT(ground[1], ground[2]);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(ground[size_t(c)], kGroundDarkening * grass[size_t(c)], 0.3f * kGroundDarkening * grass[1]) << c;
  // A different palette gives a different ground: the colours do come from the atlas.
  const TuftAtlas other = makeTuftAtlas(1, 123, 64, 4);
  const auto otherGround = meanLinear(makeGroundTexture(other, 5, 64));
  const auto otherGrass = other.meanColour(0, 0);
  EXPECT_NEAR(luminance(otherGround), kGroundDarkening * luminance(otherGrass),
              0.15f * kGroundDarkening * luminance(otherGrass));
}

TEST(AtlasPng, WritesAFileStbReadsBackIdentically) {
  const TuftAtlas atlas = makeTuftAtlas(2, 6, 32, 4);
  const std::string path = (std::filesystem::path(testing::TempDir()) / "simgrass-atlas-test.png").string();
  std::string error;
  ASSERT_TRUE(writePng(path, atlas.image, &error)) << error;
  int w = 0, h = 0, channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &channels, 4);
  ASSERT_NE(data, nullptr) << stbi_failure_reason();
  EXPECT_EQ(w, atlas.image.width);
  EXPECT_EQ(h, atlas.image.height);
  EXPECT_EQ(channels, 4);
  EXPECT_TRUE(std::equal(atlas.image.rgba.begin(), atlas.image.rgba.end(), data));
  stbi_image_free(data);
  std::filesystem::remove(path);
}

TEST(AtlasPng, MissingDirectoryFailsWithThePath) {
  const std::string path = (std::filesystem::path(testing::TempDir()) / "no-such-dir-simgrass" / "atlas.png").string();
  std::string error;
  EXPECT_FALSE(writePng(path, makeGroundTexture(defaultAtlas(), 1, 16), &error));
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_FALSE(writePng(path, Image{}, &error));
}

TEST(AtlasPng, AFullDiskIsAnErrorAndLeavesNoFileBehind) {
  // A child process with RLIMIT_FSIZE of 4 KiB (SIGXFSZ ignored, so writes fail with EFBIG, as
  // on a full disk): writePng must say so and leave neither the PNG nor a temporary file.
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "simgrass-atlas-full-disk";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "atlas.png").string();
  const Image image = makeRockTexture(7, 256);  // noisy: far more than 4 KiB compressed
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{4096, 4096};
    setrlimit(RLIMIT_FSIZE, &limit);
    std::string error;
    const bool written = writePng(path, image, &error);
    _exit(written ? 10 : error.find(path) == std::string::npos ? 11 : 0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << status;
  EXPECT_EQ(WEXITSTATUS(status), 0) << "10: the write was reported as done; 11: the error does not name the file";
  for (const auto& entry : std::filesystem::directory_iterator(dir)) ADD_FAILURE() << "left behind: " << entry.path();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sg::viewer
