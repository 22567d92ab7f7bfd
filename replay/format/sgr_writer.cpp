#include "replay/format/sgr_writer.h"
#include "replay/input_file.h"
#include "sim/state/byte_order.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <xxhash.h>
#include <zstd.h>
#include <algorithm>
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

std::string headerProblem(const Header& h) {
  auto tooLong = [](const char* what, uint64_t limit, uint64_t got) {
    return std::string(what) + " of at most " + std::to_string(limit) + " bytes, got " + std::to_string(got);
  };
  if (h.variant.size() > kMaxShortString) return tooLong("variant settings", kMaxShortString, h.variant.size());
  if (h.scenarioSource.size() > kMaxShortString)
    return tooLong("a scenario file name", kMaxShortString, h.scenarioSource.size());
  if (h.buildId.size() > kMaxShortString) return tooLong("a build id", kMaxShortString, h.buildId.size());
  if (h.scenarioText.size() > InputLimits::kScenarioBytes)
    return tooLong("a scenario text", InputLimits::kScenarioBytes, h.scenarioText.size());
  if (h.files.size() > kMaxEmbeddedFiles)
    return "at most " + std::to_string(kMaxEmbeddedFiles) + " embedded files, got " + std::to_string(h.files.size());
  uint64_t total =
      36 + 4 + h.variant.size() + 4 + h.scenarioSource.size() + 4 + h.scenarioText.size() + 4 + 4 + h.buildId.size();
  for (size_t i = 0; i < h.files.size(); ++i) {
    const EmbeddedFile& f = h.files[i];
    if (f.name.size() > kMaxShortString) return tooLong("an embedded file name", kMaxShortString, f.name.size());
    for (size_t k = 0; k < i; ++k)
      if (h.files[k].name == f.name) return "each embedded file name once (" + f.name + " is given twice)";
    total += 4 + f.name.size() + 4 + f.bytes.size();
  }
  if (total > kMaxHeadPayload)
    return tooLong("a HEAD chunk (scenario text and embedded files)", kMaxHeadPayload, total);
  if (h.startTick < 0 || h.startTick > kMaxTickGap)
    return "a start tick from 0 to " + std::to_string(kMaxTickGap) + ", got " + std::to_string(h.startTick);
  return {};
}

std::string inputProblem(const TickInput& input) {
  const uint64_t bytes = inputPayloadBytes(input.bodies.size(), true);
  if (bytes > kMaxInputPayload)
    return "at most " + std::to_string((kMaxInputPayload - inputPayloadBytes(0, true)) / (4 + 1 + 24)) +
           " body commands in one tick (an INPT chunk holds " + std::to_string(kMaxInputPayload) + " bytes), got " +
           std::to_string(input.bodies.size());
  for (const BodyCommand& c : input.bodies)
    if (c.body < 0) return "body indices >= 0, got " + std::to_string(c.body);
  return {};
}

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
  // The reader takes at most kMaxShortString bytes: a longer message is shortened (on a UTF-8
  // character boundary), never a recording the reader refuses.
  size_t n = std::min<size_t>(e.message.size(), kMaxShortString);
  while (n < e.message.size() && n > 0 && (uint8_t(e.message[n]) & 0xC0) == 0x80) --n;
  putString(out, e.message.substr(0, n));
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

Writer::Writer(const std::string& path, const Header& header) : maxBytes(InputLimits::kRecordingBytes), path_(path) {
  // Checked before the file is created: a recording the reader would refuse is never started.
  if (const std::string why = headerProblem(header); !why.empty())
    throw std::runtime_error(path + ": cannot record: expected " + why);
  // O_NONBLOCK: opening a FIFO for writing would wait for a reader for ever; it is refused below
  // (a recording is a file to read back), as is anything but a regular file or a device.
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | O_NONBLOCK | O_NOCTTY, 0644);
  if (fd_ < 0) {
    if (errno == ENXIO) errno = EINVAL;  // a FIFO without a reader
    ioFail(path, "cannot create the recording");
  }
  struct stat st {};
  if (::fstat(fd_, &st) != 0 || !(S_ISREG(st.st_mode) || S_ISCHR(st.st_mode))) {
    ::close(fd_);
    fd_ = -1;
    throw std::runtime_error(path + ": cannot create the recording: expected a regular file, not a FIFO or socket");
  }
  if (S_ISREG(st.st_mode) && ::ftruncate(fd_, 0) != 0) {
    ::close(fd_);
    fd_ = -1;
    ioFail(path, "cannot create the recording");
  }
  const int flags = ::fcntl(fd_, F_GETFL);
  if (flags >= 0) ::fcntl(fd_, F_SETFL, flags & ~O_NONBLOCK);
  pending_.insert(pending_.end(), std::begin(kMagic), std::end(kMagic));
  put<uint32_t>(pending_, kFormatVersion);
  append(ChunkType::Head, encodeHead(header));
  flush();
}

Writer::~Writer() {
  if (fd_ >= 0) {
    try {
      if (!failed_) flush();
    } catch (...) {  // a destructor must not throw; the file stays readable up to here
    }
    ::close(fd_);
  }
}

void Writer::append(ChunkType type, std::span<const uint8_t> payload) {
  if (fd_ < 0) throw std::runtime_error(path_ + ": the recording is already closed");
  if (failed_) throw std::runtime_error(path_ + ": the recording stopped at an earlier write error");
  const std::vector<uint8_t> chunk = frameChunk(type, payload);
  if (written_ + pending_.size() + chunk.size() > maxBytes)
    throw std::runtime_error(path_ + ": cannot record further: expected a recording of at most " +
                             std::to_string(maxBytes) + " bytes (what a reader accepts); it stops at " +
                             std::to_string(written_ + pending_.size()) + " bytes, readable up to there");
  pending_.insert(pending_.end(), chunk.begin(), chunk.end());
}

bool Writer::input(int64_t tick, const TickInput& in) {
  const bool cameraChanged = in.hasCamera != previous_.hasCamera || in.camera != previous_.camera;
  if (const std::string why = inputProblem(in); !why.empty())
    throw std::runtime_error(path_ + ": cannot record the input of tick " + std::to_string(tick) + ": expected " + why);
  const bool written = cameraChanged || !in.bodies.empty();
  if (written) append(ChunkType::Input, encodeInput(tick, in, previous_));
  previous_.hasCamera = in.hasCamera;
  previous_.camera = in.camera;
  return written;
}

void Writer::check(const Check& c) { append(ChunkType::Check, encodeCheck(c)); }

void Writer::snapshot(int64_t tick, uint64_t hash, std::span<const uint8_t> state) {
  if (state.size() > kMaxSnapshotRawBytes)
    throw std::runtime_error(path_ + ": cannot record a snapshot of " + std::to_string(state.size()) +
                             " bytes (a SNAP chunk holds at most " + std::to_string(kMaxSnapshotRawBytes) + ")");
  const std::vector<uint8_t> payload = encodeSnapshot(tick, hash, state, zstdLevel);
  if (payload.size() > kMaxSnapshotPayload)
    throw std::runtime_error(path_ + ": cannot record a snapshot that compresses to " + std::to_string(payload.size()) +
                             " bytes (a SNAP chunk holds at most " + std::to_string(kMaxSnapshotPayload) + ")");
  append(ChunkType::Snapshot, payload);
}

void Writer::end(const EndInfo& e) {
  append(ChunkType::End, encodeEnd(e));
  flush();
  if (::fsync(fd_) != 0 && errno != EINVAL) {
    failed_ = true;
    ioFail(path_, "cannot sync the recording");
  }
  if (::close(fd_) != 0) {
    fd_ = -1;
    ioFail(path_, "cannot close the recording");
  }
  fd_ = -1;
}

void Writer::flush() {
  if (fd_ < 0) throw std::runtime_error(path_ + ": the recording is already closed");
  if (failed_) throw std::runtime_error(path_ + ": the recording stopped at an earlier write error");
  size_t done = 0;
  while (done < pending_.size()) {
    const ssize_t n = ::write(fd_, pending_.data() + done, pending_.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      // The file now ends inside a chunk at worst (it reads as cut off there); nothing more is
      // written, so a retry can never append a second copy of a half-written chunk.
      if (n == 0) errno = EIO;
      failed_ = true;
      ioFail(path_, "cannot write the recording");
    }
    done += size_t(n);
  }
  written_ += pending_.size();
  pending_.clear();
}

}  // namespace sg::sgr
