// The memory floor of a whole grass tick (issue 17): how close a tick comes to the time its
// memory traffic alone must take on this machine.
//
//   simgrass_bench --benchmark_filter=Floor
//
// BM_Floor/<scalar>/side:S/k:K/threads:T runs the meadow of S x S patches (no bodies: the wind,
// collision, particle and patch stages of the grass) and, interleaved with every tick in the
// same run, a floor pass of the same shape: plain integer loops over arrays of the same sizes,
// element widths and thread chunks, reading and writing exactly the arrays the tick reads and
// writes, with a few adds per element (far below what the memory system delivers). Counters:
//   tick_ms, floor_ms     medians over the iterations (interleaved, so both see the same load)
//   ratio_to_floor        the median over iterations of tick time / floor time (1: a tick that is
//                         all memory traffic); ratio_p25, ratio_p75 its quartiles
//   bytes_per_tick        the traffic counted below; floor_GB/s = bytes_per_tick / floor_ms
//
// The bytes a tick must move, counted from the arrays it actually reads and writes (w = the
// scalar's width, n particles, m patches; each array counted once per tick, a write to an array
// also read counted again):
//   particle pass (integrate, rod, displacement; sim/particles/particle_row.h, blade.h):
//     reads position, velocity and anchor (9 w), writes position, velocity and the tip
//     displacement (9 w); the blade model's trample level adds 1 w each way      -> n (18 w [+2 w])
//   patch stage (sim/patches/patch_state.h): reads the displacement (3 w per particle; at k > 1 a
//     particle row serves k patch rows from cache), each patch's root height (w) and cut flag (1),
//     writes tip offset x, z and top height (3 w) and the tilt level (1)      -> n 3 w + m (4 w + 2)
//   wind: one acceleration per lattice row (negligible); collision: nothing without bodies.
// The floor pass's arrays sit in one allocation at staggered offsets (a 4 KiB page plus a
// cache line apart), so it does not suffer the cache-set conflicts of arrays that all start at
// the same page offset; a tick that does is measured against that better placement.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <memory>
#include <type_traits>
#include <vector>

#include "bench/bench_support.h"
#include "sim/world/chunk_pool.h"
#include "sim/world/settings.h"
#include "sim/world/world.h"

namespace {

using sg::ScalarKind;

// The floor loops are compiled for AVX2, as the tick's kernels run: at the baseline's 16-byte
// vectors they issue twice the loads and stores and a core cannot keep up with its share of the
// memory bandwidth (the float tick, 8-wide, then ran below its "floor").
#if defined(__x86_64__)
#define SG_FLOOR_TARGET __attribute__((target("avx2")))
#else
#define SG_FLOOR_TARGET
#endif

size_t scalarBytes(ScalarKind s) { return s == ScalarKind::Fx32 || s == ScalarKind::Double ? 8 : 4; }

/// Arrays of one allocation, each starting a page and a cache line after the previous one's end.
class StaggeredArrays {
 public:
  /// `sizes` in bytes.
  explicit StaggeredArrays(const std::vector<size_t>& sizes) {
    constexpr size_t kStagger = 4096 + 64;
    size_t total = 0;
    for (size_t s : sizes) {
      offsets_.push_back(total);
      total += (s + 63) / 64 * 64 + kStagger * (offsets_.size());
    }
    storage_.reset(new uint64_t[total / 8 + 8]);
    std::memset(storage_.get(), 1, total);  // touched: no page faults inside the timing
  }
  template <class T>
  T* at(size_t i) {
    return reinterpret_cast<T*>(reinterpret_cast<char*>(storage_.get()) + offsets_[i]);
  }

 private:
  std::unique_ptr<uint64_t[]> storage_;
  std::vector<size_t> offsets_;
};

/// The floor pass: the tick's array traffic with trivial arithmetic, in the world's row chunks.
template <class T>
class FloorPass {
 public:
  FloorPass(int64_t particlesX, int64_t particlesZ, int64_t patchesX, int64_t patchesZ, int k)
      : px_(particlesX),
        pz_(particlesZ),
        mx_(patchesX),
        mz_(patchesZ),
        k_(k),
        arrays_(sizes(size_t(particlesX * particlesZ), size_t(patchesX * patchesZ))) {}

  /// One tick's traffic on `pool`.
  void run(sg::ChunkPool& pool) {
    const int64_t rowsPerChunk = std::max<int64_t>(1, sg::settings::kTargetChunkElements / px_);
    pool.run((pz_ + rowsPerChunk - 1) / rowsPerChunk, [&](int64_t c, int) {
      for (int64_t r = c * rowsPerChunk; r < std::min(pz_, (c + 1) * rowsPerChunk); ++r) particleRow(r * px_, px_);
    });
    const int64_t patchRowsPerChunk = std::max<int64_t>(1, sg::settings::kTargetChunkElements / mx_);
    pool.run((mz_ + patchRowsPerChunk - 1) / patchRowsPerChunk, [&](int64_t c, int) {
      for (int64_t j = c * patchRowsPerChunk; j < std::min(mz_, (c + 1) * patchRowsPerChunk); ++j) patchRow(j);
    });
  }

 private:
  // 0-5 position and velocity, 6-8 anchor, 9-11 displacement, 12 root height, 13-15 tip x, z and
  // top, 16 cut, 17 tilt.
  static std::vector<size_t> sizes(size_t n, size_t m) {
    std::vector<size_t> s(12, n * sizeof(T));
    for (int i = 0; i < 4; ++i) s.push_back(m * sizeof(T));
    s.push_back(m);
    s.push_back(m);
    return s;
  }

  SG_FLOOR_TARGET void particleRow(int64_t first, int64_t count) {
    T* p[6];
    for (size_t a = 0; a < 6; ++a) p[a] = arrays_.at<T>(a) + first;
    const T* anchor[3] = {arrays_.at<T>(6) + first, arrays_.at<T>(7) + first, arrays_.at<T>(8) + first};
    T* d[3] = {arrays_.at<T>(9) + first, arrays_.at<T>(10) + first, arrays_.at<T>(11) + first};
    for (int axis = 0; axis < 3; ++axis) {
      T* __restrict pos = p[axis];
      T* __restrict vel = p[3 + axis];
      const T* __restrict a = anchor[axis];
      T* __restrict out = d[axis];
      for (int64_t i = 0; i < count; ++i) {
        vel[i] = T(vel[i] + (a[i] >> 3));
        pos[i] = T(pos[i] + vel[i]);
        out[i] = T(pos[i] - a[i]);
      }
    }
  }

  SG_FLOOR_TARGET void patchRow(int64_t j) {
    const int64_t particleRow = std::min(pz_ - 1, j / k_);
    const T* __restrict dx = arrays_.at<T>(9) + particleRow * px_;
    const T* __restrict dy = arrays_.at<T>(10) + particleRow * px_;
    const T* __restrict dz = arrays_.at<T>(11) + particleRow * px_;
    const int64_t first = j * mx_;
    const T* __restrict root = arrays_.at<T>(12) + first;
    T* __restrict tipX = arrays_.at<T>(13) + first;
    T* __restrict tipZ = arrays_.at<T>(14) + first;
    T* __restrict top = arrays_.at<T>(15) + first;
    const uint8_t* __restrict cut = arrays_.at<uint8_t>(16) + first;
    uint8_t* __restrict tilt = arrays_.at<uint8_t>(17) + first;
    if (k_ == 1) {  // three loops over the row (in L1 by then), each one the compiler vectorises
      for (int64_t i = 0; i < mx_; ++i) {
        tipX[i] = dx[i];
        tipZ[i] = dz[i];
      }
      for (int64_t i = 0; i < mx_; ++i) top[i] = T(root[i] + dy[i] + T(cut[i]));
      for (int64_t i = 0; i < mx_; ++i) tilt[i] = uint8_t(dy[i] & 3);
      return;
    }
    if (k_ == 2)
      spread<2>(dx, dy, dz, root, tipX, tipZ, top, cut, tilt);
    else
      spread<4>(dx, dy, dz, root, tipX, tipZ, top, cut, tilt);
  }

  /// k = K > 1: each particle column serves K patch columns (the interpolation's reads, from
  /// cache). The patch arrays are written in one pass over i, the particle read at i / K.
  template <int K>
  SG_FLOOR_TARGET void spread(const T* __restrict dx, const T* __restrict dy, const T* __restrict dz,
                              const T* __restrict root, T* __restrict tipX, T* __restrict tipZ, T* __restrict top,
                              const uint8_t* __restrict cut, uint8_t* __restrict tilt) const {
    const int64_t whole = std::min(mx_, px_ * K);
    for (int64_t i = 0; i < whole; ++i) {
      const int64_t q = i / K;
      tipX[i] = dx[q];
      tipZ[i] = dz[q];
      top[i] = T(root[i] + dy[q] + T(cut[i]));
      tilt[i] = uint8_t(dy[q] & 3);
    }
  }

  int64_t px_, pz_, mx_, mz_;
  int k_;
  StaggeredArrays arrays_;
};

template <class T>
void runFloor(benchmark::State& state, ScalarKind scalar) {
  const int64_t side = state.range(0);
  const int k = int(state.range(1));
  const int threads = int(state.range(2));
  auto world = sg::makeWorld(sg::bench::plainMeadow(side, k, scalar), threads);
  state.SetLabel(sg::particleKernelName(world->particleKernel()));
  const sg::WorldCounts c = world->counts();
  FloorPass<T> floor(c.particlesX, c.particlesZ, c.patchesX, c.patchesZ, k);
  sg::ChunkPool pool(threads);
  for (int t = 0; t < 30; ++t) world->step(sg::TickInput{});  // the wind is blowing on part of the field
  for (int t = 0; t < 3; ++t) floor.run(pool);
  std::vector<double> tickMs, floorMs;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!world->step(sg::TickInput{}).ok) state.SkipWithError("simulation fault");
    const auto t1 = std::chrono::steady_clock::now();
    floor.run(pool);
    const auto t2 = std::chrono::steady_clock::now();
    tickMs.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    floorMs.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
  }
  const double w = double(sizeof(T)), n = double(c.particles()), m = double(c.patches());
  const double bytes = n * (18 * w) + n * 3 * w + m * (4 * w + 2);
  const double tick = sg::bench::quantile(tickMs, 0.5), floorTime = sg::bench::quantile(floorMs, 0.5);
  // The spread: the ratio of each iteration's tick to the floor pass right after it.
  std::vector<double> ratios;
  for (size_t i = 0; i < tickMs.size(); ++i) ratios.push_back(tickMs[i] / floorMs[i]);
  state.counters["tick_ms"] = tick;
  state.counters["floor_ms"] = floorTime;
  state.counters["ratio_to_floor"] = sg::bench::quantile(ratios, 0.5);
  state.counters["ratio_p25"] = sg::bench::quantile(ratios, 0.25);
  state.counters["ratio_p75"] = sg::bench::quantile(ratios, 0.75);
  state.counters["bytes_per_tick"] = bytes;
  state.counters["floor_GB/s"] = bytes / (floorTime / 1e3) / 1e9;
  state.counters["patches"] = m;
}

void BM_Floor(benchmark::State& state, ScalarKind scalar) {
#if defined(__x86_64__)
  if (!__builtin_cpu_supports("avx2")) return state.SkipWithError("the floor pass is built for AVX2");
#endif
  if (scalarBytes(scalar) == 8)
    runFloor<uint64_t>(state, scalar);
  else
    runFloor<uint32_t>(state, scalar);
}

void floorArgs(benchmark::internal::Benchmark* b) {
  for (int64_t side : {151, 1000, 2000})  // 22,801 (the thesis), 1,000,000 and 4,000,000 patches
    for (int k : {1, 2})
      for (int threads : {1, 2}) b->Args({side, k, threads});
  b->ArgNames({"side", "k", "threads"})->Unit(benchmark::kMillisecond)->UseManualTime();
}

BENCHMARK_CAPTURE(BM_Floor, fx32, ScalarKind::Fx32)->Apply(floorArgs);
BENCHMARK_CAPTURE(BM_Floor, fx16, ScalarKind::Fx16)->Apply(floorArgs);
BENCHMARK_CAPTURE(BM_Floor, float, ScalarKind::Float)->Apply(floorArgs);
BENCHMARK_CAPTURE(BM_Floor, double, ScalarKind::Double)->Apply(floorArgs);

}  // namespace
