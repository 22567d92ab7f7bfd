#include "sim/terrain/heightmap.h"

#include <spng.h>

#include <cstring>
#include <memory>
#include <string>
#include <string_view>

namespace {

/// The largest ancillary chunk kept and the most bytes all kept chunks (text, ICC profiles, ...,
/// after decompression) may take: a heightmap needs none of them, so these only stop a small file
/// from asking spng for a large allocation (a zTXt decompression bomb). Chunks over the limits are
/// an error, not skipped: a heightmap with a 1 MiB comment is not a file someone meant to feed us.
constexpr size_t kMaxChunkBytes = size_t(1) << 20;
constexpr size_t kMaxChunkCacheBytes = size_t(4) << 20;
/// Heightmap sides (samples); scenario_json.cpp may cap the total further.
constexpr uint32_t kMinSide = 2, kMaxSide = 4096;  // = kMaxHeightmapSide (sim/scenario/scenario.h)

struct ContextFree {
  void operator()(spng_ctx* ctx) const { spng_ctx_free(ctx); }
};

std::string readable(int err) {
  // spng's own words but for the one that hides the Adler-32 check.
  if (err == SPNG_EIDAT_STREAM) return "a readable PNG (damaged image data: a zlib error or a wrong Adler-32)";
  const char* r = spng_strerror(err);
  return std::string("a readable PNG (") + (r && *r ? r : "corrupt or truncated") + ")";
}

const char* colourTypeName(uint8_t type) {
  switch (type) {
    case SPNG_COLOR_TYPE_GRAYSCALE:
      return "grayscale";
    case SPNG_COLOR_TYPE_TRUECOLOR:
      return "RGB";
    case SPNG_COLOR_TYPE_INDEXED:
      return "palette";
    case SPNG_COLOR_TYPE_GRAYSCALE_ALPHA:
      return "grayscale+alpha";
    case SPNG_COLOR_TYPE_TRUECOLOR_ALPHA:
      return "RGBA";
    default:
      return "unknown colour type";
  }
}

/// Walks the chunk frames of a PNG that spng decoded (so every frame up to IEND is whole and its
/// CRC checked): a PLTE chunk or bytes after IEND give the reason, else "".
std::string chunkLayoutProblem(std::span<const uint8_t> bytes) {
  size_t at = 8;  // after the signature
  while (at + 12 <= bytes.size()) {
    const uint32_t length = uint32_t(bytes[at]) << 24 | uint32_t(bytes[at + 1]) << 16 | uint32_t(bytes[at + 2]) << 8 |
                            uint32_t(bytes[at + 3]);
    const std::string_view type(reinterpret_cast<const char*>(bytes.data() + at + 4), 4);
    if (type == "PLTE") return "a grayscale PNG without a palette (PLTE chunk at byte " + std::to_string(at) + ")";
    const size_t next = at + 12 + size_t(length);
    if (type == "IEND") {
      if (next != bytes.size())
        return "the end of the PNG file after its IEND chunk (byte " + std::to_string(next) + " of " +
               std::to_string(bytes.size()) + ")";
      return "";
    }
    at = next;
  }
  return "";  // spng found IEND, so this is not reached for a decoded file
}

}  // namespace

namespace sg {
// libspng (not stb_image): it checks every chunk's CRC and the zlib stream's Adler-32, so a
// damaged heightmap is an error rather than a silently different terrain (docs/dependencies.md).
bool decodeHeightmapPng(std::span<const uint8_t> bytes, Heightmap* out, std::string* error) {
  static const uint8_t kPngMagic[8] = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kPngMagic, 8) != 0) {
    *error = "a PNG file (the PNG signature is missing)";
    return false;
  }
  if (bytes.size() > (size_t(1) << 30)) {
    *error = "a PNG file smaller than 1 GiB";
    return false;
  }
  const std::unique_ptr<spng_ctx, ContextFree> ctx(spng_ctx_new(0));
  if (!ctx) {
    *error = "a PNG decoder (out of memory)";
    return false;
  }
  // Checksums: spng's defaults are already "error" for both critical and ancillary chunk CRCs and
  // for the Adler-32 (no SPNG_CTX_IGNORE_ADLER32); set explicitly so that a changed default cannot
  // quietly turn them off.
  int err = spng_set_crc_action(ctx.get(), SPNG_CRC_ERROR, SPNG_CRC_ERROR);
  if (!err) err = spng_set_chunk_limits(ctx.get(), kMaxChunkBytes, kMaxChunkCacheBytes);
  if (!err) err = spng_set_png_buffer(ctx.get(), bytes.data(), bytes.size());
  spng_ihdr ihdr{};
  if (!err) err = spng_get_ihdr(ctx.get(), &ihdr);
  if (err) {
    *error = readable(err);
    return false;
  }
  if (ihdr.color_type != SPNG_COLOR_TYPE_GRAYSCALE || ihdr.bit_depth != 8) {
    *error = "an 8-bit grayscale PNG, got a " + std::to_string(ihdr.bit_depth) + "-bit " +
             colourTypeName(ihdr.color_type) + " PNG";
    return false;
  }
  // The size is checked before anything is decoded: the decoded image is width*height bytes, so
  // this bounds the one large allocation (16 MiB at 4096x4096). It is done here rather than
  // with spng_set_image_limits, whose error would hide the declared size from the message.
  if (ihdr.width < kMinSide || ihdr.height < kMinSide || ihdr.width > kMaxSide || ihdr.height > kMaxSide) {
    *error = "a heightmap between 2x2 and 4096x4096 samples, got " + std::to_string(ihdr.width) + "x" +
             std::to_string(ihdr.height);
    return false;
  }
  size_t size = 0;
  err = spng_decoded_image_size(ctx.get(), SPNG_FMT_PNG, &size);
  if (!err && size != size_t(ihdr.width) * ihdr.height) err = SPNG_EOVERFLOW;
  std::vector<uint8_t> samples;
  if (!err) {
    samples.resize(size);
    // SPNG_FMT_PNG: the file's own 8-bit samples, no gamma, no tRNS, no conversion.
    err = spng_decode_image(ctx.get(), samples.data(), samples.size(), SPNG_FMT_PNG, 0);
  }
  // The chunks after the image up to IEND: a file cut after its image data is truncated too.
  if (!err) err = spng_decode_chunks(ctx.get());
  if (err) {
    *error = readable(err);
    return false;
  }
  // What spng lets pass but the PNG spec forbids: a palette in a grayscale image (PNG 11.2.3) and
  // anything after IEND (a file glued to another, or a second image the decoder never sees).
  if (const std::string why = chunkLayoutProblem(bytes); !why.empty()) {
    *error = why;
    return false;
  }
  out->width = int(ihdr.width);
  out->height = int(ihdr.height);
  out->samples = std::move(samples);
  return true;
}
}  // namespace sg
