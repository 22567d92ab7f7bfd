#include "sim/scenario/derived.h"

namespace sg {
namespace {
/// Unwraps a checked result or reports the path whose value made the arithmetic overflow.
class Checked {
 public:
  explicit Checked(const Scenario& s) : s_(s) {}
  Rational operator()(std::optional<Rational> r, const std::string& path) const {
    if (!r)
      throw ScenarioError(s_.sourceName, path,
                          "a value that combines exactly with the others in 128-bit fractions "
                          "(write it with fewer significant digits)");
    return *r;
  }
  /// `what` names the duration when it is derived from more than the value at `path`.
  int64_t ticks(std::optional<Rational> r, const std::string& path, const char* what = "a duration") const {
    auto n = (*this)(r, path).roundToInt64();
    if (!n || *n >= (int64_t(1) << 40))
      throw ScenarioError(s_.sourceName, path, std::string(what) + " below 2^40 ticks");
    return *n;
  }

 private:
  const Scenario& s_;
};
}  // namespace

ScenarioConstants deriveConstants(const Scenario& s) {
  const Checked ok(s);
  ScenarioConstants c;
  const auto& f = s.field;
  const auto& p = s.particles;
  const int k = p.interpolation;
  c.invDt = ok(div(Rational{1, 1}, s.timeStep), "$.timeStep");
  c.dampingPerTick = deterministicPow(p.damping, s.timeStep);
  if (p.model == GrassModel::Blade) {
    const std::string b = "$.particles.blade";
    // pi as the continued-fraction convergent 245850922 / 78256779 (within 8e-17 of pi).
    const Rational twoPi{int64_t(491701844), int64_t(78256779)};  // 2 x 245850922 / 78256779
    const Rational omega = ok(mul(twoPi, p.blade.frequency), b + ".frequency");
    const Rational lift = ok(div(p.acceleration[1], p.constraintLength), "$.particles.acceleration[1]");
    c.bladeStiffness = ok(sub(ok(mul(omega, omega), b + ".frequency"), lift), b + ".frequency");
    if (c.bladeStiffness.isNegative() || c.bladeStiffness.isZero())
      throw ScenarioError(s.sourceName, b + ".frequency",
                          "a frequency whose stiffness (2 pi f)^2 - acceleration.y / L is above 0 (the lift " +
                              lift.toString() + " /s^2 alone sways the blade faster), got " +
                              p.blade.frequency.toString() + " Hz");
    c.bladeDampingRate =
        ok(mul(ok(mul(omega, p.blade.dampingRatio), b + ".dampingRatio"), Rational{2, 1}), b + ".dampingRatio");
    c.bladeStiffnessDt = ok(mul(c.bladeStiffness, s.timeStep), b + ".frequency");
    c.invRodLength = ok(div(Rational{1, 1}, p.constraintLength), "$.particles.constraintLength");
    // exp(-rate dt) exactly as the continuous damping decays a velocity over one tick (an
    // implicit 1 / (1 + rate dt) is stable too but lets a 1 Hz, 0.3 blade ring 25 % too long by
    // 2 s): (1/e)^(rate dt), 1/e to 17 digits, by the deterministic integer pow.
    const Rational invE{int64_t(36787944117144232), int64_t(100000000000000000)};
    const Rational decay = deterministicPow(invE, ok(mul(c.bladeDampingRate, s.timeStep), b + ".dampingRatio"));
    c.bladeDampingPerTick = ok(mul(c.dampingPerTick, decay), b + ".dampingRatio");
    if (!p.blade.trampleSeconds.isZero())
      c.trampleDecayPerTick = ok(div(s.timeStep, p.blade.trampleSeconds), b + ".trampleSeconds");
  }
  c.halfRod = ok(mul(p.constraintLength, Rational{1, 2}), "$.particles.constraintLength");
  c.invMass = ok(div(Rational{1, 1}, p.mass), "$.particles.mass");
  c.jitterAmplitude = ok(mul(f.jitter, f.spacing), "$.field.jitter");
  c.fieldOriginX =
      ok(sub(f.centerX, ok(mul(f.spacing, Rational{f.patchesX - 1, 2}), "$.field.spacing")), "$.field.center[0]");
  c.fieldOriginZ =
      ok(sub(f.centerZ, ok(mul(f.spacing, Rational{f.patchesZ - 1, 2}), "$.field.spacing")), "$.field.center[1]");
  c.particlesX = (f.patchesX - 1 + k - 1) / k + 1;
  c.particlesZ = (f.patchesZ - 1 + k - 1) / k + 1;
  for (int t = 0; t < k; ++t) c.interpolationWeights.push_back(Rational{t, k});
  c.invParticleSpacing =
      ok(div(Rational{1, 1}, ok(mul(f.spacing, Rational::integer(k)), "$.field.spacing")), "$.field.spacing");

  for (size_t g = 0; g < s.wind.schedule.size(); ++g) {
    const std::string path = "$.wind.schedule[" + std::to_string(g) + "]";
    std::array<Rational, 3> perMass;
    for (int i = 0; i < 3; ++i)
      perMass[size_t(i)] =
          ok(mul(s.wind.schedule[g].force[size_t(i)], c.invMass), path + ".force[" + std::to_string(i) + "]");
    c.gustForcePerMass.push_back(perMass);
    const Rational& duration = s.wind.schedule[g].duration;
    if (compare(duration, s.timeStep) < 0)
      throw ScenarioError(
          s.sourceName, path + ".duration",
          "a duration of at least one time step (" + s.timeStep.toString() + " s), got " + duration.toString() + " s");
    c.gustTicks.push_back(ok.ticks(div(duration, s.timeStep), path + ".duration"));
  }
  // A gust front needs rowSpacing / (speed * dt) ticks per particle row.
  const Rational rowSpacing = ok(mul(f.spacing, Rational::integer(k)), "$.field.spacing");
  const Rational ticksPerRow =
      ok(div(rowSpacing, ok(mul(s.wind.travelSpeed, s.timeStep), "$.wind.travelSpeed")), "$.wind.travelSpeed");
  // Too long a crossing is a too-slow gust, unless the spacing is over a metre (blades are
  // centimetres apart): then the spacing is the value to change (the same rule as the field reach).
  const char* crossingKey = compare(f.spacing, Rational{1, 1}) > 0 ? "$.field.spacing" : "$.wind.travelSpeed";
  c.ticksPerParticleSpacing = ticksPerRow;
  // A front in any direction crosses at most particlesX + particlesZ spacings; its per-column and
  // per-row delays are Q32.32 integers (sim/wind/wind.h), which need under 2^30 ticks per spacing.
  for (size_t g = 0; g < s.wind.schedule.size(); ++g) {
    if (!s.wind.schedule[g].front) continue;
    const std::string path = "$.wind.schedule[" + std::to_string(g) + "].front";
    const auto crossing = mul(ticksPerRow, Rational::integer(c.particlesX + c.particlesZ));
    if (compare(ticksPerRow, Rational{int64_t(1) << 30, 1}) >= 0 || !crossing ||
        compare(*crossing, Rational{int64_t(1) << 40, 1}) >= 0)
      throw ScenarioError(s.sourceName, crossingKey,
                          "a gust front that crosses the field (" + path +
                              ") in under 2^40 ticks: (particlesX + particlesZ) x field.spacing x interpolation / "
                              "(travelSpeed x timeStep)");
  }
  c.rowDelayTicks.resize(size_t(c.particlesZ));
  for (int64_t r = 0; r < c.particlesZ; ++r)
    c.rowDelayTicks[size_t(r)] =
        ok.ticks(mul(ticksPerRow, Rational::integer(r)), crossingKey,
                 "a gust crossing of the field (rows x field.spacing x interpolation / (travelSpeed x timeStep))");

  if (!s.terrain.flat) {
    const auto& t = s.terrain;
    c.terrainInvCellSize = ok(div(Rational{1, 1}, t.cellSize), "$.terrain.cellSize");
    c.terrainOriginX = ok(sub(t.centerX, ok(mul(t.cellSize, Rational{t.heightmap.width - 1, 2}), "$.terrain.cellSize")),
                          "$.terrain.center[0]");
    c.terrainOriginZ =
        ok(sub(t.centerZ, ok(mul(t.cellSize, Rational{t.heightmap.height - 1, 2}), "$.terrain.cellSize")),
           "$.terrain.center[1]");
    for (int v = 0; v < 256; ++v)
      c.terrainHeightOfSample[size_t(v)] = ok(mul(t.maxHeight, *Rational::make(v, 255)), "$.terrain.maxHeight");
  }
  return c;
}
}  // namespace sg
