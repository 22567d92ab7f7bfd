// An 8-bit grayscale heightmap image, decoded from PNG bytes (libspng). 0 = flat, 255 = the
// scenario's maximum height. Decoding is pure: the caller reads the file.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace sg {

struct Heightmap {
  int width = 0;                 ///< samples along x
  int height = 0;                ///< samples along z
  std::vector<uint8_t> samples;  ///< row-major, z rows of x samples
};

/// Decodes an 8-bit single-channel PNG. On failure returns false and sets *error to what was
/// expected ("an 8-bit grayscale PNG, got 16-bit", ...).
bool decodeHeightmapPng(std::span<const uint8_t> bytes, Heightmap* out, std::string* error);

}  // namespace sg
