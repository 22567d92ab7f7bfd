#include "replay/report/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <tuple>

#include <stb_image_write.h>

#include "replay/output_file.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

namespace sg::plot {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr Rgb kWhite{255, 255, 255}, kBlack{0, 0, 0}, kGrid{228, 228, 228}, kAxis{60, 60, 60};
constexpr int kMarkerRadius = 5;   ///< px: markers are 11 px across
constexpr int kLegendWidth = 250;  ///< px: the panel right of the plot area

/// The value as the axis sees it: log10 on a log axis (NaN for values <= 0 or not finite).
double axisValue(double v, bool log) {
  if (!std::isfinite(v)) return kNaN;
  if (!log) return v;
  return v > 0 ? std::log10(v) : kNaN;
}

/// [lo, hi] of the shown range: whole decades around the data on a log axis, the data plus 5 %
/// on a linear one; a default range without data.
std::pair<double, double> axisRange(const std::vector<double>& values, bool log) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : values) {
    const double a = axisValue(v, log);
    if (std::isnan(a)) continue;
    lo = std::min(lo, a), hi = std::max(hi, a);
  }
  if (!(lo <= hi)) return {0.0, 1.0};
  if (log) {
    lo = std::floor(lo), hi = std::ceil(hi);
    if (hi <= lo) hi = lo + 1;
    return {lo, hi};
  }
  const double pad = hi > lo ? 0.05 * (hi - lo) : std::max(1.0, std::fabs(lo) * 0.1);
  return {lo - pad, hi + pad};
}

/// Tick positions (axis units) over [lo, hi]: decades on a log axis (every n-th when there are
/// many), 1-2-5 steps on a linear one.
std::vector<double> majorTicks(double lo, double hi, bool log) {
  std::vector<double> ticks;
  if (log) {
    const int decades = int(std::lround(hi - lo));
    const int every = std::max(1, (decades + 9) / 10);
    for (int d = int(std::lround(lo)); d <= int(std::lround(hi)); d += every) ticks.push_back(double(d));
    return ticks;
  }
  const double raw = (hi - lo) / 6.0;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double step = raw / mag < 2 ? 2 * mag : raw / mag < 5 ? 5 * mag : 10 * mag;
  for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * step; t += step) ticks.push_back(t);
  return ticks;
}

/// True when offset (dx, dy) from a marker's centre lies inside the marker of radius r.
bool insideMarker(Marker m, int dx, int dy, int r) {
  switch (m) {
    case Marker::Circle:
      return dx * dx + dy * dy <= r * r;
    case Marker::Square:
      return std::abs(dx) <= r - 1 && std::abs(dy) <= r - 1;
    case Marker::Diamond:
      return std::abs(dx) + std::abs(dy) <= r;
    case Marker::Triangle:
      return dy >= -r && dy <= r - 1 && 2 * std::abs(dx) <= dy + r;  // apex up
  }
  return false;
}

void drawMarker(Canvas& c, int cx, int cy, Marker m, Rgb colour, bool hollow, bool ringed) {
  const int r = kMarkerRadius, ringOuter = r + 5, ringInner = r + 3;
  for (int dy = -ringOuter; dy <= ringOuter; ++dy)
    for (int dx = -ringOuter; dx <= ringOuter; ++dx) {
      const int d2 = dx * dx + dy * dy;
      if (ringed && d2 <= ringOuter * ringOuter && d2 > ringInner * ringInner) c.set(cx + dx, cy + dy, kBlack);
      if (!insideMarker(m, dx, dy, r)) continue;
      const bool edge = !insideMarker(m, dx, dy, r - 2);
      if (!hollow || edge)
        c.set(cx + dx, cy + dy, colour);
      else
        c.set(cx + dx, cy + dy, kWhite);
    }
}

/// Splits `s` at spaces into lines no wider than `width` px.
std::vector<std::string> wrap(const std::string& s, int width, int scale) {
  std::vector<std::string> lines;
  std::string line, word;
  auto flushWord = [&] {
    if (word.empty()) return;
    const std::string joined = line.empty() ? word : line + " " + word;
    if (!line.empty() && Canvas::textWidth(joined, scale) > width)
      lines.push_back(line), line = word;
    else
      line = joined;
    word.clear();
  };
  for (char ch : s) {
    if (ch == ' ')
      flushWord();
    else
      word += ch;
  }
  flushWord();
  if (!line.empty()) lines.push_back(line);
  return lines;
}
}  // namespace

double Axes::pixelX(double x) const {
  const double a = axisValue(x, logX);
  if (std::isnan(a)) return kNaN;
  return double(left) + (a - x0) / (x1 - x0) * double(right - 1 - left);
}

double Axes::pixelY(double y) const {
  const double a = axisValue(y, logY);
  if (std::isnan(a)) return kNaN;
  return double(bottom - 1) - (a - y0) / (y1 - y0) * double(bottom - 1 - top);
}

Axes layoutAxes(const ScatterPlot& plot) {
  Axes a;
  a.logX = plot.logX, a.logY = plot.logY;
  a.left = 90, a.top = 56;
  a.right = std::max(a.left + 50, plot.width - kLegendWidth);
  a.bottom = std::max(a.top + 50, plot.height - 64);
  std::vector<double> xs, ys;
  for (const Point& p : plot.points) xs.push_back(p.x), ys.push_back(p.y);
  for (const auto& [x, y] : plot.line) xs.push_back(x), ys.push_back(y);
  std::tie(a.x0, a.x1) = axisRange(xs, plot.logX);
  std::tie(a.y0, a.y1) = axisRange(ys, plot.logY);
  return a;
}

Rgb Image::at(int x, int y) const {
  const uint8_t* p = &rgb[(size_t(y) * size_t(width) + size_t(x)) * 3];
  return {p[0], p[1], p[2]};
}

std::string tickLabel(double v) {
  char buf[32];
  if (v == 0) return "0";
  const double e = std::log10(std::fabs(v));
  if (std::fabs(e - std::round(e)) < 1e-9 && (e < -2.5 || e > 3.5)) {
    std::snprintf(buf, sizeof buf, "%s1e%d", v < 0 ? "-" : "", int(std::lround(e)));
  } else {
    std::snprintf(buf, sizeof buf, "%g", v);
  }
  return buf;
}

Image render(const ScatterPlot& plot) {
  const Axes a = layoutAxes(plot);
  Canvas c(plot.width, plot.height);
  const int plotW = a.right - a.left, plotH = a.bottom - a.top;
  // Grid: minor lines at 2..9 x each decade (when few decades), major lines at the ticks.
  auto minorLines = [&](double lo, double hi, bool log, bool vertical) {
    if (!log || hi - lo > 6) return;
    for (int d = int(std::lround(lo)); d < int(std::lround(hi)); ++d)
      for (int m = 2; m <= 9; ++m) {
        const double v = double(d) + std::log10(double(m));
        if (vertical) {
          const int x = a.left + int(std::lround((v - lo) / (hi - lo) * double(plotW - 1)));
          c.fill(x, a.top, x + 1, a.bottom, Rgb{242, 242, 242});
        } else {
          const int y = a.bottom - 1 - int(std::lround((v - lo) / (hi - lo) * double(plotH - 1)));
          c.fill(a.left, y, a.right, y + 1, Rgb{242, 242, 242});
        }
      }
  };
  minorLines(a.x0, a.x1, a.logX, true);
  minorLines(a.y0, a.y1, a.logY, false);
  for (double t : majorTicks(a.x0, a.x1, a.logX)) {
    const int x = a.left + int(std::lround((t - a.x0) / (a.x1 - a.x0) * double(plotW - 1)));
    c.fill(x, a.top, x + 1, a.bottom, kGrid);
    c.fill(x, a.bottom, x + 1, a.bottom + 6, kAxis);
    const std::string s = tickLabel(a.logX ? std::pow(10.0, t) : t);
    c.text(x - Canvas::textWidth(s, 2) / 2, a.bottom + 10, s, 2, kAxis);
  }
  for (double t : majorTicks(a.y0, a.y1, a.logY)) {
    const int y = a.bottom - 1 - int(std::lround((t - a.y0) / (a.y1 - a.y0) * double(plotH - 1)));
    c.fill(a.left, y, a.right, y + 1, kGrid);
    c.fill(a.left - 6, y, a.left, y + 1, kAxis);
    const std::string s = tickLabel(a.logY ? std::pow(10.0, t) : t);
    c.text(a.left - 10 - Canvas::textWidth(s, 2), y - 6, s, 2, kAxis);
  }
  // Frame, title, axis labels (the y label above the axis, horizontal).
  c.fill(a.left, a.top, a.right, a.top + 1, kAxis);
  c.fill(a.left, a.bottom - 1, a.right, a.bottom, kAxis);
  c.fill(a.left, a.top, a.left + 1, a.bottom, kAxis);
  c.fill(a.right - 1, a.top, a.right, a.bottom, kAxis);
  c.text(a.left, 8, plot.title, 2, kBlack);
  c.text(std::max(4, a.left - 60), a.top - 22, plot.yLabel, 2, kAxis);
  c.text(a.left + (plotW - Canvas::textWidth(plot.xLabel, 2)) / 2, a.bottom + 36, plot.xLabel, 2, kAxis);
  // The polyline, then the points on top of it, then their labels.
  for (size_t i = 1; i < plot.line.size(); ++i) {
    const double x0 = a.pixelX(plot.line[i - 1].first), y0 = a.pixelY(plot.line[i - 1].second);
    const double x1 = a.pixelX(plot.line[i].first), y1 = a.pixelY(plot.line[i].second);
    if (std::isnan(x0) || std::isnan(y0) || std::isnan(x1) || std::isnan(y1)) continue;
    c.line(x0, y0, x1, y1, 2, plot.lineColour, a.left + 1, a.top + 1, a.right - 1, a.bottom - 1);
  }
  for (const Point& p : plot.points) {
    const double x = a.pixelX(p.x), y = a.pixelY(p.y);
    if (std::isnan(x) || std::isnan(y)) continue;
    drawMarker(c, int(std::lround(x)), int(std::lround(y)), p.marker, p.colour, p.hollow, p.highlighted);
  }
  // Labels right, left, above or below their point, wherever they overlap no label placed before
  // (and stay inside the plot area); a label that fits nowhere is left out (the CSV has it all).
  struct Box {
    int x0, y0, x1, y1;
    bool overlaps(const Box& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
  };
  std::vector<Box> placed;
  for (const Point& p : plot.points) {
    const double x = a.pixelX(p.x), y = a.pixelY(p.y);
    if (p.label.empty() || std::isnan(x) || std::isnan(y)) continue;
    const int px = int(std::lround(x)), py = int(std::lround(y)), w = Canvas::textWidth(p.label, 1), h = 8;
    const int gap = kMarkerRadius + 6;
    const Box candidates[] = {{px + gap, py - 4, px + gap + w, py - 4 + h},
                              {px - gap - w, py - 4, px - gap, py - 4 + h},
                              {px - w / 2, py - gap - h, px - w / 2 + w, py - gap},
                              {px - w / 2, py + gap, px - w / 2 + w, py + gap + h}};
    for (const Box& b : candidates) {
      const bool inside = b.x0 > a.left && b.x1 < a.right && b.y0 > a.top && b.y1 < a.bottom;
      if (!inside || std::any_of(placed.begin(), placed.end(), [&](const Box& o) { return o.overlaps(b); })) continue;
      c.text(b.x0, b.y0 + 1, p.label, 1, kBlack);
      placed.push_back(b);
      break;
    }
  }
  // Legend panel.
  const int lx = a.right + 16, legendTextW = plot.width - lx - 8;
  int ly = a.top;
  for (const LegendEntry& e : plot.legend) {
    if (e.isLine)
      c.line(lx, ly + 6, lx + 16, ly + 6, 2, e.colour, 0, 0, plot.width, plot.height);
    else
      drawMarker(c, lx + 8, ly + 6, e.marker, e.colour, e.hollow, false);
    c.text(lx + 24, ly, e.text, 2, kBlack);
    ly += 20;
  }
  ly += 8;
  for (const std::string& note : plot.notes) {
    for (const std::string& l : wrap(note, legendTextW, 1)) {
      c.text(lx, ly, l, 1, kAxis);
      ly += 11;
    }
    ly += 5;
  }
  return std::move(c.img);
}

std::vector<uint8_t> encodePng(const Image& image) {
  std::vector<uint8_t> png;
  if (image.width <= 0 || image.height <= 0 || image.rgb.size() != size_t(image.width) * size_t(image.height) * 3)
    return png;
  // stb's callback writer: the PNG in memory, so that writing it to disk is writeFileAtomic's
  // (every write checked; a full disk is an error, not a truncated file).
  auto append = [](void* context, void* data, int size) {
    auto* out = static_cast<std::vector<uint8_t>*>(context);
    const auto* bytes = static_cast<const uint8_t*>(data);
    out->insert(out->end(), bytes, bytes + size);
  };
  if (!stbi_write_png_to_func(append, &png, image.width, image.height, 3, image.rgb.data(), image.width * 3))
    png.clear();
  return png;
}

bool writePng(const std::string& path, const Image& image, std::string* error) {
  const std::vector<uint8_t> png = encodePng(image);
  if (png.empty()) {
    if (error) *error = path + ": cannot encode the PNG image";
    return false;
  }
  std::string why;
  if (!writeFileAtomic(path, png, &why)) {
    if (error) *error = why;
    return false;
  }
  return true;
}

Canvas::Canvas(int w, int h, Rgb background) {
  img.width = w, img.height = h;
  img.rgb.resize(size_t(w) * size_t(h) * 3);
  for (size_t p = 0; p < img.rgb.size(); p += 3)
    img.rgb[p] = background.r, img.rgb[p + 1] = background.g, img.rgb[p + 2] = background.b;
}

void Canvas::set(int x, int y, Rgb c) {
  if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
  uint8_t* p = &img.rgb[(size_t(y) * size_t(img.width) + size_t(x)) * 3];
  p[0] = c.r, p[1] = c.g, p[2] = c.b;
}

void Canvas::fill(int x0, int y0, int x1, int y1, Rgb c) {
  for (int y = std::max(y0, 0); y < std::min(y1, img.height); ++y)
    for (int x = std::max(x0, 0); x < std::min(x1, img.width); ++x) set(x, y, c);
}

void Canvas::line(double x0, double y0, double x1, double y1, int thick, Rgb c, int cx0, int cy0, int cx1, int cy1) {
  const int steps = std::max(1, int(std::ceil(std::max(std::fabs(x1 - x0), std::fabs(y1 - y0)))));
  for (int s = 0; s <= steps; ++s) {
    const double f = double(s) / double(steps);
    const int x = int(std::lround(x0 + f * (x1 - x0))), y = int(std::lround(y0 + f * (y1 - y0)));
    for (int dy = 0; dy < thick; ++dy)
      for (int dx = 0; dx < thick; ++dx) {
        const int px = x + dx - thick / 2, py = y + dy - thick / 2;
        if (px >= cx0 && px < cx1 && py >= cy0 && py < cy1) set(px, py, c);
      }
  }
}

void Canvas::text(int x, int y, const std::string& s, int scale, Rgb c) {
  std::vector<char> chars(s.begin(), s.end());
  chars.push_back('\0');
  std::vector<char> quads(s.size() * 400 + 64);  // ~270 bytes per glyph at most
  const int n = stb_easy_font_print(0, 0, chars.data(), nullptr, quads.data(), int(quads.size()));
  for (int q = 0; q < n; ++q) {
    float v0[2], v2[2];  // corners 0 and 2 of an axis-aligned quad, 16 bytes per vertex
    std::memcpy(v0, &quads[size_t(q) * 64], sizeof v0);
    std::memcpy(v2, &quads[size_t(q) * 64 + 32], sizeof v2);
    fill(x + int(v0[0]) * scale, y + int(v0[1]) * scale, x + int(v2[0]) * scale, y + int(v2[1]) * scale, c);
  }
}

int Canvas::textWidth(const std::string& s, int scale) {
  std::vector<char> chars(s.begin(), s.end());
  chars.push_back('\0');
  return stb_easy_font_width(chars.data()) * scale;
}

}  // namespace sg::plot
