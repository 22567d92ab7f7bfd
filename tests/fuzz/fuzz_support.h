// Shared fixtures of the libFuzzer targets (tests/fuzz/CMakeLists.txt): one small scenario with
// every kind of body (sphere, box, mower) for the input-track and state targets, and a 4x4
// heightmap PNG served to the scenario target by its file reader.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim/scenario/scenario.h"

namespace sg::fuzz {

/// 6x6 tufts, three bodies, a two-command script: small enough for thousands of worlds a second.
inline const char* const kScenarioText = R"({
  "format": "simgrass-scenario/1",
  "name": "fuzz",
  "field": {"patchesX": 6, "patchesZ": 6, "spacing": 0.25, "center": [0, 0]},
  "particles": {"constraintLength": 0.5, "tiltDrop": [0.1, 0.15, 0.2]},
  "bodies": {
    "list": [
      {"name": "ball", "shape": {"type": "sphere", "radius": 0.3}, "mass": 0.5, "position": [-0.5, 0.3, 0]},
      {"name": "box", "shape": {"type": "box", "halfExtents": [0.2, 0.2, 0.2]}, "mass": 2, "position": [0.5, 0.2, 0]},
      {"name": "mower", "shape": {"type": "box", "halfExtents": [0.3, 0.1, 0.2]}, "mass": 5, "position": [0, 0.1, 0.5], "mower": true}
    ]
  },
  "script": [
    {"tick": 3, "body": "ball", "command": "addVelocity", "value": [2, 0, 0.5]},
    {"tick": 5, "body": "box", "command": "impulse", "value": [0, 1, -0.5]}
  ]
})";

/// An 8-bit grayscale 4x4 PNG (made with Python's zlib): the heightmap every file name resolves to.
inline const std::vector<uint8_t>& heightmapPng() {
  static const std::vector<uint8_t> png = {
      0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00,
      0x00, 0x00, 0x04, 0x00, 0x00, 0x00, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00, 0x8c, 0x9a, 0xc1, 0xa2, 0x00,
      0x00, 0x00, 0x1c, 0x49, 0x44, 0x41, 0x54, 0x78, 0xda, 0x63, 0x60, 0xd5, 0xf2, 0x2f, 0x61, 0x10, 0x30,
      0x8d, 0xaa, 0x67, 0x90, 0x76, 0x48, 0xed, 0x62, 0x50, 0xf3, 0x2e, 0x98, 0x0a, 0x00, 0x29, 0x04, 0x04,
      0xd1, 0xfc, 0x9f, 0x83, 0xf2, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
  return png;
}

/// The fixed scenario, parsed once.
inline const Scenario& fixedScenario() {
  static const Scenario s = parseScenario(kScenarioText, "fuzz-scenario.json", {});
  return s;
}

}  // namespace sg::fuzz
