#include "sim/terrain/heightmap.h"

#include <stb_image.h>

#include <cstring>

namespace {
std::string reason() {
  const char* r = stbi_failure_reason();
  return r && *r ? r : "corrupt or truncated";
}
}  // namespace

namespace sg {
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
  const auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
  const int len = int(bytes.size());
  int w = 0, h = 0, channels = 0;
  if (!stbi_info_from_memory(data, len, &w, &h, &channels)) {
    *error = "a readable PNG (" + reason() + ")";
    return false;
  }
  if (stbi_is_16_bit_from_memory(data, len)) {
    *error = "an 8-bit grayscale PNG, got a 16-bit PNG";
    return false;
  }
  if (channels != 1) {
    *error = "an 8-bit grayscale PNG, got " + std::to_string(channels) + " channels";
    return false;
  }
  if (w < 2 || h < 2 || w > 16384 || h > 16384) {
    *error = "a heightmap between 2x2 and 16384x16384 samples, got " + std::to_string(w) + "x" + std::to_string(h);
    return false;
  }
  stbi_uc* pixels = stbi_load_from_memory(data, len, &w, &h, &channels, 1);
  if (!pixels) {
    *error = "a readable PNG (" + reason() + ")";
    return false;
  }
  out->width = w;
  out->height = h;
  out->samples.assign(pixels, pixels + size_t(w) * size_t(h));
  stbi_image_free(pixels);
  return true;
}
}  // namespace sg
