#include "replay/divergence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include <stb_image_write.h>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

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
  const bool sameBodies = a.bodyPosition.size() == b.bodyPosition.size() &&
                          a.bodyOrientation.size() == b.bodyOrientation.size();
  const bool wellFormed = a.tipX.size() == n && a.tipY.size() == n && a.tipZ.size() == n && b.tipX.size() == n &&
                          b.tipY.size() == n && b.tipZ.size() == n && a.bodyPosition.size() % 3 == 0 &&
                          a.bodyOrientation.size() == a.bodyPosition.size() / 3 * 4;
  if (sameField && sameBodies && wellFormed) return {};
  if (sameField && sameBodies) return "observations with one tip per patch and a pose per body";
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
  const size_t bodies = a.bodyPosition.size() / 3;
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
/// An 8-bit RGB image being drawn.
struct Canvas {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  Canvas(int w, int h, const uint8_t background[3]) : width(w), height(h), rgb(size_t(w) * size_t(h) * 3) {
    for (size_t p = 0; p < rgb.size(); p += 3) std::memcpy(&rgb[p], background, 3);
  }
  void fill(int x0, int y0, int x1, int y1, const uint8_t colour[3]) {
    x0 = std::max(x0, 0), y0 = std::max(y0, 0), x1 = std::min(x1, width), y1 = std::min(y1, height);
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) std::memcpy(&rgb[(size_t(y) * size_t(width) + size_t(x)) * 3], colour, 3);
  }
  /// ASCII text with its top-left corner at (x, y), stb_easy_font glyphs scaled by `scale`.
  void text(int x, int y, const std::string& s, int scale, const uint8_t colour[3]) {
    std::vector<char> chars(s.begin(), s.end());
    chars.push_back('\0');
    std::vector<char> quads(s.size() * 400 + 64);  // ~270 bytes per glyph at most
    const int n = stb_easy_font_print(0, 0, chars.data(), nullptr, quads.data(), int(quads.size()));
    for (int q = 0; q < n; ++q) {
      float v0[2], v2[2];  // corners 0 and 2 of an axis-aligned quad, 16 bytes per vertex
      std::memcpy(v0, &quads[size_t(q) * 64], sizeof v0);
      std::memcpy(v2, &quads[size_t(q) * 64 + 32], sizeof v2);
      fill(x + int(v0[0]) * scale, y + int(v0[1]) * scale, x + int(v2[0]) * scale, y + int(v2[1]) * scale, colour);
    }
  }
  static int textWidth(const std::string& s, int scale) {
    std::vector<char> chars(s.begin(), s.end());
    chars.push_back('\0');
    return stb_easy_font_width(chars.data()) * scale;
  }
};

std::string metres(double v) {
  char buf[40];
  if (v == 0) return "0 m";
  if (std::fabs(v) >= 1e-2 && std::fabs(v) < 1e4) std::snprintf(buf, sizeof buf, "%.4g m", v);
  else std::snprintf(buf, sizeof buf, "%.3e m", v);
  return buf;
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
  const uint8_t background[3] = {24, 24, 24}, white[3] = {235, 235, 235};
  Canvas img(width, height, background);
  const int mapX = (width - mapW) / 2;
  for (int64_t r = 0; r < rows; ++r)
    for (int64_t c = 0; c < cols; ++c) {
      const double d = cell[size_t(r * cols + c)];
      uint8_t colour[3];
      divergenceColour(maxDist > 0 ? d / maxDist : (std::isfinite(d) ? 0.0 : 1.0), colour);
      img.fill(mapX + int(c * scale), int(r * scale), mapX + int((c + 1) * scale), int((r + 1) * scale), colour);
    }
  // Legend: the ramp from 0 to the largest distance, labelled underneath.
  const int barY = mapH + margin, barX0 = margin, barX1 = width - margin;
  for (int x = barX0; x < barX1; ++x) {
    uint8_t colour[3];
    divergenceColour(double(x - barX0) / double(std::max(1, barX1 - barX0 - 1)), colour);
    img.fill(x, barY, x + 1, barY + barHeight, colour);
  }
  const int textY = barY + barHeight + margin / 2;
  img.text(barX0, textY, "0", textScale, white);
  const std::string middle = "tip distance, tick " + std::to_string(a.tick);
  img.text((width - Canvas::textWidth(middle, textScale)) / 2, textY, middle, textScale, white);
  const std::string right = metres(maxDist);
  img.text(barX1 - Canvas::textWidth(right, textScale), textY, right, textScale, white);
  if (!stbi_write_png(path.c_str(), width, height, 3, img.rgb.data(), width * 3)) {
    if (error) *error = path + ": expected a writable file for the heat map (cannot write it)";
    return false;
  }
  return true;
}

}  // namespace sg
