#include "replay/divergence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include <stb_image_write.h>

#include "replay/report/plot.h"

namespace sg {
namespace {
/// m = max(m, x), letting a NaN through (a run that produced NaNs must not read as "no error").
void raise(double& m, double x) {
  if (!(x <= m)) m = x;
}
}  // namespace

std::string observationMismatch(const Observation& a, const Observation& b) {
  auto shape = [](const Observation& o) {
    return std::to_string(o.patchesX) + " x " + std::to_string(o.patchesZ) + " patches, " +
           std::to_string(o.bodyPosition.size() / 3) + " bodies";
  };
  const size_t n = size_t(a.patchesX * a.patchesZ);
  const bool sameField = a.patchesX == b.patchesX && a.patchesZ == b.patchesZ;
  auto posesFit = [](const Observation& o) {
    return o.bodyPosition.size() % 3 == 0 && o.bodyOrientation.size() == o.bodyPosition.size() / 3 * 4;
  };
  const bool wellFormed = a.tipX.size() == n && a.tipY.size() == n && a.tipZ.size() == n && b.tipX.size() == n &&
                          b.tipY.size() == n && b.tipZ.size() == n && posesFit(a) && posesFit(b);
  if (sameField && wellFormed) return {};
  if (sameField) return "observations with one tip per patch and a pose per body";
  return shape(a) + " vs " + shape(b);
}

double relativeRotationAngle(const double* qa, const double* qb) {
  const double aw = qa[0], ax = qa[1], ay = qa[2], az = qa[3];
  const double bw = qb[0], bx = qb[1], by = qb[2], bz = qb[3];
  // r = conj(a) * b: the rotation from a to b.
  const double w = aw * bw + ax * bx + ay * by + az * bz;
  const double x = aw * bx - ax * bw - ay * bz + az * by;
  const double y = aw * by - ay * bw - az * bx + ax * bz;
  const double z = aw * bz - az * bw - ax * by + ay * bx;
  return 2.0 * std::atan2(std::sqrt(x * x + y * y + z * z), std::fabs(w));
}

std::vector<double> tipDistances(const Observation& a, const Observation& b) {
  const std::string why = observationMismatch(a, b);
  if (!why.empty()) throw std::invalid_argument(why);
  std::vector<double> d(a.tipX.size());
  for (size_t p = 0; p < d.size(); ++p) {
    const double dx = a.tipX[p] - b.tipX[p], dy = a.tipY[p] - b.tipY[p], dz = a.tipZ[p] - b.tipZ[p];
    d[p] = std::sqrt(dx * dx + dy * dy + dz * dz);
  }
  return d;
}

TickDivergence measureDivergence(const Observation& a, const Observation& b, bool hashesEqual) {
  const std::string why = observationMismatch(a, b);
  if (!why.empty()) throw std::invalid_argument(why);
  TickDivergence d;
  d.tick = a.tick;
  d.identical = hashesEqual;
  d.contactsA = a.contacts;
  d.contactsB = b.contacts;
  const size_t n = a.tipX.size();
  double sumSquares = 0;
  for (size_t p = 0; p < n; ++p) {
    const double dx = a.tipX[p] - b.tipX[p], dy = a.tipY[p] - b.tipY[p], dz = a.tipZ[p] - b.tipZ[p];
    const double squared = dx * dx + dy * dy + dz * dz;
    sumSquares += squared;
    raise(d.tipMax, std::sqrt(squared));
  }
  d.tipRms = n > 0 ? std::sqrt(sumSquares / double(n)) : 0.0;
  d.bodiesA = int64_t(a.bodyPosition.size() / 3);
  d.bodiesB = int64_t(b.bodyPosition.size() / 3);
  const size_t bodies = size_t(std::min(d.bodiesA, d.bodiesB));  // the bodies both runs have
  for (size_t i = 0; i < bodies; ++i) {
    const double* pa = &a.bodyPosition[3 * i];
    const double* pb = &b.bodyPosition[3 * i];
    const double dx = pa[0] - pb[0], dy = pa[1] - pb[1], dz = pa[2] - pb[2];
    raise(d.bodyPosMax, std::sqrt(dx * dx + dy * dy + dz * dz));
    raise(d.bodyAngleMax, relativeRotationAngle(&a.bodyOrientation[4 * i], &b.bodyOrientation[4 * i]));
  }
  return d;
}

void DivergenceSummary::add(const TickDivergence& d) {
  // The first tick of the largest error (or of the first NaN, which stays).
  if (ticks == 0 || d.tipMax > tipMax || (std::isnan(d.tipMax) && !std::isnan(tipMax))) {
    tipMax = d.tipMax;
    tipMaxTick = d.tick;
  }
  tipSumSquares += d.tipRms * d.tipRms;
  raise(bodyPosMax, d.bodyPosMax);
  raise(bodyAngleMax, d.bodyAngleMax);
  contactDeltaMax = std::max(contactDeltaMax, std::abs(d.contactsA - d.contactsB));
  if (firstObservedTick < 0 && d.observedDifference()) firstObservedTick = d.tick;
  if (firstHashTick < 0 && !d.identical) firstHashTick = d.tick;
  ++ticks;
}

double DivergenceSummary::tipRms() const { return ticks > 0 ? std::sqrt(tipSumSquares / double(ticks)) : 0.0; }

void divergenceColour(double t, uint8_t rgb[3]) {
  // Viridis at nine evenly spaced stops (perceptually uniform, readable in grey and by most
  // colour-blind viewers), linearly interpolated.
  static constexpr uint8_t kStops[9][3] = {{68, 1, 84},    {71, 44, 122},  {59, 81, 139},
                                           {44, 113, 142}, {33, 144, 141}, {39, 173, 129},
                                           {92, 200, 99},  {170, 220, 50}, {253, 231, 37}};
  if (!(t >= 0)) t = t < 0 ? 0.0 : 1.0;  // NaN: hottest
  t = std::min(t, 1.0) * 8.0;
  const int i = std::min(int(t), 7);
  const double f = t - double(i);
  for (int c = 0; c < 3; ++c)
    rgb[c] = uint8_t(std::lround(double(kStops[i][c]) + f * (double(kStops[i + 1][c]) - double(kStops[i][c]))));
}

namespace {
std::string metres(double v) {
  char buf[40];
  if (v == 0) return "0 m";
  if (std::fabs(v) >= 1e-2 && std::fabs(v) < 1e4)
    std::snprintf(buf, sizeof buf, "%.4g m", v);
  else
    std::snprintf(buf, sizeof buf, "%.3e m", v);
  return buf;
}

plot::Rgb rampColour(double t) {
  uint8_t rgb[3];
  divergenceColour(t, rgb);
  return {rgb[0], rgb[1], rgb[2]};
}
}  // namespace

bool writeDivergencePng(const std::string& path, const Observation& a, const Observation& b, std::string* error) {
  const std::string why = observationMismatch(a, b);
  if (!why.empty()) {
    if (error) *error = path + ": expected observations of the same field (" + why + ")";
    return false;
  }
  const std::vector<double> dist = tipDistances(a, b);
  const int64_t px = a.patchesX, pz = a.patchesZ;
  // Very wide fields: each pixel shows the largest distance of a bin x bin block of patches.
  const int64_t bin = std::max<int64_t>(1, (std::max(px, pz) + 2047) / 2048);
  const int64_t cols = (px + bin - 1) / bin, rows = (pz + bin - 1) / bin;
  std::vector<double> cell(size_t(cols * rows), 0.0);
  double maxDist = 0;
  for (int64_t j = 0; j < pz; ++j)
    for (int64_t i = 0; i < px; ++i) {
      const double d = dist[size_t(j * px + i)];
      raise(cell[size_t((j / bin) * cols + i / bin)], d);
      if (std::isfinite(d)) maxDist = std::max(maxDist, d);
    }
  // Each cell a square of `scale` pixels: at least ~512 px wide, at most ~4096 px tall.
  int64_t scale = std::max<int64_t>(1, (512 + cols - 1) / cols);
  scale = std::max<int64_t>(1, std::min(scale, 4096 / rows));
  const int margin = 8, barHeight = 20, textScale = 2, textHeight = 7 * textScale;
  const int mapW = int(cols * scale), mapH = int(rows * scale);
  const int width = std::max(mapW, 480);
  const int height = mapH + margin + barHeight + margin / 2 + textHeight + margin;
  const plot::Rgb white{235, 235, 235};
  plot::Canvas img(width, height, plot::Rgb{24, 24, 24});
  const int mapX = (width - mapW) / 2;
  for (int64_t r = 0; r < rows; ++r)
    for (int64_t c = 0; c < cols; ++c) {
      const double d = cell[size_t(r * cols + c)];
      const plot::Rgb colour = rampColour(maxDist > 0 ? d / maxDist : (std::isfinite(d) ? 0.0 : 1.0));
      img.fill(mapX + int(c * scale), int(r * scale), mapX + int((c + 1) * scale), int((r + 1) * scale), colour);
    }
  // Legend: the ramp from 0 to the largest distance, labelled underneath.
  const int barY = mapH + margin, barX0 = margin, barX1 = width - margin;
  for (int x = barX0; x < barX1; ++x) {
    img.fill(x, barY, x + 1, barY + barHeight, rampColour(double(x - barX0) / double(std::max(1, barX1 - barX0 - 1))));
  }
  const int textY = barY + barHeight + margin / 2;
  img.text(barX0, textY, "0", textScale, white);
  const std::string middle = "tip distance, tick " + std::to_string(a.tick);
  img.text((width - plot::Canvas::textWidth(middle, textScale)) / 2, textY, middle, textScale, white);
  const std::string right = metres(maxDist);
  img.text(barX1 - plot::Canvas::textWidth(right, textScale), textY, right, textScale, white);
  return plot::writePng(path, img.img, error);
}

}  // namespace sg
