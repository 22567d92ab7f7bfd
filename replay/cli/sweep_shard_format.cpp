#include "replay/cli/sweep_shard_format.h"

#include <xxhash.h>
#include <zstd.h>

#include <cstring>
#include <stdexcept>

#include "sim/state/byte_order.h"

namespace sg::sweep {
namespace {
constexpr char kShardMagic[8] = {'S', 'G', 'S', 'W', 'E', 'E', 'P', '1'};
constexpr uint64_t kShardJsonBytes = uint64_t(64) << 20;

void put64(std::vector<uint8_t>& out, uint64_t v) {
  const size_t at = out.size();
  out.resize(at + 8);
  storeLE<uint64_t>(out.data() + at, v);
}
void putDoubles(std::vector<uint8_t>& out, const std::vector<double>& v) {
  put64(out, v.size());
  const size_t at = out.size();
  out.resize(at + 8 * v.size());
  for (size_t i = 0; i < v.size(); ++i) storeLE<double>(out.data() + at + 8 * i, v[i]);
}

/// Reads a payload back, every length checked against what is left (a damaged shard is an
/// error at its offset, never an allocation it cannot back).
struct Reader {
  const std::vector<uint8_t>& bytes;
  size_t at = 0;
  const std::string& file;
  uint64_t u64(const char* what) {
    if (bytes.size() - at < 8) failInput(file, "payload byte " + std::to_string(at), what);
    const uint64_t v = loadLE<uint64_t>(bytes.data() + at);
    at += 8;
    return v;
  }
  std::vector<double> doubles(const char* what) {
    const uint64_t n = u64(what);
    if (n > (bytes.size() - at) / 8) failInput(file, "payload byte " + std::to_string(at - 8), what);
    std::vector<double> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = loadLE<double>(bytes.data() + at + 8 * i);
    at += 8 * n;
    return v;
  }
};

}  // namespace

void failInput(const std::string& file, const std::string& where, const std::string& what) {
  throw std::runtime_error(file + ": " + where + ": expected " + what);
}

/// The reference shard's payload: the reference recording's bytes and the observations.
std::vector<uint8_t> referencePayload(const sgr::Recording& recording, const std::vector<Observation>& observed) {
  std::vector<uint8_t> raw;
  put64(raw, recording.bytes.size());
  raw.insert(raw.end(), recording.bytes.begin(), recording.bytes.end());
  put64(raw, observed.size());
  for (const Observation& o : observed) {
    put64(raw, uint64_t(o.tick));
    put64(raw, uint64_t(o.patchesX));
    put64(raw, uint64_t(o.patchesZ));
    put64(raw, uint64_t(o.contacts));
    putDoubles(raw, o.tipX);
    putDoubles(raw, o.tipY);
    putDoubles(raw, o.tipZ);
    putDoubles(raw, o.bodyPosition);
    putDoubles(raw, o.bodyOrientation);
  }
  return raw;
}

void readReferencePayload(const std::vector<uint8_t>& raw, const std::string& file,
                          std::unique_ptr<sgr::Recording>* recording, std::vector<Observation>* observed) {
  Reader r{raw, 0, file};
  const uint64_t n = r.u64("the reference recording's size");
  if (n > raw.size() - r.at) failInput(file, "payload byte 0", "a reference recording within the shard");
  std::vector<uint8_t> bytes(raw.begin() + std::ptrdiff_t(r.at), raw.begin() + std::ptrdiff_t(r.at + n));
  r.at += n;
  try {
    *recording = std::make_unique<sgr::Recording>(sgr::parseRecording(std::move(bytes), file));
  } catch (const sgr::RecordingError& e) {
    failInput(file, "payload", std::string("an intact reference recording (") + e.what() + ")");
  }
  const uint64_t count = r.u64("the observation count");
  if (count > raw.size() / 40) failInput(file, "payload", "an observation count that fits the shard");
  observed->clear();
  for (uint64_t k = 0; k < count; ++k) {
    Observation o;
    o.tick = int64_t(r.u64("an observation's tick"));
    o.patchesX = int64_t(r.u64("its patches"));
    o.patchesZ = int64_t(r.u64("its patches"));
    o.contacts = int64_t(r.u64("its contacts"));
    o.tipX = r.doubles("its tips");
    o.tipY = r.doubles("its tips");
    o.tipZ = r.doubles("its tips");
    o.bodyPosition = r.doubles("its body positions");
    o.bodyOrientation = r.doubles("its body orientations");
    observed->push_back(std::move(o));
  }
  if (r.at != raw.size()) failInput(file, "payload byte " + std::to_string(r.at), "the end of the payload");
}

/// Shard bytes: magic, u32 JSON length, the JSON header, u64 payload length, the payload (zstd),
/// u64 xxHash3 of everything before it. Little-endian.
std::vector<uint8_t> shardBytes(const nlohmann::json& header, const std::vector<uint8_t>& payload) {
  const std::string text = header.dump();
  std::vector<uint8_t> packed;
  if (!payload.empty()) {
    packed.resize(ZSTD_compressBound(payload.size()));
    const size_t n = ZSTD_compress(packed.data(), packed.size(), payload.data(), payload.size(), 3);
    if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
    packed.resize(n);
  }
  std::vector<uint8_t> out(kShardMagic, kShardMagic + 8);
  out.resize(12);
  storeLE<uint32_t>(out.data() + 8, uint32_t(text.size()));
  out.insert(out.end(), text.begin(), text.end());
  put64(out, packed.size());
  out.insert(out.end(), packed.begin(), packed.end());
  put64(out, XXH3_64bits(out.data(), out.size()));
  return out;
}

Shard parseShard(const std::vector<uint8_t>& b, const std::string& path, uint64_t maxPayload, bool withPayload) {
  if (b.size() < 8 || std::memcmp(b.data(), kShardMagic, 8) != 0) failInput(path, "byte 0", "a sweep shard (SGSWEEP1)");
  if (b.size() < 12 + 8 + 8) failInput(path, "byte 8", "a complete shard (it is cut off)");
  const uint64_t sum = loadLE<uint64_t>(b.data() + b.size() - 8);
  if (XXH3_64bits(b.data(), b.size() - 8) != sum)
    failInput(path, "byte " + std::to_string(b.size() - 8), "the shard's checksum (the file is damaged)");
  const uint32_t textBytes = loadLE<uint32_t>(b.data() + 8);
  if (textBytes > kShardJsonBytes || 12 + uint64_t(textBytes) + 16 > b.size())
    failInput(path, "byte 8", "a header length within the shard");
  Shard s;
  s.header = nlohmann::json::parse(b.begin() + 12, b.begin() + 12 + textBytes, nullptr, false);
  if (!s.header.is_object()) failInput(path, "byte 12", "a JSON header");
  const size_t at = 12 + textBytes;
  const uint64_t packed = loadLE<uint64_t>(b.data() + at);
  if (packed != b.size() - at - 16) failInput(path, "byte " + std::to_string(at), "a payload length within the shard");
  if (packed > 0 && withPayload) {
    const uint8_t* src = b.data() + at + 8;
    const unsigned long long size = ZSTD_getFrameContentSize(src, packed);
    if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN || size > maxPayload)
      failInput(path, "byte " + std::to_string(at + 8), "a zstd payload of a known size within the plan's bounds");
    s.payload.resize(size);
    const size_t n = ZSTD_decompress(s.payload.data(), s.payload.size(), src, packed);
    if (ZSTD_isError(n) || n != size) failInput(path, "byte " + std::to_string(at + 8), "an intact zstd payload");
  }
  return s;
}

}  // namespace sg::sweep
