// libFuzzer target for the `.sgr` reader: any bytes must give a Recording or an
// sgr::RecordingError (from parseRecording, snapshotState or recordedScenario), never a crash, an
// uncaught exception, a hang or a huge allocation. Built by tests/fuzz/CMakeLists.txt (Clang,
// SIMGRASS_BUILD_FUZZ=ON; the clang-asan and clang-release presets), which also registers the
// ctest runs.
//
// Every input is read twice: as it is, and with every complete chunk's checksum (and the HEAD's
// scenario hash) recomputed. A random mutation almost never keeps an XXH3 checksum right, so
// without the second pass the fuzzer would only ever meet the checksum check and never the field
// checks, the snapshot decompression and the scenario parser behind it.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include <xxhash.h>

#include "replay/format/sgr_reader.h"
#include "replay/player.h"

namespace {
namespace sgr = sg::sgr;

/// Scenario texts larger than this are not parsed (the reader itself allows 256 MiB of HEAD).
constexpr size_t kMaxScenarioText = size_t(64) << 10;

template <class T>
T load(const std::vector<uint8_t>& b, size_t at) {
  T v;
  std::memcpy(&v, b.data() + at, sizeof v);
  return v;
}

void readAll(std::vector<uint8_t> bytes) {
  sgr::Recording r;
  try {
    r = sgr::parseRecording(std::move(bytes), "fuzz.sgr");
  } catch (const sgr::RecordingError&) {
    return;
  }
  for (const sgr::SnapshotInfo& s : r.snapshots) {
    try {
      (void)r.snapshotState(s);
    } catch (const sgr::RecordingError&) {
    }
  }
  const int64_t last = r.lastTick();
  (void)r.inputAt(last);
  (void)r.inputAt(r.header.startTick);
  (void)r.snapshotAtOrBefore(last);
  if (r.header.scenarioText.size() > kMaxScenarioText) return;
  try {
    (void)sg::recordedScenario(r);
  } catch (const sgr::RecordingError&) {
  }
}

/// The HEAD payload at `payload` (of `length` bytes): points its scenario hash at its text.
void fixScenarioHash(std::vector<uint8_t>& b, size_t payload, uint32_t length) {
  size_t at = 36;  // the fixed fields; then the variant, source and text strings
  for (int field = 0; field < 3; ++field) {
    if (length < 4 || at > length - 4) return;
    const uint32_t n = load<uint32_t>(b, payload + at);
    if (n > length - 4 - at) return;
    if (field == 2) {
      const uint64_t hash = XXH3_64bits(b.data() + payload + at + 4, n);
      std::memcpy(b.data() + payload + 12, &hash, sizeof hash);
    }
    at += 4 + n;
  }
}

/// Recomputes the checksum of every complete chunk (and the first HEAD's scenario hash).
/// Returns false when nothing changed.
bool repairChecksums(std::vector<uint8_t>& b) {
  const std::vector<uint8_t> before = b;
  size_t at = sgr::kPreambleBytes;
  bool first = true;
  while (b.size() >= at && b.size() - at >= sgr::kChunkHeaderBytes) {
    const uint32_t type = load<uint32_t>(b, at);
    const uint32_t length = load<uint32_t>(b, at + 4);
    const uint64_t total = sgr::kChunkHeaderBytes + uint64_t(length) + sgr::kChunkTrailerBytes;
    if (total > b.size() - at) break;
    if (first && type == uint32_t(sgr::ChunkType::Head)) fixScenarioHash(b, at + sgr::kChunkHeaderBytes, length);
    first = false;
    const uint64_t sum = XXH3_64bits(b.data() + at, sgr::kChunkHeaderBytes + length);
    std::memcpy(b.data() + at + sgr::kChunkHeaderBytes + length, &sum, sizeof sum);
    at += size_t(total);
  }
  return b != before;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  readAll(bytes);
  if (repairChecksums(bytes)) readAll(std::move(bytes));
  return 0;
}
