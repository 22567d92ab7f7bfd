// Heightmap PNG decoding (libspng): every damaged or unsupported file is refused with one line
// "expected ..." before anything is decoded, and valid 8-bit grayscale files decode to their exact
// samples. The fixtures are built here chunk by chunk (zlib's crc32 and compress), so each test
// damages exactly one thing: a stale CRC, a wrong Adler-32, a cut IDAT, another depth or colour
// type, an Adam7 file, a huge declared size, a zTXt decompression bomb.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "sim/terrain/heightmap.h"
#include "tests/test_support.h"

namespace sg {
namespace {

using Bytes = std::vector<uint8_t>;

void put32(Bytes& b, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) b.push_back(uint8_t(v >> s));
}

void chunk(Bytes& png, const char type[4], const Bytes& data) {
  put32(png, uint32_t(data.size()));
  Bytes body(type, type + 4);
  body.insert(body.end(), data.begin(), data.end());
  png.insert(png.end(), body.begin(), body.end());
  put32(png, uint32_t(crc32(0, body.data(), uInt(body.size()))));
}

Bytes deflate(const Bytes& raw) {
  uLongf n = compressBound(uLong(raw.size()));
  Bytes z(n);
  EXPECT_EQ(compress2(z.data(), &n, raw.data(), uLong(raw.size()), 9), Z_OK);
  z.resize(n);
  return z;
}

struct Png {
  uint32_t width = 4, height = 3;
  uint8_t depth = 8, colour = 0, interlace = 0;
  Bytes raw;                  ///< the filtered scanlines (filter byte 0 + row)
  std::vector<Bytes> before;  ///< extra chunks before IDAT, each "TYPE" + data
  bool iend = true;

  Bytes ihdr() const {
    Bytes d;
    put32(d, width);
    put32(d, height);
    d.insert(d.end(), {depth, colour, 0, 0, interlace});
    return d;
  }
  Bytes bytes() const { return build(deflate(raw)); }
  Bytes build(const Bytes& idat) const {
    Bytes png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
    chunk(png, "IHDR", ihdr());
    for (const Bytes& c : before) chunk(png, reinterpret_cast<const char*>(c.data()), Bytes(c.begin() + 4, c.end()));
    chunk(png, "IDAT", idat);
    if (iend) chunk(png, "IEND", {});
    return png;
  }
};

/// The sample at (x, z) of the test images.
uint8_t sampleAt(uint32_t x, uint32_t z) { return uint8_t(37 * x + 11 * z + 5); }

/// A non-interlaced 8-bit grayscale image: rows of filter 0 + samples.
Png gray8(uint32_t w, uint32_t h) {
  Png p;
  p.width = w, p.height = h;
  for (uint32_t z = 0; z < h; ++z) {
    p.raw.push_back(0);
    for (uint32_t x = 0; x < w; ++x) p.raw.push_back(sampleAt(x, z));
  }
  return p;
}

/// The same image Adam7-interlaced: seven reduced images, each with its own filter bytes.
Png gray8Interlaced(uint32_t w, uint32_t h) {
  Png p = gray8(w, h);
  p.interlace = 1;
  p.raw.clear();
  const uint32_t x0[7] = {0, 4, 0, 2, 0, 1, 0}, z0[7] = {0, 0, 4, 0, 2, 0, 1};
  const uint32_t dx[7] = {8, 8, 4, 4, 2, 2, 1}, dz[7] = {8, 8, 8, 4, 4, 2, 2};
  for (int pass = 0; pass < 7; ++pass) {
    if (x0[pass] >= w || z0[pass] >= h) continue;  // an empty pass has no rows, not even a filter byte
    for (uint32_t z = z0[pass]; z < h; z += dz[pass]) {
      p.raw.push_back(0);
      for (uint32_t x = x0[pass]; x < w; x += dx[pass]) p.raw.push_back(sampleAt(x, z));
    }
  }
  return p;
}

/// Decodes and expects a failure whose text contains `phrase` (one line, no crash). The text is
/// what was expected; parseScenario puts "FILE: $.terrain.file: expected " before it.
void expectRefused(const Bytes& png, const std::string& phrase) {
  Heightmap hm;
  hm.width = 77;
  std::string error;
  ASSERT_FALSE(decodeHeightmapPng(png, &hm, &error)) << "accepted; wanted: " << phrase;
  EXPECT_NE(error.find(phrase), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  EXPECT_EQ(hm.width, 77) << "a refused file leaves the output as it was";
}

size_t idatOffset(const Bytes& png) {
  for (size_t i = 8; i + 8 <= png.size();) {
    uint32_t n = 0;
    for (int k = 0; k < 4; ++k) n = n << 8 | png[i + size_t(k)];
    if (std::memcmp(&png[i + 4], "IDAT", 4) == 0) return i;
    i += 12 + n;
  }
  return 0;
}

TEST(HeightmapPng, EightBitGrayDecodesToItsExactSamples) {
  for (const Png& p : {gray8(4, 3), gray8(2, 2), gray8(17, 9)}) {
    Heightmap hm;
    std::string error;
    ASSERT_TRUE(decodeHeightmapPng(p.bytes(), &hm, &error)) << error;
    ASSERT_EQ(hm.width, int(p.width));
    ASSERT_EQ(hm.height, int(p.height));
    ASSERT_EQ(hm.samples.size(), size_t(p.width) * p.height);
    for (uint32_t z = 0; z < p.height; ++z)
      for (uint32_t x = 0; x < p.width; ++x) EXPECT_EQ(hm.samples[z * p.width + x], sampleAt(x, z));
  }
}

// Decision: Adam7 files are accepted. They are valid 8-bit grayscale heightmaps (some tools write
// them), spng de-interlaces them exactly, and the samples are the same as the plain file's.
TEST(HeightmapPng, InterlacedDecodesToTheSameSamplesAsThePlainFile) {
  // 300x70: the filtered bytes (over 21,000) are more than the stream check's 16 KiB output buffer.
  for (const auto& [w, h] : {std::pair{2u, 2u}, {9u, 5u}, {16u, 16u}, {3u, 11u}, {33u, 2u}, {2u, 33u}, {300u, 70u}}) {
    Heightmap plain, adam7;
    std::string error;
    ASSERT_TRUE(decodeHeightmapPng(gray8(w, h).bytes(), &plain, &error)) << error;
    ASSERT_TRUE(decodeHeightmapPng(gray8Interlaced(w, h).bytes(), &adam7, &error)) << w << "x" << h << ": " << error;
    EXPECT_EQ(adam7.samples, plain.samples) << w << "x" << h;
  }
}

TEST(HeightmapPng, CommittedHillsPngStillDecodes) {
  std::ifstream in(test::sourcePath("scenarios/hills.png"), std::ios::binary);
  const Bytes bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Heightmap hm;
  std::string error;
  ASSERT_TRUE(decodeHeightmapPng(bytes, &hm, &error)) << error;
  EXPECT_EQ(hm.width, 129);
  EXPECT_EQ(hm.samples.size(), size_t(129 * 129));
}

/// The offset of the CRC of the chunk at `at` (its 4 bytes follow the data).
size_t crcOffset(const Bytes& png, size_t at) {
  uint32_t n = 0;
  for (int k = 0; k < 4; ++k) n = n << 8 | png[at + size_t(k)];
  return at + 8 + n;
}

TEST(HeightmapPng, StaleCrcIsRefused) {
  // Only the stored CRC changes: the data is intact, so nothing but the CRC check can see it.
  Bytes png = gray8(4, 3).bytes();
  png[crcOffset(png, idatOffset(png)) + 3] ^= 0x01;
  expectRefused(png, "a readable PNG (invalid chunk checksum)");
  Bytes header = gray8(4, 3).bytes();
  header[crcOffset(header, 8) + 3] ^= 0x01;  // IHDR
  expectRefused(header, "a readable PNG (invalid chunk checksum)");
}

TEST(HeightmapPng, StaleCrcOfAnAncillaryChunkIsRefused) {
  Png p = gray8(4, 3);
  p.before.push_back(Bytes{'t', 'E', 'X', 't', 'k', 0, 'v'});
  Bytes png = p.bytes();
  png[crcOffset(png, 8 + 25) + 3] ^= 0x01;  // the tEXt after the signature and the 25-byte IHDR
  expectRefused(png, "a readable PNG (invalid chunk checksum)");
}

TEST(HeightmapPng, WrongAdler32IsRefused) {
  // The zlib stream's checksum is wrong but every chunk CRC is right: only the Adler-32 check
  // can see it (stb_image did not, and decoded the image as if nothing were wrong).
  const Png p = gray8(4, 3);
  Bytes z = deflate(p.raw);
  z.back() ^= 0x01;
  expectRefused(p.build(z), "a readable PNG (damaged image data: a zlib error or a wrong Adler-32)");
}

TEST(HeightmapPng, TruncatedFilesAreRefused) {
  const Png p = gray8(8, 8);
  const Bytes z = deflate(p.raw);
  // The IDAT cut short (its declared length matches the cut, its CRC is right).
  expectRefused(p.build(Bytes(z.begin(), z.begin() + z.size() / 2)), "a readable PNG (");
  // The file cut inside IDAT, and after IDAT with no IEND.
  const Bytes whole = p.bytes();
  const size_t idat = idatOffset(whole);
  expectRefused(Bytes(whole.begin(), whole.begin() + idat + 8 + 4), "a readable PNG (");
  Png noEnd = p;
  noEnd.iend = false;
  expectRefused(noEnd.bytes(), "a readable PNG (");
  // Signature and IHDR only.
  expectRefused(Bytes(whole.begin(), whole.begin() + 33), "a readable PNG (");
}

TEST(HeightmapPng, APaletteInAGrayImageOrBytesAfterIendAreRefused) {
  // The PNG spec forbids PLTE in a grayscale image; spng decodes it anyway.
  Png palette = gray8(4, 3);
  palette.before.push_back(Bytes{'P', 'L', 'T', 'E', 0, 0, 0, 255, 255, 255});
  expectRefused(palette.bytes(), "a grayscale PNG without a palette (PLTE chunk at byte 33)");
  // Bytes glued after IEND: a second image, or another file, that the decoder never sees.
  Bytes glued = gray8(4, 3).bytes();
  const size_t end = glued.size();
  glued.push_back(0);
  expectRefused(glued, "the end of the PNG file after its IEND chunk (byte " + std::to_string(end) + " of " +
                           std::to_string(end + 1) + ")");
  Bytes twice = gray8(4, 3).bytes();
  const Bytes again = gray8(4, 3).bytes();
  twice.insert(twice.end(), again.begin(), again.end());
  expectRefused(twice, "after its IEND chunk");
  // The plain file still decodes.
  Heightmap h;
  std::string error;
  EXPECT_TRUE(decodeHeightmapPng(gray8(4, 3).bytes(), &h, &error)) << error;
}

/// A PNG whose image data is the given IDAT chunks, in order (then IEND).
Bytes withIdats(const Png& p, const std::vector<Bytes>& idats) {
  Png head = p;
  head.iend = false;
  Bytes png = head.build(idats.front());
  for (size_t i = 1; i < idats.size(); ++i) chunk(png, "IDAT", idats[i]);
  chunk(png, "IEND", {});
  return png;
}

// spng stops inflating once the image is whole, so these passed before the core inflated the
// stream to its end itself (docs/robustness.md): each was accepted, and decoded to the image.
TEST(HeightmapPng, AStreamCutInsideItsAdler32OrFollowedByMoreDataIsRefused) {
  const Png p = gray8(6, 5);
  const Bytes z = deflate(p.raw);
  // The Adler-32 missing, or cut after 2 of its 4 bytes: a file truncated inside its checksum.
  expectRefused(p.build(Bytes(z.begin(), z.end() - 4)), "image data whose zlib stream ends with its Adler-32");
  expectRefused(p.build(Bytes(z.begin(), z.end() - 2)), "image data whose zlib stream ends with its Adler-32");
  // Bytes after the stream's end, in the same IDAT and in another one.
  Bytes tail = z;
  tail.insert(tail.end(), {1, 2, 3});
  const size_t streamEnd = idatOffset(p.bytes()) + 8 + z.size();
  expectRefused(p.build(tail), "nothing after the end of the image's zlib stream (3 more bytes at byte " +
                                   std::to_string(streamEnd) + ")");
  expectRefused(withIdats(p, {z, Bytes{0x78}}), "nothing after the end of the image's zlib stream (1 more IDAT bytes");
  // A second whole stream glued behind the first.
  expectRefused(withIdats(p, {z, z}), "nothing after the end of the image's zlib stream");
  // A stream holding more than the image: one scanline too many, with its Adler-32 right.
  Bytes longer = p.raw;
  longer.insert(longer.end(), 7, 0);
  expectRefused(p.build(deflate(longer)), "image data that inflates to exactly 35 bytes (the zlib stream holds more");
  // The same for an interlaced file (its seven passes' filter bytes counted).
  const Png adam7 = gray8Interlaced(9, 5);
  const Bytes za = deflate(adam7.raw);
  expectRefused(adam7.build(Bytes(za.begin(), za.end() - 4)), "image data whose zlib stream ends with its Adler-32");
}

TEST(HeightmapPng, AStreamSplitOverManyIdatChunksStillDecodes) {
  // Valid PNGs: IDAT chunks of one byte each, empty ones between, and an image whose filtered
  // bytes fill the stream check's output buffer more than once.
  for (const Png& p : {gray8(6, 5), gray8(300, 70)}) {
    const Bytes z = deflate(p.raw);
    std::vector<Bytes> bytewise;
    for (uint8_t b : z) {
      bytewise.push_back(Bytes{b});
      bytewise.push_back(Bytes{});
    }
    for (const Bytes& png : {p.bytes(), withIdats(p, bytewise), withIdats(p, {z, Bytes{}})}) {
      Heightmap hm;
      std::string error;
      ASSERT_TRUE(decodeHeightmapPng(png, &hm, &error)) << p.width << "x" << p.height << ": " << error;
      EXPECT_EQ(hm.samples.size(), size_t(p.width) * p.height);
      EXPECT_EQ(hm.samples.back(), sampleAt(p.width - 1, p.height - 1));
    }
  }
}

TEST(HeightmapPng, OtherDepthsAndColourTypesAreRefusedBeforeDecoding) {
  const struct {
    uint8_t depth, colour;
    const char* phrase;
  } cases[] = {{1, 0, "1-bit grayscale"},   {2, 0, "2-bit grayscale"},       {4, 0, "4-bit grayscale"},
               {16, 0, "16-bit grayscale"}, {8, 3, "8-bit palette"},         {4, 3, "4-bit palette"},
               {8, 2, "8-bit RGB"},         {8, 4, "8-bit grayscale+alpha"}, {8, 6, "8-bit RGBA"},
               {16, 2, "16-bit RGB"}};
  for (const auto& c : cases) {
    Png p = gray8(4, 3);
    p.depth = c.depth, p.colour = c.colour;
    if (c.colour == 3) p.before.push_back(Bytes{'P', 'L', 'T', 'E', 0, 0, 0, 255, 255, 255});
    SCOPED_TRACE(c.phrase);
    expectRefused(p.bytes(), std::string("an 8-bit grayscale PNG, got a ") + c.phrase + " PNG");
  }
}

TEST(HeightmapPng, SizesOutsideTheBoundsAreRefusedBeforeDecoding) {
  // The IDAT holds 12 samples whatever the header says: the size check comes first, so a
  // 2^31-1 square (8 EiB of samples) allocates nothing.
  const struct {
    uint32_t w, h;
  } cases[] = {{1, 5}, {5, 1}, {4097, 2}, {2, 4097}, {0x7fffffff, 0x7fffffff}, {100000, 100000}};
  for (const auto& c : cases) {
    Png p = gray8(4, 3);
    p.width = c.w, p.height = c.h;
    expectRefused(p.bytes(), "a heightmap between 2x2 and 4096x4096 samples, got " + std::to_string(c.w) + "x" +
                                 std::to_string(c.h));
  }
  Png zero = gray8(4, 3);
  zero.width = 0;
  expectRefused(zero.bytes(), "a readable PNG (");  // width 0 is not a PNG at all
}

TEST(HeightmapPng, ZtxtDecompressionBombIsRefused) {
  // 64 MiB of zeros compress to ~64 KiB: kept, it would be a 64 MiB allocation for a comment.
  Bytes bomb = {'z', 'T', 'X', 't', 'k', 0, 0};
  const Bytes z = deflate(Bytes(size_t(64) << 20, 0));
  bomb.insert(bomb.end(), z.begin(), z.end());
  Png p = gray8(4, 3);
  p.before.push_back(bomb);
  expectRefused(p.bytes(), "a readable PNG (");
}

TEST(HeightmapPng, NotAPngAtAll) {
  expectRefused({}, "PNG signature");
  expectRefused(Bytes{'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd', '!'}, "PNG signature");
}

}  // namespace
}  // namespace sg
