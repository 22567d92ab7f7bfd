// The bytes of a sweep shard (docs/scale-out.md): what a job writes and a merge reads.
//   "SGSWEEP1", u32 header length, the JSON header, u64 payload length, the payload (zstd; empty
//   for a variant), u64 xxHash3-64 of everything before it. Every integer little-endian.
// A reference's payload: u64 length + the reference recording's .sgr bytes, u64 count + the
// observations (tick, patches x, patches z, contacts, then tips x, y, z, body positions and
// orientations, each as u64 count + IEEE doubles).
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "replay/format/sgr_reader.h"
#include "sim/world/sim_world.h"

namespace sg::sweep {

/// Throws std::runtime_error with the one line every sweep input error has:
/// "file: where: expected what".
[[noreturn]] void failInput(const std::string& file, const std::string& where, const std::string& what);

struct Shard {
  nlohmann::json header;
  std::vector<uint8_t> payload;  ///< decompressed (empty when not asked for)
};

/// A shard's bytes (the payload compressed here). Throws std::runtime_error when zstd fails.
std::vector<uint8_t> shardBytes(const nlohmann::json& header, const std::vector<uint8_t>& payload);

/// Checks and parses shard bytes read from `file`: the magic, the checksum, the lengths, the JSON
/// header and (with `withPayload`) the zstd payload, which may not decompress to more than
/// `maxPayload` bytes. Throws std::runtime_error, one line: "file: byte N: expected ...".
Shard parseShard(const std::vector<uint8_t>& bytes, const std::string& file, uint64_t maxPayload, bool withPayload);

/// A reference shard's payload, and back. readReferencePayload throws std::runtime_error ("file:
/// payload byte N: expected ...") for a payload that is not one; every length is checked against
/// what is left before anything is allocated.
std::vector<uint8_t> referencePayload(const sgr::Recording& recording, const std::vector<Observation>& observed);
void readReferencePayload(const std::vector<uint8_t>& raw, const std::string& file,
                          std::unique_ptr<sgr::Recording>* recording, std::vector<Observation>* observed);

}  // namespace sg::sweep
