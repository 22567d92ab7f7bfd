#include "sim/terrain/heightmap.h"

#include <spng.h>
#include <zlib.h>

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

uint32_t readBE32(const uint8_t* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

/// Walks the chunk frames of a PNG that spng decoded (so every frame up to IEND is whole and its
/// CRC checked): a PLTE chunk or bytes after IEND give the reason, else "".
std::string chunkLayoutProblem(std::span<const uint8_t> bytes) {
  size_t at = 8;  // after the signature
  while (at + 12 <= bytes.size()) {
    const uint32_t length = readBE32(bytes.data() + at);
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

/// Bytes of filtered scanlines (a filter byte and the samples of every row) that an 8-bit
/// grayscale image of width x height holds: one image, or Adam7's seven reduced ones.
size_t filteredImageBytes(uint32_t width, uint32_t height, bool adam7) {
  if (!adam7) return size_t(height) * (size_t(width) + 1);
  static constexpr uint32_t x0[7] = {0, 4, 0, 2, 0, 1, 0}, z0[7] = {0, 0, 4, 0, 2, 0, 1};
  static constexpr uint32_t dx[7] = {8, 8, 4, 4, 2, 2, 1}, dz[7] = {8, 8, 8, 4, 4, 2, 2};
  size_t total = 0;
  for (int pass = 0; pass < 7; ++pass) {
    if (x0[pass] >= width || z0[pass] >= height) continue;  // an empty pass has no filter bytes
    const size_t columns = (width - x0[pass] + dx[pass] - 1) / dx[pass];
    const size_t rows = (height - z0[pass] + dz[pass] - 1) / dz[pass];
    total += rows * (columns + 1);
  }
  return total;
}

struct InflateEnd {
  void operator()(z_stream* z) const { inflateEnd(z); }
};

/// Inflates the IDAT stream of a PNG spng decoded, to its very end, and gives the reason it is not
/// one whole zlib stream of exactly the image's filtered bytes (else ""). spng stops reading once
/// the image is complete, so on its own it accepts a stream cut right after the image's last byte
/// (no Adler-32: a file truncated inside its checksum) or followed by more data (a stream glued
/// to another). zlib checks the Adler-32 when it reaches the stream's end. The output goes to a
/// fixed scratch buffer and stops one byte past the expected size: no allocation grows with it.
std::string idatStreamProblem(std::span<const uint8_t> bytes, size_t expected) {
  z_stream z{};
  if (inflateInit(&z) != Z_OK) return "a PNG decoder (zlib: out of memory)";
  const std::unique_ptr<z_stream, InflateEnd> guard(&z);
  uint8_t scratch[16384];
  size_t produced = 0;
  bool ended = false;
  size_t streamEndAt = 0;  // the file offset just after the stream's last byte
  for (size_t at = 8; at + 12 <= bytes.size();) {
    const uint32_t length = readBE32(bytes.data() + at);
    const std::string_view type(reinterpret_cast<const char*>(bytes.data() + at + 4), 4);
    const size_t data = at + 8;
    if (type == "IEND") break;
    if (type == "IDAT" && length > 0) {
      if (ended)
        return "nothing after the end of the image's zlib stream (" + std::to_string(length) +
               " more IDAT bytes at byte " + std::to_string(data) + ")";
      z.next_in = const_cast<Bytef*>(bytes.data() + data);  // zlib's API is not const
      z.avail_in = uInt(length);                            // a chunk is < 2^31 bytes (PNG spec)
      // Until this chunk's bytes are used up and zlib holds no output back (a full scratch
      // buffer may leave some in its window), or the stream ends.
      for (bool full = true; !ended && (z.avail_in > 0 || full);) {
        z.next_out = scratch;
        z.avail_out = uInt(sizeof scratch);
        const int r = inflate(&z, Z_NO_FLUSH);
        produced += sizeof scratch - z.avail_out;
        full = z.avail_out == 0;
        const size_t where = data + (length - z.avail_in);
        if (produced > expected)
          return "image data that inflates to exactly " + std::to_string(expected) +
                 " bytes (the zlib stream holds more, by byte " + std::to_string(where) + ")";
        if (r == Z_STREAM_END) {
          ended = true;
          streamEndAt = where;
        } else if (r == Z_BUF_ERROR && z.avail_in == 0) {
          // No progress without more input: the next IDAT chunk's bytes.
        } else if (r != Z_OK) {  // (Z_BUF_ERROR with input left cannot happen: output is free)
          return "a readable PNG (damaged image data at byte " + std::to_string(where) + ": " +
                 (r == Z_DATA_ERROR && z.msg ? z.msg : "a zlib error") + ")";
        }
      }
      if (ended && z.avail_in > 0)
        return "nothing after the end of the image's zlib stream (" + std::to_string(z.avail_in) +
               " more bytes at byte " + std::to_string(streamEndAt) + ")";
    }
    at = data + size_t(length) + 4;
  }
  if (!ended)
    return "image data whose zlib stream ends with its Adler-32 checksum (the stream stops after " +
           std::to_string(produced) + " of " + std::to_string(expected) + " bytes, unfinished)";
  if (produced != expected)
    return "image data that inflates to exactly " + std::to_string(expected) + " bytes, got " +
           std::to_string(produced) + " (the stream ends at byte " + std::to_string(streamEndAt) + ")";
  return "";
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
  // What spng does not read: the zlib stream past the image's last byte (its Adler-32).
  const size_t filtered = filteredImageBytes(ihdr.width, ihdr.height, ihdr.interlace_method != 0);
  if (const std::string why = idatStreamProblem(bytes, filtered); !why.empty()) {
    *error = why;
    return false;
  }
  out->width = int(ihdr.width);
  out->height = int(ihdr.height);
  out->samples = std::move(samples);
  return true;
}
}  // namespace sg
