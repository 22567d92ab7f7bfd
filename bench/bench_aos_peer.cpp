// The "what a user would write" peer (issue 17): the thesis' grass physics as a plain float loop
// over an array of structs, the way the thesis' own engine (Cyclone's particle integrator plus
// the thesis' rod projection, float) and most game code hold particles: one struct per tuft.
//
//   simgrass_bench --benchmark_filter='BM_AosPeer|BM_Floor/(fx32|fx16|float)/side:1000/k:1'
//
// BM_AosPeer/side:S/k:K/threads:T does per tick what the SoA core's grass tick does (wind per
// lattice row, Cyclone's integration p += v dt, v = (v + a dt) d^dt, the rod projection, and the
// patch state: tip offset, top height and tilt, bilinearly interpolated at k = 2), on the same
// meadow sizes and thread chunks, in float without SIMD intrinsics (the compiler may vectorise
// what it can; it cannot do much with an array of structs). It is not bit-compared with
// anything: it is the speed peer that BM_Floor's fx32, fx16 and float rows are read against
// (docs/performance.md, "The memory floor"). Counters: tick_ms (median), patch_steps/s.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <vector>

#include "bench/bench_support.h"
#include "sim/world/chunk_pool.h"
#include "sim/world/settings.h"

namespace {

struct Vec3f {
  float x, y, z;
};

/// One tuft's particle, as Cyclone's Particle holds it (plus the anchor the rod hangs from).
struct TuftParticle {
  Vec3f position, velocity, anchor;
};

/// What the renderer reads per patch.
struct TuftPatch {
  float rootY, tipOffsetX, tipOffsetZ, topY;
  uint8_t cut, tilt;
};

class AosMeadow {
 public:
  AosMeadow(int64_t side, int k) : k_(k), patchesX_(side) {
    particlesX_ = (side - 1 + k - 1) / k + 1;
    particles_.resize(size_t(particlesX_ * particlesX_));
    patches_.resize(size_t(side * side));
    for (int64_t j = 0; j < particlesX_; ++j)
      for (int64_t i = 0; i < particlesX_; ++i) {
        const Vec3f anchor{0.1f * float(i * k), 0.0f, 0.1f * float(j * k)};
        particles_[size_t(j * particlesX_ + i)] = {{anchor.x, anchor.y + kRod, anchor.z}, {0, 0, 0}, anchor};
      }
    for (TuftPatch& p : patches_) p = {0.0f, 0.0f, 0.0f, kScaleY, 0, 0};
    rowAcceleration_.resize(size_t(particlesX_));
  }

  void tick(sg::ChunkPool& pool) {
    // Wind: a gust front travelling along z, one acceleration per particle row.
    for (int64_t j = 0; j < particlesX_; ++j) {
      const float phase = 0.05f * float(j) - 0.02f * float(tick_);
      rowAcceleration_[size_t(j)] = phase > 0.0f && phase < 1.0f ? 4.0f : 0.0f;
    }
    ++tick_;
    const int64_t rowsPerChunk = std::max<int64_t>(1, sg::settings::kTargetChunkElements / particlesX_);
    pool.run((particlesX_ + rowsPerChunk - 1) / rowsPerChunk, [&](int64_t c, int) {
      for (int64_t j = c * rowsPerChunk; j < std::min(particlesX_, (c + 1) * rowsPerChunk); ++j) particleRow(j);
    });
    const int64_t patchRowsPerChunk = std::max<int64_t>(1, sg::settings::kTargetChunkElements / patchesX_);
    pool.run((patchesX_ + patchRowsPerChunk - 1) / patchRowsPerChunk, [&](int64_t c, int) {
      for (int64_t j = c * patchRowsPerChunk; j < std::min(patchesX_, (c + 1) * patchRowsPerChunk); ++j) patchRow(j);
    });
  }

  int64_t patches() const { return patchesX_ * patchesX_; }

 private:
  static constexpr float kRod = 0.5f, kScaleY = 0.6f, kDt = 1.0f / 60.0f, kDampingPerTick = 0.99f;

  void particleRow(int64_t j) {
    const float lift = 1.0f, wind = rowAcceleration_[size_t(j)];
    TuftParticle* row = particles_.data() + j * particlesX_;
    for (int64_t i = 0; i < particlesX_; ++i) {
      TuftParticle& q = row[i];
      // Cyclone: position first, then velocity with damping.
      q.position.x += q.velocity.x * kDt;
      q.position.y += q.velocity.y * kDt;
      q.position.z += q.velocity.z * kDt;
      q.velocity.x = (q.velocity.x + wind * kDt) * kDampingPerTick;
      q.velocity.y = (q.velocity.y + lift * kDt) * kDampingPerTick;
      q.velocity.z = (q.velocity.z + 0.5f * wind * kDt) * kDampingPerTick;
      // The thesis' rod: the tip back to distance L from its anchor.
      const float dx = q.position.x - q.anchor.x, dy = q.position.y - q.anchor.y, dz = q.position.z - q.anchor.z;
      const float length = std::sqrt(dx * dx + dy * dy + dz * dz);
      const float scale = length > 0.0f ? kRod / length : 0.0f;
      q.position = {q.anchor.x + dx * scale, q.anchor.y + (length > 0.0f ? dy * scale : kRod), q.anchor.z + dz * scale};
    }
  }

  /// The tip displacement of particle (i, j) from rest.
  Vec3f displacement(int64_t i, int64_t j) const {
    const TuftParticle& q =
        particles_[size_t(std::min(j, particlesX_ - 1) * particlesX_ + std::min(i, particlesX_ - 1))];
    return {q.position.x - q.anchor.x, q.position.y - q.anchor.y - kRod, q.position.z - q.anchor.z};
  }

  void patchRow(int64_t j) {
    const int64_t b = j / k_;
    const float tz = float(j % k_) / float(k_);
    TuftPatch* row = patches_.data() + j * patchesX_;
    for (int64_t i = 0; i < patchesX_; ++i) {
      const int64_t a = i / k_;
      const float tx = float(i % k_) / float(k_);
      Vec3f d = displacement(a, b);
      if (k_ > 1) {  // bilinear between the four particles around the patch
        const Vec3f d10 = displacement(a + 1, b), d01 = displacement(a, b + 1), d11 = displacement(a + 1, b + 1);
        auto mix = [&](float v00, float v10, float v01, float v11) {
          const float low = v00 + (v10 - v00) * tx, high = v01 + (v11 - v01) * tx;
          return low + (high - low) * tz;
        };
        d = {mix(d.x, d10.x, d01.x, d11.x), mix(d.y, d10.y, d01.y, d11.y), mix(d.z, d10.z, d01.z, d11.z)};
      }
      TuftPatch& p = row[i];
      const float sink = std::clamp(-d.y, 0.0f, kRod / 2);
      p.tipOffsetX = d.x;
      p.tipOffsetZ = d.z;
      p.topY = p.rootY + std::max(kScaleY - sink - (p.cut ? 0.2f : 0.0f), kScaleY / 10);
      p.tilt = uint8_t(-d.y > 0.3f ? 3 : -d.y > 0.2f ? 2 : -d.y > 0.1f ? 1 : 0);
    }
  }

  int k_;
  int64_t patchesX_, particlesX_ = 0, tick_ = 0;
  std::vector<TuftParticle> particles_;
  std::vector<TuftPatch> patches_;
  std::vector<float> rowAcceleration_;
};

void BM_AosPeer(benchmark::State& state) {
  const int64_t side = state.range(0);
  const int k = int(state.range(1));
  AosMeadow meadow(side, k);
  sg::ChunkPool pool(int(state.range(2)));
  for (int t = 0; t < 30; ++t) meadow.tick(pool);
  std::vector<double> tickMs;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    meadow.tick(pool);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    tickMs.push_back(s * 1e3);
    state.SetIterationTime(s);
  }
  state.counters["tick_ms"] = sg::bench::quantile(tickMs, 0.5);
  state.counters["patches"] = double(meadow.patches());
  state.counters["patch_steps/s"] =
      benchmark::Counter(double(meadow.patches()) * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_AosPeer)
    ->ArgsProduct({{151, 1000, 2000}, {1, 2}, {1, 2}})
    ->ArgNames({"side", "k", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();

}  // namespace
