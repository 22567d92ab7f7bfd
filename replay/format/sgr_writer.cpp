#include "replay/format/sgr_writer.h"
#include "sim/state/byte_order.h"

#include <fcntl.h>
#include <unistd.h>

#include <xxhash.h>
#include <zstd.h>
#include <bit>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace sg::sgr {
namespace {
// Little-endian append helpers: explicit byte order, so a recording made on a big-endian host
// (s390x) is the same bytes as one made on x86-64.
template <class T>
void put(std::vector<uint8_t>& out, T value) {
  const size_t at = out.size();
  out.resize(at + sizeof(T));
  storeLE(out.data() + at, value);
}
void putString(std::vector<uint8_t>& out, const std::string& s) {
  put<uint32_t>(out, uint32_t(s.size()));
  out.insert(out.end(), s.begin(), s.end());
}
void putVec3(std::vector<uint8_t>& out, const InputVec3& v) {
  put<int64_t>(out, v.x);
  put<int64_t>(out, v.y);
  put<int64_t>(out, v.z);
}
[[noreturn]] void ioFail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what + ": " + std::strerror(errno));
}
}  // namespace

std::vector<uint8_t> encodeHead(const Header& h) {
  std::vector<uint8_t> out;
  put<uint8_t>(out, uint8_t(h.scalar));
  put<uint8_t>(out, 0);
  put<uint16_t>(out, 0);
  put<uint32_t>(out, h.checkEvery);
  put<uint32_t>(out, h.snapshotEvery);
  put<uint64_t>(out, h.scenarioHash);
  put<uint64_t>(out, h.initialStateHash);
  put<int64_t>(out, h.startTick);
  putString(out, h.variant);
  putString(out, h.scenarioSource);
  putString(out, h.scenarioText);
  put<uint32_t>(out, uint32_t(h.files.size()));
  for (const EmbeddedFile& f : h.files) {
    putString(out, f.name);
    put<uint32_t>(out, uint32_t(f.bytes.size()));
    out.insert(out.end(), f.bytes.begin(), f.bytes.end());
  }
  putString(out, h.buildId);
  return out;
}

std::vector<uint8_t> encodeInput(int64_t tick, const TickInput& input, const TickInput& previous) {
  // flags bit 0: the camera changed (then u8 hasCamera and its position follow).
  std::vector<uint8_t> out;
  put<int64_t>(out, tick);
  const bool cameraChanged = input.hasCamera != previous.hasCamera || input.camera != previous.camera;
  put<uint8_t>(out, cameraChanged ? 1 : 0);
  if (cameraChanged) {
    put<uint8_t>(out, input.hasCamera ? 1 : 0);
    putVec3(out, input.camera);
  }
  put<uint32_t>(out, uint32_t(input.bodies.size()));
  for (const BodyCommand& c : input.bodies) {
    put<int32_t>(out, c.body);
    put<uint8_t>(out, uint8_t(c.kind));
    putVec3(out, c.value);
  }
  return out;
}

std::vector<uint8_t> encodeCheck(const Check& c) {
  std::vector<uint8_t> out;
  put<int64_t>(out, c.tick);
  put<uint64_t>(out, c.hash);
  return out;
}

std::vector<uint8_t> encodeSnapshot(int64_t tick, uint64_t hash, std::span<const uint8_t> state, int level) {
  std::vector<uint8_t> out;
  put<int64_t>(out, tick);
  put<uint64_t>(out, hash);
  put<uint64_t>(out, uint64_t(state.size()));
  const size_t header = out.size();
  out.resize(header + ZSTD_compressBound(state.size()));
  const size_t n = ZSTD_compress(out.data() + header, out.size() - header, state.data(), state.size(), level);
  if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
  out.resize(header + n);
  return out;
}

std::vector<uint8_t> encodeEnd(const EndInfo& e) {
  std::vector<uint8_t> out;
  put<int64_t>(out, e.tick);
  put<uint64_t>(out, e.hash);
  put<uint8_t>(out, e.faulted ? 1 : 0);
  putString(out, e.message);
  return out;
}

std::vector<uint8_t> frameChunk(ChunkType type, std::span<const uint8_t> payload) {
  std::vector<uint8_t> out;
  out.reserve(payload.size() + kChunkHeaderBytes + kChunkTrailerBytes);
  put<uint32_t>(out, uint32_t(type));
  put<uint32_t>(out, uint32_t(payload.size()));
  out.insert(out.end(), payload.begin(), payload.end());
  put<uint64_t>(out, XXH3_64bits(out.data(), out.size()));
  return out;
}

Writer::Writer(const std::string& path, const Header& header) : path_(path) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) ioFail(path, "cannot create the recording");
  pending_.insert(pending_.end(), std::begin(kMagic), std::end(kMagic));
  put<uint32_t>(pending_, kFormatVersion);
  append(ChunkType::Head, encodeHead(header));
  flush();
}

Writer::~Writer() {
  if (fd_ >= 0) {
    try {
      flush();
    } catch (...) {  // a destructor must not throw; the file stays readable up to here
    }
    ::close(fd_);
  }
}

void Writer::append(ChunkType type, std::span<const uint8_t> payload) {
  if (fd_ < 0) throw std::runtime_error(path_ + ": the recording is already closed");
  const std::vector<uint8_t> chunk = frameChunk(type, payload);
  pending_.insert(pending_.end(), chunk.begin(), chunk.end());
}

void Writer::input(int64_t tick, const TickInput& in) {
  const bool cameraChanged = in.hasCamera != previous_.hasCamera || in.camera != previous_.camera;
  if (cameraChanged || !in.bodies.empty()) append(ChunkType::Input, encodeInput(tick, in, previous_));
  previous_.hasCamera = in.hasCamera;
  previous_.camera = in.camera;
}

void Writer::check(const Check& c) { append(ChunkType::Check, encodeCheck(c)); }

void Writer::snapshot(int64_t tick, uint64_t hash, std::span<const uint8_t> state) {
  append(ChunkType::Snapshot, encodeSnapshot(tick, hash, state, zstdLevel));
}

void Writer::end(const EndInfo& e) {
  append(ChunkType::End, encodeEnd(e));
  flush();
  if (::fsync(fd_) != 0 && errno != EINVAL) ioFail(path_, "cannot sync the recording");
  if (::close(fd_) != 0) {
    fd_ = -1;
    ioFail(path_, "cannot close the recording");
  }
  fd_ = -1;
}

void Writer::flush() {
  size_t done = 0;
  while (done < pending_.size()) {
    const ssize_t n = ::write(fd_, pending_.data() + done, pending_.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      ioFail(path_, "cannot write the recording");
    }
    done += size_t(n);
  }
  written_ += pending_.size();
  pending_.clear();
}

}  // namespace sg::sgr
